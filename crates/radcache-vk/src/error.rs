//! Errors of the Vulkan backend.
//!
//! Vulkan results are mapped per kind of call (wgpu-hal style): the `call` names the entry point so a
//! failure reads "vkCreateBuffer failed: ERROR_OUT_OF_DEVICE_MEMORY" rather than a bare code. A lost
//! device carries the name of the pass that was open when it happened (kajiya's crash marker, made
//! cheap by the profiler's scope stack).

use ash::vk;

/// Errors of `radcache-vk`.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The Vulkan loader (libvulkan.so.1) could not be loaded.
    #[error("could not load the Vulkan loader (libvulkan.so.1): {0}; install libvulkan1")]
    Loader(String),
    /// A Vulkan call returned an error code.
    #[error("{call} failed: {result:?}")]
    Vk {
        /// The Vulkan entry point.
        call: &'static str,
        /// Its result code.
        result: vk::Result,
    },
    /// The device was lost; `last_pass` is the profiler scope that was open, if any.
    #[error("the Vulkan device was lost (last pass: {})", last_pass.as_deref().unwrap_or("none"))]
    DeviceLost {
        /// Name of the last opened pass scope.
        last_pass: Option<String>,
    },
    /// A memory allocation failed.
    #[error("allocating {name:?} failed: {source}")]
    Alloc {
        /// The allocation's name.
        name: String,
        /// The allocator's error.
        source: gpu_allocator::AllocationError,
    },
    /// A shader failed to compile (the message carries file and line).
    #[error("shader {path}: {message}")]
    Shader {
        /// The shader's path (the entry file).
        path: String,
        /// The compiler's message, with file:line for each problem.
        message: String,
    },
    /// No device has everything radcache needs.
    #[error("{0}")]
    NoSuitableDevice(crate::select::DeviceReport),
    /// A required capability is missing on the chosen device.
    #[error("missing device capability: {0}")]
    MissingFeature(String),
    /// An argument was out of range for the device (e.g. a dispatch over the limits).
    #[error("{0}")]
    Invalid(String),
}

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Maps a `vk::Result` to [`Error`], naming the call.
pub(crate) fn vk_err(call: &'static str) -> impl Fn(vk::Result) -> Error {
    move |result| {
        if result == vk::Result::ERROR_DEVICE_LOST {
            Error::DeviceLost { last_pass: None }
        } else {
            Error::Vk { call, result }
        }
    }
}

/// `?`-friendly conversion of an ash result with the call's name.
pub(crate) trait VkResultExt<T> {
    fn call(self, name: &'static str) -> Result<T>;
}

impl<T> VkResultExt<T> for std::result::Result<T, vk::Result> {
    fn call(self, name: &'static str) -> Result<T> {
        self.map_err(vk_err(name))
    }
}
