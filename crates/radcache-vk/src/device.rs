//! Physical device queries and logical device creation.
//!
//! [`query_caps`] turns a `VkPhysicalDevice` into the plain [`DeviceCaps`] that `select` judges;
//! [`create_device`] enables exactly the extensions and features listed in `select`.

use std::ffi::{CStr, CString};

use ash::vk;

use crate::error::{Error, Result, VkResultExt};
use crate::select::{DeviceCaps, DeviceKind, REQUIRED_EXTENSIONS};

/// Facts about the chosen device that the renderer and the profiler need.
#[derive(Debug, Clone)]
pub struct DeviceInfo {
    /// `deviceName`.
    pub name: String,
    /// Kind of device.
    pub kind: DeviceKind,
    /// Driver name and info (e.g. "llvmpipe", "Mesa 25.0.7").
    pub driver: String,
    /// Vulkan version of the device.
    pub api_version: (u32, u32, u32),
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f64,
    /// Valid bits of timestamps on the queue.
    pub timestamp_valid_bits: u32,
    /// `maxComputeWorkGroupCount`.
    pub max_compute_work_group_count: [u32; 3],
    /// `maxStorageBufferRange` in bytes.
    pub max_storage_buffer_range: u32,
    /// `maxUniformBufferRange` in bytes.
    pub max_uniform_buffer_range: u32,
    /// `minStorageBufferOffsetAlignment` in bytes.
    pub min_storage_buffer_offset_alignment: u64,
    /// `minUniformBufferOffsetAlignment` in bytes.
    pub min_uniform_buffer_offset_alignment: u64,
    /// `maxColorAttachments`.
    pub max_color_attachments: u32,
    /// `maxPushConstantsSize` in bytes.
    pub max_push_constants_size: u32,
    /// `minAccelerationStructureScratchOffsetAlignment`.
    pub min_scratch_alignment: u32,
    /// Subgroup size.
    pub subgroup_size: u32,
    /// Whether the validation layer is active.
    pub validation: bool,
    /// `vendorID`.
    pub vendor_id: u32,
    /// `deviceID`.
    pub device_id: u32,
    /// `driverVersion` (encoding vendor-specific).
    pub driver_version: u32,
    /// `pipelineCacheUUID`: pipeline cache data is exchangeable between devices with equal ids.
    pub pipeline_cache_uuid: [u8; 16],
    /// Bytes of the largest `DEVICE_LOCAL` memory heap (on a CPU device such as lavapipe, the
    /// host memory it reports).
    pub memory_bytes: u64,
    /// A smaller budget asked for by [`crate::ContextOptions::memory_limit`]
    /// (`RADCACHE_DEVICE_MEMORY`).
    pub memory_limit: Option<u64>,
}

impl DeviceInfo {
    /// The bytes of device memory a scene may plan for: the largest device-local heap, or the
    /// limit asked for where that is smaller.
    pub fn usable_memory(&self) -> u64 {
        self.memory_limit
            .map_or(self.memory_bytes, |l| l.min(self.memory_bytes))
    }
}

fn kind_of(t: vk::PhysicalDeviceType) -> DeviceKind {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => DeviceKind::Discrete,
        vk::PhysicalDeviceType::INTEGRATED_GPU => DeviceKind::Integrated,
        vk::PhysicalDeviceType::VIRTUAL_GPU => DeviceKind::Virtual,
        vk::PhysicalDeviceType::CPU => DeviceKind::Cpu,
        _ => DeviceKind::Other,
    }
}

/// The universal (graphics + compute, timestamped) queue family, if any.
pub(crate) fn universal_queue_family(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
) -> Option<(u32, u32)> {
    // SAFETY: `pd` was enumerated from `instance`.
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    families.iter().enumerate().find_map(|(i, f)| {
        let flags = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
        (f.queue_flags.contains(flags) && f.timestamp_valid_bits > 0)
            .then_some((i as u32, f.timestamp_valid_bits))
    })
}

