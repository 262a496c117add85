//! The command-line arguments of `radcache render` (and the environment overrides `info` shares),
//! parsed by clap, with the checks clap cannot make; the cache's options are in [`ic`].

pub mod ic;

use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use radcache_scene::{CameraView, EnvOverride};

use ic::IcArgs;

/// Where the GLSL sources live: `RADCACHE_SHADERS`, else the source tree this binary was built
/// from.
pub fn shader_root() -> PathBuf {
    std::env::var_os("RADCACHE_SHADERS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shaders")))
}

/// Environment overrides shared by `render` and `info`.
#[derive(Args, Debug, Clone)]
pub struct EnvArgs {
    /// Equirectangular EXR environment map (+Y up; see docs/design.md for the convention).
    #[arg(long, value_name = "FILE.exr")]
    pub env_map: Option<PathBuf>,
    /// Constant environment radiance, linear RGB W/(sr·m²), e.g. `0.5,0.6,0.8`.
    #[arg(long, value_name = "R,G,B")]
    pub env_radiance: Option<String>,
    /// Multiplier of the environment (map or constant).
    #[arg(long, default_value_t = 1.0)]
    pub env_scale: f32,
}

impl EnvArgs {
    /// The loader's environment override.
    pub fn to_override(&self) -> Result<EnvOverride> {
        let radiance = match &self.env_radiance {
            None => None,
            Some(text) => Some(parse_rgb(text)?),
        };
        if !self.env_scale.is_finite() || self.env_scale < 0.0 {
            bail!(
                "--env-scale must be finite and non-negative, got {}",
                self.env_scale
            );
        }
        Ok(EnvOverride {
            map: self.env_map.clone(),
            radiance,
            scale: self.env_scale,
        })
    }
}

fn parse_rgb(text: &str) -> Result<[f32; 3]> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values: Vec<f32> = parts
        .iter()
        .map(|p| p.parse::<f32>())
        .collect::<std::result::Result<_, _>>()
        .with_context(|| format!("--env-radiance {text:?}: expected three numbers R,G,B"))?;
    match values[..] {
        [r, g, b] if values.iter().all(|v| v.is_finite() && *v >= 0.0) => Ok([r, g, b]),
        _ => bail!("--env-radiance {text:?}: expected three finite non-negative numbers R,G,B"),
    }
}

/// Rendering method.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The unbiased reference path tracer.
    Path,
    /// The irradiance cache.
    Ic,
}

