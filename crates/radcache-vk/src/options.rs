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
    /// Plan scenes for at most this many bytes of device memory (where the device has more: a
    /// shared GPU, or a test of the refusal); see [`crate::DeviceInfo::usable_memory`].
    pub memory_limit: Option<u64>,
}

impl ContextOptions {
    /// Options from the environment: `RADCACHE_VALIDATION=0/1` (default: on in debug builds;
    /// `=sync` adds synchronization validation),
    /// `RADCACHE_DEVICE=<substring of the device name>`, the pipeline cache folder
    /// ([`pipeline_cache_dir_from_env`]) and `RADCACHE_DEVICE_MEMORY=SIZE` (bytes, or with a
    /// `K`/`M`/`G` suffix, powers of 1024; a value that does not parse is ignored with a warning).
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
            memory_limit: memory_limit_from_env(),
        }
    }
}

/// The environment variable that caps the device memory scenes plan for.
pub const DEVICE_MEMORY_ENV: &str = "RADCACHE_DEVICE_MEMORY";

fn memory_limit_from_env() -> Option<u64> {
    let v = std::env::var(DEVICE_MEMORY_ENV)
        .ok()
        .filter(|v| !v.is_empty())?;
    let parsed = parse_size(&v);
    if parsed.is_none() {
        log::warn!("{DEVICE_MEMORY_ENV}={v:?} is not a size (e.g. 512M, 8G): ignored");
    }
    parsed
}

/// `N`, `NK`, `NM`, `NG` or `NT` (optionally followed by `B` or `iB`, any case) in bytes,
/// powers of 1024; zero is not a size.
pub fn parse_size(s: &str) -> Option<u64> {
    let upper = s.trim().to_ascii_uppercase();
    let u = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, shift) = match u.as_bytes().last()? {
        b'K' => (&u[..u.len() - 1], 10),
        b'M' => (&u[..u.len() - 1], 20),
        b'G' => (&u[..u.len() - 1], 30),
        b'T' => (&u[..u.len() - 1], 40),
        _ => (u, 0),
    };
    let n: u64 = number.trim().parse().ok()?;
    n.checked_mul(1u64 << shift).filter(|&b| b > 0)
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

#[cfg(test)]
mod tests {
    use super::parse_size;

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        for (text, bytes) in [
            ("4096", Some(4096)),
            ("64K", Some(64 << 10)),
            ("512MiB", Some(512 << 20)),
            ("8g", Some(8 << 30)),
            ("2 GB", Some(2 << 30)),
            ("1T", Some(1 << 40)),
            ("0", None),
            ("lots", None),
            ("G", None),
            ("-1M", None),
            ("99999999999T", None),
        ] {
            assert_eq!(parse_size(text), bytes, "{text}");
        }
    }
}
