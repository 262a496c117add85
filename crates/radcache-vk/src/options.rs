//! How a [`Context`](crate::Context) is created: options, by hand or from the environment.

use std::path::PathBuf;

/// The environment variable that moves (`=DIR`) or disables (`=off`) the pipeline cache.
pub const PIPELINE_CACHE_ENV: &str = "RADCACHE_PIPELINE_CACHE";

/// How to create a [`Context`](crate::Context).
#[derive(Debug, Clone, Default)]
pub struct ContextOptions {
    /// Enable the Khronos validation layer (if installed).
    pub validation: bool,
    /// With the layer, also check synchronization: a hazard between two commands that no
    /// barrier orders is a validation error (slower; the tests of the derived barriers use it).
    pub sync_validation: bool,
    /// Keep only devices whose name contains this (case-insensitive).
    pub device_filter: Option<String>,
    /// Device extensions to require on top of radcache's own.
    pub extra_device_extensions: Vec<String>,
    /// The folder of the persistent pipeline cache (one file per device and driver); `None`
    /// keeps pipelines in memory only. [`Self::from_env`] picks the user's cache folder.
    pub pipeline_cache_dir: Option<PathBuf>,
}

impl ContextOptions {
    /// Options from the environment: `RADCACHE_VALIDATION=0/1` (default: on in debug builds;
    /// `=sync` adds synchronization validation),
    /// `RADCACHE_DEVICE=<substring of the device name>` and the pipeline cache folder
    /// ([`pipeline_cache_dir_from_env`]).
    pub fn from_env() -> Self {
        let validation = match std::env::var("RADCACHE_VALIDATION").as_deref() {
            Ok("0") | Ok("false") | Ok("off") | Ok("no") => false,
            Ok("1") | Ok("true") | Ok("on") | Ok("yes") | Ok("sync") => true,
            _ => cfg!(debug_assertions),
        };
        let sync_validation = std::env::var("RADCACHE_VALIDATION").as_deref() == Ok("sync");
        let device_filter = std::env::var("RADCACHE_DEVICE")
            .ok()
            .filter(|s| !s.is_empty());
        ContextOptions {
            validation,
            sync_validation,
            device_filter,
            extra_device_extensions: Vec::new(),
            pipeline_cache_dir: pipeline_cache_dir_from_env(),
        }
    }
}

/// The pipeline cache folder the environment asks for: `RADCACHE_PIPELINE_CACHE=off` (or `0`,
/// `none`, `false`, `no`) disables it, `RADCACHE_PIPELINE_CACHE=DIR` moves it; by default it is
/// `$XDG_CACHE_HOME/radcache`, else `$HOME/.cache/radcache` (none without either).
pub fn pipeline_cache_dir_from_env() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(v) = var(PIPELINE_CACHE_ENV) {
        return match v.to_str() {
            Some("off") | Some("0") | Some("none") | Some("false") | Some("no") => None,
            _ => Some(PathBuf::from(v)),
        };
    }
    var("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| var("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .map(|d| d.join("radcache"))
}
