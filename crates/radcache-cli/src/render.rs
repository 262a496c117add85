//! `radcache render SCENE -o OUT.exr`: load, upload, render, write; one frame or a sequence
//! (`-o out/frame_####.exr --frames 1..120`), resumable, with the cache kept across frames
//! where the plan allows.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use radcache_render::{Budget, EnvMap, GpuScene};
use radcache_scene::{EnvOverride, Environment, LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};
use serde_json::json;

use crate::frame::{self, FrameSetup};
use crate::ic_args::IcArgs;
use crate::profile::Profile;
use crate::sequence::{ContactSheet, FrameArgs, Sequence, SequenceProgress};

/// Environment overrides shared by `render` and `info`.
#[derive(Args, Debug, Clone)]
pub struct EnvArgs {
    /// Equirectangular EXR environment map (+Y up; see the README for the convention).
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
    #[command(flatten)]
    pub(crate) env: EnvArgs,
    /// Write the run's timeline (GPU passes, host work) in the Chrome trace event format, for
    /// Perfetto or chrome://tracing.
    #[arg(long, value_name = "FILE.json")]
    pub(crate) profile: Option<PathBuf>,
    /// Write per-frame statistics as JSON.
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
    /// No progress line.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

fn parse_resolution(text: &str) -> Result<(u32, u32)> {
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

pub fn run(args: &RenderArgs) -> Result<ExitCode> {
    let budget = match (args.spp, args.time_budget) {
        (_, Some(s)) if !(s.is_finite() && s > 0.0) => bail!("--time-budget must be positive"),
        (_, Some(s)) => Budget::Seconds(s),
        (Some(0), _) => bail!("--spp must be at least 1"),
        (Some(n), None) => Budget::Samples(n),
        (None, None) => Budget::Samples(64),
    };
    let pattern = args.output.to_string_lossy().contains('#');
    let mut profile = Profile::new();

    let t_load = Instant::now();
    let opts = LoadOptions {
        camera_name: args.camera.clone(),
        env: args.env.to_override()?,
    };
    let (scene, warnings) = Scene::load(&args.scene, &opts)?;
    for w in &warnings {
        log::warn!("{w}");
    }
    let env_map = match &scene.environment {
        Environment::Map { path, .. } => Some(EnvMap::load(path)?),
        _ => None,
    };
    let load_s = t_load.elapsed().as_secs_f64();
    profile.cpu("scene load", t_load, Instant::now(), None);
    let plan = scene.plan();
    let sequence = Sequence::new(
        &FrameArgs {
            frames: args.frames.as_deref(),
            frame: args.frame,
            time: args.time,
            start_time: args.start_time,
            fps: args.fps,
            pattern,
        },
        plan.animation.time_range,
    )?;

    let view = scene.camera_at(sequence.frames[0].1);
    let size = match &args.resolution {
        Some(r) => parse_resolution(r)?,
        None => {
            let aspect = view.perspective.aspect_or(1.0);
            (((512.0 * aspect).round() as u32).max(1), 512)
        }
    };

    let ctx = Context::new()?;
    let shaders = ShaderCompiler::new(crate::shader_root())?;
    let t_upload = Instant::now();
    let mut gpu = GpuScene::new(&ctx, &scene, env_map.as_ref())?;
    let upload_s = t_upload.elapsed().as_secs_f64();
    profile.cpu(
        "upload + acceleration structures",
        t_upload,
        Instant::now(),
        None,
    );
    // Records are kept across frames; where geometry or lights move they carry lifespans
    // (temporal caching, a time step of one frame).
    let temporal = !args.no_temporal;
    let time_step_s = if temporal && sequence.frames.len() > 1 && plan.needs_lifespans() {
        1.0 / args.fps
    } else {
        0.0
    };
    let setup = FrameSetup {
        args,
        ctx: &ctx,
        shaders: &shaders,
        scene: &scene,
        size,
        budget,
        temporal,
        sequence: sequence.frames.len() > 1,
        time_step_s,
    };
    let stop = interrupt_flag(sequence.frames.len() > 1);
    let mut progress = SequenceProgress::new(sequence.frames.len(), args.quiet);
    let mut ic = None;
    let mut entries = Vec::new();
    let mut write_s = 0.0;
    let mut stopped = false;
    let mut sheet = ContactSheet::new(args.contact_sheet.clone());
    for &(number, time) in &sequence.frames {
        if stop.load(Ordering::SeqCst) {
            stopped = true;
            break;
        }
        let output = if pattern {
            radcache_image::frame_path(&args.output, number)?
        } else {
            args.output.clone()
        };
        if pattern && !args.overwrite && output.exists() {
            progress.skipped(number, &output);
            sheet.add_file(&output)?;
            continue;
        }
        let t_frame = Instant::now();
        let rendered = frame::render(&setup, &mut gpu, &mut ic, number, time)?;
        if rendered.out.nonfinite_pixels > 0 {
            log::warn!(
                "frame {number}: {} pixels were non-finite and written as black",
                rendered.out.nonfinite_pixels
            );
        }
        if let Some((from, to)) = rendered.created {
            profile.cpu("pipelines", from, to, Some(number));
        }
        profile.frame(number, rendered.started, &rendered.out);
        let t_image = Instant::now();
        let image = frame::image(&rendered)?;
        let meta = frame::metadata(&setup, &rendered, number, time);
        let t_write = Instant::now();
        profile.cpu("image + metadata", t_image, t_write, Some(number));
        frame::write(args, &output, &image, &meta)?;
        sheet.add(&image);
        profile.cpu("write", t_write, Instant::now(), Some(number));
        let mut entry = frame::stats_entry(&rendered, number, time);
        entry["device_memory_bytes"] = json!(ctx.memory_by_category());
        entries.push(entry);
        if let Some(path) = &args.stats {
            write_stats(path, &setup, &entries, [load_s, upload_s, write_s])?;
        }
        write_s += t_write.elapsed().as_secs_f64();
        if !args.quiet && sequence.frames.len() == 1 {
            let out = &rendered.out;
            let rays: u64 = out.rays.values().sum();
            eprintln!(
                "wrote {} ({}x{}, {}, {} spp, {:.2} s, {:.2} Mrays/s)",
                output.display(),
                size.0,
                size.1,
                frame::method_name(args.method),
                out.spp,
                out.time_s,
                rays as f64 / out.time_s.max(1e-9) / 1e6
            );
        }
        progress.rendered(number, t_frame.elapsed().as_secs_f64());
    }
    progress.finish(stopped);
    sheet.write(&frame::png_options(args))?;
    if let Some(path) = &args.profile {
        profile.write(path)?;
    }
    if !args.quiet {
        eprint!("{}", profile.table());
    }
    drop(ic);
    drop(gpu);
    let first = ctx.first_validation_error();
    let report = ctx.shutdown();
    if report.validation_errors > 0 {
        // The images are written; the run still fails, since a validation error is a bug.
        bail!(
            "{} Vulkan validation errors (first: {})",
            report.validation_errors,
            first.unwrap_or_default()
        );
    }
    Ok(if stopped {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    })
}

/// A flag set by the first Ctrl-C of a sequence render: the frame in flight is finished and
/// written, then the run stops (exit code 130). A second Ctrl-C abandons that frame at once;
/// frames are written atomically, so nothing partial is left at an output path. A single frame
/// keeps the default behaviour (Ctrl-C stops at once).
fn interrupt_flag(sequence: bool) -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    if sequence {
        let seen = flag.clone();
        let installed = ctrlc::set_handler(move || {
            if seen.swap(true, Ordering::SeqCst) {
                eprintln!("\nabandoning the frame in flight");
                std::process::exit(130);
            }
            eprintln!("\nfinishing the frame in flight (Ctrl-C again to abandon it)");
        });
        if let Err(e) = installed {
            log::warn!("Ctrl-C will stop at once: {e}");
        }
    }
    flag
}

/// Writes the stats file (atomically, after every frame, so an interrupted run keeps it).
fn write_stats(
    path: &Path,
    setup: &FrameSetup<'_>,
    frames: &[serde_json::Value],
    cpu_s: [f64; 3],
) -> Result<()> {
    let [load_s, upload_s, write_s] = cpu_s;
    let value = json!({
        "scene": setup.args.scene,
        "method": frame::method_name(setup.args.method),
        "device": setup.ctx.info().name,
        "resolution": [setup.size.0, setup.size.1],
        "temporal": setup.temporal,
        "time_step_s": setup.time_step_s,
        "cpu_s": {"scene_load": load_s, "upload": upload_s, "write": write_s},
        "frames": frames,
    });
    crate::output::write_text(path, &serde_json::to_string_pretty(&value)?, "stats")
}
