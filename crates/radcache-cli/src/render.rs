//! `radcache render SCENE -o OUT.exr`: load, upload, render, write.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use radcache_image::{
    png_beside, write_exr, write_png, ExrOptions, Image, Layer, Metadata, PngOptions, ToneMap,
};
use radcache_render::{
    render_aovs, render_ic, render_path, vulkan_clip_from_view, Budget, EnvMap, GpuScene,
    IcSettings, IcStats, PathSettings,
};
use radcache_scene::{EnvOverride, Environment, LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};
use serde_json::json;

use crate::ic_args::IcArgs;
use crate::progress::ProgressLine;

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
    scene: PathBuf,
    /// Output EXR (or .png for a PNG only); `####` is replaced by the frame number.
    #[arg(short, long)]
    output: PathBuf,
    /// Image size WxH; default 512 pixels high at the camera's aspect ratio.
    #[arg(long, value_name = "WxH")]
    resolution: Option<String>,
    /// Rendering method.
    #[arg(long, value_enum, default_value_t = Method::Ic)]
    method: Method,
    #[command(flatten)]
    ic: IcArgs,
    /// Samples per pixel (path tracer).
    #[arg(long, conflicts_with = "time_budget")]
    spp: Option<u32>,
    /// Sample until this many seconds have passed instead of a fixed spp.
    #[arg(long, value_name = "SECONDS")]
    time_budget: Option<f64>,
    /// Seed of the random sequences.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Scene time in seconds (for animated scenes).
    #[arg(long, default_value_t = 0.0)]
    time: f32,
    /// Frame number (for `####` in the output path and the stats).
    #[arg(long, default_value_t = 1)]
    frame: u32,
    /// Use the camera with this name instead of the scene's first.
    #[arg(long)]
    camera: Option<String>,
    #[command(flatten)]
    env: EnvArgs,
    /// Write per-frame statistics as JSON.
    #[arg(long, value_name = "FILE.json")]
    stats: Option<PathBuf>,
    /// Store half floats in the EXR.
    #[arg(long)]
    half: bool,
    /// Add albedo, normal and depth layers to the EXR.
    #[arg(long)]
    aov: bool,
    /// Add the cache's debug layers to the EXR: `ic_indirect` (indirect radiance only),
    /// `ic_weight` (Σw), `ic_records` (records per pixel), `ic_positions` (record positions).
    #[arg(long)]
    debug_aov: bool,
    /// Also write a PNG preview beside the EXR.
    #[arg(long)]
    png: bool,
    /// Exposure of the PNG preview, in stops.
    #[arg(long, default_value_t = 0.0)]
    exposure: f32,
    /// Tone curve of the PNG preview.
    #[arg(long, default_value = "none", value_parser = ["none", "filmic"])]
    tonemap: String,
    /// No progress line.
    #[arg(long, short)]
    quiet: bool,
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
    let output = radcache_image::frame_path(&args.output, args.frame)
        .unwrap_or_else(|_| args.output.clone());
    let png_only = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));

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

    let view = scene.camera_at(args.time);
    let (width, height) = match &args.resolution {
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
    let (out, ic_stats) = match args.method {
        Method::Path => {
            let settings = PathSettings {
                width,
                height,
                budget,
                seed: args.seed,
                frame: args.frame,
                time: args.time,
                aovs: args.aov,
                ..PathSettings::default()
            };
            let mut bar = ProgressLine::new(format!("frame {}", args.frame), "spp", args.quiet);
            let out = render_path(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |p| {
                bar.update(p.done, p.total, p.elapsed_s)
            })?;
            bar.finish();
            (out, None)
        }
        Method::Ic => {
            let settings = IcSettings {
                width,
                height,
                params: args.ic.params()?,
                sub_frames: args
                    .ic
                    .sub_frames
                    .unwrap_or(IcSettings::default().sub_frames)
                    .max(1),
                direct_samples: args
                    .ic
                    .direct_samples
                    .unwrap_or(IcSettings::default().direct_samples)
                    .max(1),
                seed: args.seed,
                frame: args.frame,
                time: args.time,
                debug_aovs: args.debug_aov,
                ..IcSettings::default()
            };
            let mut bar =
                ProgressLine::new(format!("frame {}", args.frame), "sub-frames", args.quiet);
            let (mut out, stats) =
                render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |p| {
                    bar.update(p.done, p.total, p.elapsed_s)
                })?;
            bar.finish();
            if args.aov {
                out.aovs = Some(render_aovs(&ctx, &shaders, &gpu, width, height)?);
            }
            (out, Some(stats))
        }
    };
    if out.nonfinite_pixels > 0 {
        log::warn!(
            "{} pixels were non-finite and written as black",
            out.nonfinite_pixels
        );
    }

    let mut image = Image::from_pixels(width, height, out.pixels.clone())?;
    if let Some(aovs) = &out.aovs {
        image.add_layer(Layer::albedo(aovs.albedo.clone()))?;
        image.add_layer(Layer::normal(aovs.normal.clone()))?;
        image.add_layer(Layer::depth(aovs.depth.clone()))?;
    }
    if let Some(debug) = ic_stats.as_ref().and_then(|s| s.debug.as_ref()) {
        let rgb = || vec!["R".to_string(), "G".to_string(), "B".to_string()];
        let y = || vec!["Y".to_string()];
        image.add_layer(Layer::new("ic_indirect", rgb(), debug.indirect.clone())?)?;
        image.add_layer(Layer::new("ic_weight", y(), debug.weight_sum.clone())?)?;
        image.add_layer(Layer::new(
            "ic_records",
            y(),
            debug.records_per_pixel.clone(),
        )?)?;
        image.add_layer(Layer::new(
            "ic_positions",
            y(),
            debug.record_positions.clone(),
        )?)?;
    }
    let aspect = width as f32 / height as f32;
    let mut meta = Metadata::new();
    let method = match args.method {
        Method::Path => "path",
        Method::Ic => "ic",
    };
    meta.method = Some(method.into());
    meta.spp = Some(out.spp);
    if let Some(stats) = &ic_stats {
        meta.extra.insert(
            "quality".into(),
            format!("{:?}", args.ic.quality).to_lowercase(),
        );
        meta.extra
            .insert("records".into(), stats.records.to_string());
    }
    meta.render_time_s = Some(out.time_s);
    meta.scene_file = Some(args.scene.display().to_string());
    meta.world_from_camera = Some(view.world_from_camera.to_cols_array());
    meta.projection = Some(
        vulkan_clip_from_view(view.perspective.yfov, aspect, view.perspective.znear)
            .to_cols_array(),
    );
    meta.extra.insert("seed".into(), args.seed.to_string());
    meta.extra.insert("time".into(), args.time.to_string());
    meta.extra.insert("device".into(), ctx.info().name.clone());
    let png_options = PngOptions {
        exposure: args.exposure,
        tone_map: if args.tonemap == "filmic" {
            ToneMap::Filmic
        } else {
            ToneMap::None
        },
    };
    let t_write = Instant::now();
    for path in [Some(output.as_path()), args.stats.as_deref()]
        .into_iter()
        .flatten()
    {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("creating the output folder {}", dir.display()))?;
        }
    }
    if png_only {
        write_png(&output, &image, &png_options)?;
    } else {
        let exr = ExrOptions {
            half: args.half,
            ..ExrOptions::default()
        };
        write_exr(&output, &image, &meta, &exr)?;
        if args.png {
            write_png(png_beside(&output), &image, &png_options)?;
        }
    }
    let write_s = t_write.elapsed().as_secs_f64();
    if let Some(path) = &args.stats {
        let run = RunInfo {
            method,
            size: (width, height),
            cpu_s: [load_s, upload_s, write_s],
        };
        write_stats(path, args, &ctx, &out, ic_stats.as_ref(), &run)?;
    }
    if !args.quiet {
        let rays: u64 = out.rays.values().sum();
        eprintln!(
            "wrote {} ({width}x{height}, {method}, {} spp, {:.2} s, {:.2} Mrays/s)",
            output.display(),
            out.spp,
            out.time_s,
            rays as f64 / out.time_s.max(1e-9) / 1e6
        );
    }
    drop(gpu);
    let first = ctx.first_validation_error();
    let report = ctx.shutdown();
    if report.validation_errors > 0 {
        // The image is written; the run still fails, since a validation error is a bug.
        bail!(
            "{} Vulkan validation errors (first: {})",
            report.validation_errors,
            first.unwrap_or_default()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// What the stats file says about the run besides the frames.
struct RunInfo {
    method: &'static str,
    size: (u32, u32),
    cpu_s: [f64; 3],
}

fn write_stats(
    path: &Path,
    args: &RenderArgs,
    ctx: &Context,
    out: &radcache_render::FrameOutput,
    ic: Option<&IcStats>,
    run: &RunInfo,
) -> Result<()> {
    let (width, height) = run.size;
    let [load_s, upload_s, write_s] = run.cpu_s;
    let mut frame = json!({
        "frame": args.frame,
        "time": args.time,
        "time_s": out.time_s,
        "spp": out.spp,
        "rays": out.rays,
        "passes_ms": out.passes_ms,
        "nonfinite_pixels": out.nonfinite_pixels,
    });
    if let Some(ic) = ic {
        frame["records"] = json!(ic.records);
        frame["records_per_level"] = json!(ic.records_per_level);
        frame["holes_left"] = json!(ic.holes_left);
        frame["dropped_requests"] = json!(ic.dropped_requests);
        frame["rejected_records"] = json!(ic.rejected_records);
        frame["phases_wall_s"] = json!(ic.phases_s);
    }
    let value = json!({
        "scene": args.scene,
        "method": run.method,
        "device": ctx.info().name,
        "resolution": [width, height],
        "cpu_s": {"scene_load": load_s, "upload": upload_s, "write": write_s},
        "frames": [frame],
    });
    let text = serde_json::to_string_pretty(&value)?;
    radcache_image::write_atomic(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|source| radcache_image::Error::Io {
                op: "cannot write",
                path: path.to_path_buf(),
                source,
            })
    })
    .with_context(|| format!("writing stats {}", path.display()))?;
    Ok(())
}