impl Method {
    /// The method's name in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Method::Path => "path",
            Method::Ic => "ic",
        }
    }
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The glTF scene (.gltf or .glb).
    pub(crate) scene: PathBuf,
    /// Output EXR (or .png for a PNG only); `####` is replaced by the frame number.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// Image size WxH; default 512 pixels high at the camera's aspect ratio.
    #[arg(long, value_name = "WxH")]
    pub(crate) resolution: Option<String>,
    /// Rendering method.
    #[arg(long, value_enum, default_value_t = Method::Ic)]
    pub(crate) method: Method,
    /// Take the configuration an EXR was rendered with (its `radcache.extra.config`: method,
    /// resolution, seed, the cache's quality, overrides and technique switches); options given
    /// after this one override it.
    #[arg(long, value_name = "FILE.exr")]
    pub(crate) config_from: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) ic: IcArgs,
    /// Samples per pixel (path tracer).
    #[arg(long, conflicts_with = "time_budget")]
    pub(crate) spp: Option<u32>,
    /// Sample until this many seconds have passed instead of a fixed spp.
    #[arg(long, value_name = "SECONDS")]
    pub(crate) time_budget: Option<f64>,
    /// Seed of the random sequences.
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u32,
    /// Scene time in seconds of a single frame (default: from the frame number, see `--fps`).
    #[arg(long)]
    pub(crate) time: Option<f32>,
    /// Render this one frame (the number replaces `####` in the output path).
    #[arg(long)]
    pub(crate) frame: Option<u32>,
    /// Render a sequence: frames A..B inclusive (`####` in the output path); default with a
    /// pattern on an animated scene: the animation's own range.
    #[arg(long, value_name = "A..B")]
    pub(crate) frames: Option<String>,
    /// Frames per second: frame f shows the scene at start + (f − first)/fps.
    #[arg(long, default_value_t = 24.0)]
    pub(crate) fps: f32,
    /// Scene time of the first frame (default: the animation's first key, else 0).
    #[arg(long)]
    pub(crate) start_time: Option<f32>,
    /// The frame shown at the start time (default: the first of `--frames`): a part of a longer
    /// sequence (a farm chunk) passes the sequence's first frame to get its frames' times.
    #[arg(long, value_name = "N")]
    pub(crate) start_frame: Option<u32>,
    /// Before each frame to write, render the K frames before it without writing them (down to
    /// `--start-frame`), so the records kept across frames have the lifespans and values of one
    /// run from the start (a farm chunk, a resumed run).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub(crate) warm_up: u32,
    /// Render frames again that are already on disk (a sequence skips them otherwise, so an
    /// interrupted run resumes where it stopped).
    #[arg(long)]
    pub(crate) overwrite: bool,
    /// Rebuild the cache every frame instead of keeping its records (by default records are
    /// kept; with moving geometry or lights they carry lifespans and are refreshed in place).
    #[arg(long)]
    pub(crate) no_temporal: bool,
    /// Use the camera with this name instead of the scene's first.
    #[arg(long)]
    pub(crate) camera: Option<String>,
    /// Start from the records of this cache file (`--cache-out`, `radcache cache build`): made
    /// for this scene, cache parameters and resolution, it is refused otherwise.
    #[arg(long, value_name = "FILE.rcache")]
    pub(crate) cache_in: Option<PathBuf>,
    /// Write the cache's records after the last frame rendered to this file (atomically).
    #[arg(long, value_name = "FILE.rcache")]
    pub(crate) cache_out: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) env: EnvArgs,
    /// Write the run's timeline (GPU passes, host work) in the Chrome trace event format, for
    /// Perfetto or chrome://tracing.
    #[arg(long, value_name = "FILE.json")]
    pub(crate) profile: Option<PathBuf>,
    /// Write per-frame statistics as JSON (times, rays, passes, live device memory), with the
    /// run's configuration, host times and memory (the upload's planned device peak by part, the
    /// peak resident host memory).
    #[arg(long, value_name = "FILE.json")]
    pub(crate) stats: Option<PathBuf>,
    /// Store half floats in the EXR.
    #[arg(long)]
    pub(crate) half: bool,
    /// Add albedo, normal and depth layers to the EXR.
    #[arg(long)]
    pub(crate) aov: bool,
    /// Add the cache's debug layers to the EXR: `ic_indirect` (indirect radiance only),
    /// `ic_weight` (Σw), `ic_records` (records per pixel), `ic_positions` (record positions).
    #[arg(long)]
    pub(crate) debug_aov: bool,
    /// Also write a PNG preview beside the EXR.
    #[arg(long)]
    pub(crate) png: bool,
    /// After a sequence, write its frames (rendered or already on disk as EXR) reduced to at
    /// most 160 pixels and tiled into this PNG.
    #[arg(long, value_name = "FILE.png")]
    pub(crate) contact_sheet: Option<PathBuf>,
    /// Exposure of the PNG preview, in stops.
    #[arg(long, default_value_t = 0.0)]
    pub(crate) exposure: f32,
    /// Tone curve of the PNG preview.
    #[arg(long, default_value = "none", value_parser = ["none", "filmic"])]
    pub(crate) tonemap: String,
    /// No progress bars, per-frame lines or pass table (warnings and errors stay).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// `--resolution WxH`, else 512 pixels high at the camera's aspect ratio.
pub fn image_size(resolution: Option<&str>, view: &CameraView) -> Result<(u32, u32)> {
    match resolution {
        Some(r) => parse_resolution(r),
        None => {
            let aspect = view.perspective.aspect_or(1.0);
            Ok((((512.0 * aspect).round() as u32).max(1), 512))
        }
    }
}

/// Parses `--resolution WxH` (each side in 1..=16384).
pub fn parse_resolution(text: &str) -> Result<(u32, u32)> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("--resolution {text:?}: expected WxH, e.g. 640x480"))?;
    let w: u32 = w
        .trim()
        .parse()
        .with_context(|| format!("--resolution {text:?}: bad width"))?;
    let h: u32 = h
        .trim()
        .parse()
        .with_context(|| format!("--resolution {text:?}: bad height"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        bail!("--resolution {text:?}: each side must be in 1..=16384");
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_is_checked() {
        assert_eq!(parse_resolution("64x48").unwrap(), (64, 48));
        assert_eq!(parse_resolution(" 8 X 9 ").unwrap(), (8, 9));
        for bad in ["64", "0x5", "ax5", "5x99999"] {
            let err = parse_resolution(bad).unwrap_err().to_string();
            assert!(err.contains("--resolution"), "{bad}: {err}");
        }
    }

    #[test]
    fn environment_radiance_is_three_non_negative_numbers() {
        assert_eq!(parse_rgb("0.5, 0.6,0.8").unwrap(), [0.5, 0.6, 0.8]);
        for bad in ["1,2", "1,2,3,4", "a,b,c", "-1,0,0", "inf,0,0"] {
            let err = parse_rgb(bad).unwrap_err().to_string();
            assert!(err.contains("--env-radiance"), "{bad}: {err}");
        }
    }
}