/// Reads what `pd` offers.
pub(crate) fn query_caps(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Result<DeviceCaps> {
    // SAFETY: `pd` was enumerated from `instance`.
    let props = unsafe { instance.get_physical_device_properties(pd) };
    // SAFETY: as above.
    let exts = unsafe { instance.enumerate_device_extension_properties(pd) }
        .call("vkEnumerateDeviceExtensionProperties")?;
    let extensions: Vec<String> = exts
        .iter()
        .filter_map(|e| e.extension_name_as_c_str().ok())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    let api = (
        vk::api_version_major(props.api_version),
        vk::api_version_minor(props.api_version),
    );
    let has = |name: &CStr| extensions.iter().any(|e| e.as_bytes() == name.to_bytes());

    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut fas = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut frq = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
    let mut core = vk::PhysicalDeviceFeatures2::default();
    if api >= (1, 2) {
        core = core.push_next(&mut f12);
    }
    if api >= (1, 3) {
        core = core.push_next(&mut f13);
    }
    if has(ash::khr::acceleration_structure::NAME) {
        core = core.push_next(&mut fas);
    }
    if has(ash::khr::ray_query::NAME) {
        core = core.push_next(&mut frq);
    }
    // SAFETY: the chain only holds structs the device's API version / extensions define.
    unsafe { instance.get_physical_device_features2(pd, &mut core) };
    let c = core.features;
    let flags: [(&'static str, u32); 16] = [
        ("bufferDeviceAddress", f12.buffer_device_address),
        ("scalarBlockLayout", f12.scalar_block_layout),
        ("runtimeDescriptorArray", f12.runtime_descriptor_array),
        (
            "descriptorBindingPartiallyBound",
            f12.descriptor_binding_partially_bound,
        ),
        (
            "shaderSampledImageArrayNonUniformIndexing",
            f12.shader_sampled_image_array_non_uniform_indexing,
        ),
        ("dynamicRendering", f13.dynamic_rendering),
        ("synchronization2", f13.synchronization2),
        ("maintenance4", f13.maintenance4),
        (
            "shaderDemoteToHelperInvocation",
            f13.shader_demote_to_helper_invocation,
        ),
        ("accelerationStructure", fas.acceleration_structure),
        ("rayQuery", frq.ray_query),
        ("fragmentStoresAndAtomics", c.fragment_stores_and_atomics),
        ("shaderInt64", c.shader_int64),
        ("shaderBufferInt64Atomics", f12.shader_buffer_int64_atomics),
        ("drawIndirectFirstInstance", c.draw_indirect_first_instance),
        (
            "timestampComputeAndGraphics",
            props.limits.timestamp_compute_and_graphics,
        ),
    ];
    Ok(DeviceCaps {
        name: props
            .device_name_as_c_str()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|_| "<unnamed>".into()),
        kind: kind_of(props.device_type),
        api,
        extensions,
        features: flags
            .iter()
            .filter(|(_, v)| *v == vk::TRUE)
            .map(|(n, _)| *n)
            .collect(),
        has_universal_queue: universal_queue_family(instance, pd).is_some(),
    })
}

/// Reads the facts kept in [`DeviceInfo`].
pub(crate) fn device_info(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    timestamp_valid_bits: u32,
    validation: bool,
) -> DeviceInfo {
    let mut as_props = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
    let mut sub = vk::PhysicalDeviceSubgroupProperties::default();
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut p2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut as_props)
        .push_next(&mut sub)
        .push_next(&mut driver);
    // SAFETY: the device supports Vulkan 1.3 and VK_KHR_acceleration_structure (checked by select).
    unsafe { instance.get_physical_device_properties2(pd, &mut p2) };
    let p = p2.properties;
    // SAFETY: `pd` is a physical device of `instance`.
    let memory = unsafe { instance.get_physical_device_memory_properties(pd) };
    let memory_bytes = memory
        .memory_heaps_as_slice()
        .iter()
        .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
        .map(|h| h.size)
        .max()
        .unwrap_or(0);
    let text = |r: std::result::Result<&CStr, _>| {
        r.map(|c: &CStr| c.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    DeviceInfo {
        name: text(p.device_name_as_c_str()),
        kind: kind_of(p.device_type),
        driver: format!(
            "{} ({})",
            text(driver.driver_name_as_c_str()),
            text(driver.driver_info_as_c_str())
        ),
        api_version: (
            vk::api_version_major(p.api_version),
            vk::api_version_minor(p.api_version),
            vk::api_version_patch(p.api_version),
        ),
        timestamp_period_ns: f64::from(p.limits.timestamp_period),
        timestamp_valid_bits,
        max_compute_work_group_count: p.limits.max_compute_work_group_count,
        max_storage_buffer_range: p.limits.max_storage_buffer_range,
        max_uniform_buffer_range: p.limits.max_uniform_buffer_range,
        min_storage_buffer_offset_alignment: p.limits.min_storage_buffer_offset_alignment,
        min_uniform_buffer_offset_alignment: p.limits.min_uniform_buffer_offset_alignment,
        max_color_attachments: p.limits.max_color_attachments,
        max_push_constants_size: p.limits.max_push_constants_size,
        min_scratch_alignment: as_props.min_acceleration_structure_scratch_offset_alignment,
        subgroup_size: sub.subgroup_size,
        validation,
        vendor_id: p.vendor_id,
        device_id: p.device_id,
        driver_version: p.driver_version,
        pipeline_cache_uuid: p.pipeline_cache_uuid,
        memory_bytes,
        memory_limit: None,
    }
}

/// Creates the logical device with one universal queue and radcache's extensions and features.
pub(crate) fn create_device(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    queue_family: u32,
    extra_extensions: &[String],
) -> Result<ash::Device> {
    let mut names: Vec<CString> = Vec::new();
    for e in REQUIRED_EXTENSIONS
        .iter()
        .map(|s| s.to_string())
        .chain(extra_extensions.iter().cloned())
    {
        names.push(CString::new(e).map_err(|_| Error::Invalid("extension name with NUL".into()))?);
    }
    let ptrs: Vec<*const i8> = names.iter().map(|n| n.as_ptr()).collect();
    let priorities = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&priorities)];
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
        .buffer_device_address(true)
        .scalar_block_layout(true)
        .runtime_descriptor_array(true)
        .descriptor_binding_partially_bound(true)
        .shader_sampled_image_array_non_uniform_indexing(true)
        .shader_buffer_int64_atomics(true);
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .dynamic_rendering(true)
        .synchronization2(true)
        .maintenance4(true)
        .shader_demote_to_helper_invocation(true);
    let mut fas =
        vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
    let mut frq = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
    // drawIndirectFirstInstance: the splat pass's batch draw starts at a GPU-written instance;
    // shaderInt64 (and shaderBufferInt64Atomics above): the record pass's radiance grid sums in
    // 64-bit fixed point (shaders/common/path_grid.glsl).
    let core = vk::PhysicalDeviceFeatures::default()
        .fragment_stores_and_atomics(true)
        .shader_int64(true)
        .draw_indirect_first_instance(true);
    let mut f2 = vk::PhysicalDeviceFeatures2::default()
        .features(core)
        .push_next(&mut f12)
        .push_next(&mut f13)
        .push_next(&mut fas)
        .push_next(&mut frq);
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&ptrs)
        .push_next(&mut f2);
    // SAFETY: `select` verified every extension and feature enabled here; `info` outlives the call.
    unsafe { instance.create_device(pd, &info, None) }.call("vkCreateDevice")
}
