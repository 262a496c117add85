//! How a [`Context`](crate::Context) is created: options, by hand or from the environment.

/// How to create a [`Context`](crate::Context).
#[derive(Debug, Clone, Default)]
pub struct ContextOptions {
    /// Enable the Khronos validation layer (if installed).
    pub validation: bool,
    /// Keep only devices whose name contains this (case-insensitive).
    pub device_filter: Option<String>,
    /// Device extensions to require on top of radcache's own.
    pub extra_device_extensions: Vec<String>,
}

impl ContextOptions {
    /// Options from the environment: `RADCACHE_VALIDATION=0/1` (default: on in debug builds) and
    /// `RADCACHE_DEVICE=<substring of the device name>`.
    pub fn from_env() -> Self {
        let validation = match std::env::var("RADCACHE_VALIDATION").as_deref() {
            Ok("0") | Ok("false") | Ok("off") | Ok("no") => false,
            Ok("1") | Ok("true") | Ok("on") | Ok("yes") => true,
            _ => cfg!(debug_assertions),
        };
        let device_filter = std::env::var("RADCACHE_DEVICE")
            .ok()
            .filter(|s| !s.is_empty());
        ContextOptions {
            validation,
            device_filter,
            extra_device_extensions: Vec::new(),
        }
    }
}
