//! Vulkan instance creation: the loader, the Khronos validation layer and the debug messenger.
//!
//! Validation is on by default in debug builds (which include tests) and off in release builds;
//! `RADCACHE_VALIDATION=0/1` overrides. Messages go to `log` by severity, and errors are counted so
//! that a test can assert that none occurred ([`crate::Context::validation_errors`]).

use std::ffi::{c_void, CStr, CString};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

use ash::vk;

use crate::error::{Error, Result, VkResultExt};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Counters shared with the debug messenger callback. Boxed so its address is stable.
#[derive(Debug, Default)]
pub(crate) struct MessengerState {
    pub errors: AtomicU32,
    pub warnings: AtomicU32,
    pub first_error: Mutex<Option<String>>,
}

/// The instance with its optional debug messenger.
pub(crate) struct InstanceParts {
    /// Owns the loaded Vulkan library: must outlive the instance.
    #[allow(dead_code)]
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub debug_utils: Option<ash::ext::debug_utils::Instance>,
    pub messenger: vk::DebugUtilsMessengerEXT,
    pub messenger_state: Box<MessengerState>,
    pub validation: bool,
}

/// Creates the instance (API 1.3), enabling validation if asked and available, and the layer's
/// synchronization validation (hazards between commands that no barrier orders) with it if
/// `sync_validation`.
pub(crate) fn create_instance(
    want_validation: bool,
    sync_validation: bool,
) -> Result<InstanceParts> {
    // SAFETY: loading the system Vulkan loader; no Vulkan call is in flight.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;

    // SAFETY: `entry` is a loaded Vulkan entry point table.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }
        .call("vkEnumerateInstanceLayerProperties")?;
    let has_layer = layers
        .iter()
        .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
    let validation = want_validation && has_layer;
    if want_validation && !has_layer {
        log::warn!(
            "validation requested but VK_LAYER_KHRONOS_validation is not installed \
             (apt-get install vulkan-validationlayers); running without it"
        );
    }

    // SAFETY: as above.
    let exts = unsafe { entry.enumerate_instance_extension_properties(None) }
        .call("vkEnumerateInstanceExtensionProperties")?;
    let has_debug_utils = exts.iter().any(|e| {
        e.extension_name_as_c_str()
            .is_ok_and(|n| n == ash::ext::debug_utils::NAME)
    });

    let app_name = CString::from(c"radcache");
    let app = vk::ApplicationInfo::default()
        .application_name(&app_name)
        .application_version(vk::make_api_version(0, 0, 1, 0))
        .engine_name(&app_name)
        .api_version(vk::API_VERSION_1_3);
    let layer_ptrs: Vec<*const i8> = if validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let mut ext_ptrs: Vec<*const i8> = if has_debug_utils {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    // The layer provides VK_EXT_validation_features, which carries the synchronization check.
    let sync_validation = validation && sync_validation && {
        // SAFETY: as above; the layer name is a NUL-terminated string of the loader's list.
        let layer_exts =
            unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                .call("vkEnumerateInstanceExtensionProperties")?;
        layer_exts.iter().any(|e| {
            e.extension_name_as_c_str()
                .is_ok_and(|n| n == ash::ext::validation_features::NAME)
        })
    };
    let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
    if sync_validation {
        ext_ptrs.push(ash::ext::validation_features::NAME.as_ptr());
    }
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layer_ptrs)
        .enabled_extension_names(&ext_ptrs);
    if sync_validation {
        info = info.push_next(&mut features);
    }
    // SAFETY: `info` and everything it points to live until the call returns.
    let instance = unsafe { entry.create_instance(&info, None) }.call("vkCreateInstance")?;

    let messenger_state = Box::<MessengerState>::default();
    let (debug_utils, messenger) = if has_debug_utils {
        let du = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let severity = vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
            | vk::DebugUtilsMessageSeverityFlagsEXT::INFO;
        let types = vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
            | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
            | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE;
        let user_data: *const MessengerState = &*messenger_state;
        let ci = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(severity)
            .message_type(types)
            .pfn_user_callback(Some(debug_callback))
            .user_data(user_data as *mut c_void);
        // SAFETY: the callback only reads its arguments; `messenger_state` is boxed and outlives
        // the messenger (destroyed first in `DeviceShared::drop`).
        let messenger = unsafe { du.create_debug_utils_messenger(&ci, None) };
        match messenger {
            Ok(m) => (Some(du), m),
            Err(e) => {
                // SAFETY: no child object of the instance exists yet.
                unsafe { instance.destroy_instance(None) };
                return Err(Error::Vk {
                    call: "vkCreateDebugUtilsMessengerEXT",
                    result: e,
                });
            }
        }
    } else {
        (None, vk::DebugUtilsMessengerEXT::null())
    };

    Ok(InstanceParts {
        entry,
        instance,
        debug_utils,
        messenger,
        messenger_state,
        validation,
    })
}

/// Routes validation and loader messages into `log` and counts errors.
unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the implementation passes a valid callback-data pointer (or null) for the duration of
    // the call, with a NUL-terminated message.
    let message = unsafe {
        data.as_ref()
            .filter(|d| !d.p_message.is_null())
            .map(|d| CStr::from_ptr(d.p_message).to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    // SAFETY: `user` is the boxed `MessengerState` registered with this messenger, alive while it is.
    let state = unsafe { (user as *const MessengerState).as_ref() };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        log::error!("[vulkan] {message}");
        if let Some(state) = state {
            state.errors.fetch_add(1, Ordering::SeqCst);
            if let Ok(mut first) = state.first_error.lock() {
                first.get_or_insert(message);
            }
        }
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        log::warn!("[vulkan] {message}");
        if let Some(state) = state {
            state.warnings.fetch_add(1, Ordering::SeqCst);
        }
    } else {
        log::debug!("[vulkan] {message}");
    }
    vk::FALSE
}
