//! `radcache render --cache-in/--cache-out`: what a render's records are made for, the check of
//! the flags, and the import into and export from the cache's renderer (the file format is
//! `radcache_cache::cache_file`; `radcache cache` is the `cache` command).

use std::path::Path;

use anyhow::{bail, Context as _, Result};
use radcache_cache::cache_file::{CacheFile, CacheIdentity, CacheRecords, CacheSettings};
use radcache_render::{GpuScene, IcRenderer, IcSettings};
use radcache_scene::Scene;
use radcache_vk::{Context, ShaderCompiler};

use crate::args::{Method, RenderArgs};

/// What the records of `settings` on `scene` are made for.
pub fn identity(scene: &Scene, settings: &IcSettings) -> CacheIdentity {
    CacheIdentity {
        scene_hash: scene.content_hash(),
        settings: CacheSettings {
            width: settings.width,
            height: settings.height,
            time_step_s: settings.time_step_s,
        },
        params: settings.params,
    }
}

/// Refuses cache flags that cannot apply to the render.
pub fn check_render_args(args: &RenderArgs) -> Result<()> {
    let cache = args.cache_in.is_some() || args.cache_out.is_some();
    if cache && args.method != Method::Ic {
        bail!("--cache-in and --cache-out need --method ic");
    }
    if args.cache_in.is_some() && args.no_temporal {
        bail!("--cache-in keeps the file's records across frames: it excludes --no-temporal");
    }
    Ok(())
}

/// Loads the cache file at `path` into the fresh renderer `r` after checking it was made for
/// `scene` and `settings`; returns the number of records.
pub fn import(
    path: &Path,
    r: &mut IcRenderer,
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &GpuScene,
    settings: &IcSettings,
) -> Result<usize> {
    let file = CacheFile::load(path, &identity(scene, settings), settings.record_capacity)?;
    r.import_cache(ctx, shaders, gpu, &file.records)
        .with_context(|| format!("loading the records of {}", path.display()))?;
    Ok(file.records.records.len())
}

/// Writes the records of the renderer `ic` (the last frame's), made with `settings` on `scene`,
/// to `path`; without a renderer (every frame was on disk already) nothing is written.
pub fn export(
    path: &Path,
    ic: Option<&IcRenderer>,
    ctx: &Context,
    scene: &Scene,
    settings: &IcSettings,
    quiet: bool,
) -> Result<()> {
    let Some(r) = ic else {
        log::warn!(
            "no frame was rendered: the cache file {} is not written",
            path.display()
        );
        return Ok(());
    };
    let records = r.export_cache(ctx)?;
    write(path, identity(scene, settings), records, quiet)
}

/// Writes `records` made for `identity` to `path` atomically.
pub fn write(
    path: &Path,
    identity: CacheIdentity,
    records: CacheRecords,
    quiet: bool,
) -> Result<()> {
    let file = CacheFile::new(identity, records);
    crate::output::write_bytes(path, &file.encode(), "cache file")?;
    if !quiet {
        crate::progress::line(&format!(
            "wrote {} records to {}",
            file.header.record_count,
            path.display()
        ));
    }
    Ok(())
}
