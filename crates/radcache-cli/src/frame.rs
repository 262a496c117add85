//! One frame of `radcache render`: render it (path tracer, or the cache's renderer kept across
//! the frames of a sequence), assemble the image with its layers and metadata, write it
//! atomically, and describe it for the stats file.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use radcache_image::{
    png_beside, write_exr, write_png, ExrOptions, Image, Layer, Metadata, PngOptions, ToneMap,
};
use radcache_render::{
    render_aovs, render_path, vulkan_clip_from_view, Budget, FrameOutput, GpuScene, IcRenderer,
    IcSettings, IcStats, PathSettings,
};
use radcache_scene::Scene;
use radcache_vk::{Context, ShaderCompiler};
use serde_json::{json, Value};

use crate::args::ic::IcArgs;
use crate::args::{Method, RenderArgs};
use crate::progress::FrameBar;

/// What stays the same over the frames of a run.
pub struct FrameSetup<'a> {
    pub args: &'a RenderArgs,
    pub ctx: &'a Context,
    pub shaders: &'a ShaderCompiler,
    pub scene: &'a Scene,
    pub size: (u32, u32),
    pub budget: Budget,
    /// Keep the cache's records from frame to frame.
    pub temporal: bool,
    /// More than one frame is rendered.
    pub sequence: bool,
    /// Seconds per frame when records need lifespans (moving geometry or lights), else 0.
    pub time_step_s: f32,
    /// The render's configuration as command-line arguments ([`config_args`]), in every EXR's
    /// metadata (`radcache.extra.config`) and the stats.
    pub config: String,
}

impl std::fmt::Debug for FrameSetup<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameSetup")
            .field("size", &self.size)
            .field("temporal", &self.temporal)
            .finish_non_exhaustive()
    }
}

/// A rendered frame.
#[derive(Debug)]
pub struct Rendered {
    pub out: FrameOutput,
    pub ic: Option<IcStats>,
    /// When the frame's rendering started (its spans count from here).
    pub started: Instant,
    /// When the cache's renderer was created (passes and pipelines), on the first frame.
    pub created: Option<(Instant, Instant)>,
}

/// Renders `frame` at scene time `time`. The cache's renderer is created on the first frame and
/// kept in `ic`; without `setup.temporal` it forgets its records before every frame. A
/// `warm_up` frame (not written: only its records matter) shades the cache's sub-frames alone,
/// without adaptive anti-aliasing, which changes no record.
pub fn render(
    setup: &FrameSetup<'_>,
    gpu: &mut GpuScene,
    ic: &mut Option<IcRenderer>,
    frame: u32,
    time: f32,
    warm_up: bool,
) -> Result<Rendered> {
    let args = setup.args;
    let (width, height) = setup.size;
    match args.method {
        Method::Path => {
            let settings = PathSettings {
                width,
                height,
                budget: setup.budget,
                seed: args.seed,
                frame,
                time,
                aovs: args.aov,
                ..PathSettings::default()
            };
            let bar = FrameBar::new(format!("frame {frame}"), "spp", args.quiet);
            let started = Instant::now();
            let out = render_path(
                setup.ctx,
                setup.shaders,
                setup.scene,
                gpu,
                &settings,
                &mut |p| bar.update(p.done, p.total),
            )?;
            bar.finish();
            Ok(Rendered {
                out,
                ic: None,
                started,
                created: None,
            })
        }
        Method::Ic => {
            let settings = IcSettings {
                frame,
                time,
                debug_aovs: args.debug_aov,
                settle_records: setup.temporal && setup.sequence,
                time_step_s: setup.time_step_s,
                ..ic_settings(&args.ic, setup.size, args.seed)?
            };
            let mut created = None;
            let renderer = match ic {
                Some(r) => r,
                None => {
                    let start = Instant::now();
                    let mut r = IcRenderer::new(setup.ctx, setup.shaders, gpu, &settings)?;
                    if let Some(path) = &args.cache_in {
                        let (ctx, shaders) = (setup.ctx, setup.shaders);
                        let n = crate::cache_io::import(
                            path,
                            &mut r,
                            ctx,
                            shaders,
                            setup.scene,
                            gpu,
                            &settings,
                        )?;
                        if !args.quiet {
                            crate::progress::line(&format!(
                                "loaded {n} records from {}",
                                path.display()
                            ));
                        }
                    }
                    created = Some((start, Instant::now()));
                    ic.insert(r)
                }
            };
            if !setup.temporal {
                renderer.forget();
            }
            let settings = IcSettings {
                anti_aliasing: settings.anti_aliasing.filter(|_| !warm_up),
                ..settings
            };
            let bar = FrameBar::new(format!("frame {frame}"), "sub-frame phases", args.quiet);
            let started = Instant::now();
            let (mut out, stats) =
                renderer.render(setup.ctx, setup.scene, gpu, &settings, &mut |p| {
                    bar.update(p.done, p.total)
                })?;
            bar.finish();
            if args.aov {
                out.aovs = Some(render_aovs(setup.ctx, setup.shaders, gpu, width, height)?);
            }
            Ok(Rendered {
                out,
                ic: Some(stats),
                started,
                created,
            })
        }
    }
}

/// The cache's settings of `--method ic` at `size` with `seed` (frame 1 at time 0, one frame
/// without temporal caching: the caller sets those).
pub fn ic_settings(ic: &IcArgs, size: (u32, u32), seed: u32) -> Result<IcSettings> {
    let defaults = IcSettings::preset(ic.preset());
    let mut settings = IcSettings {
        width: size.0,
        height: size.1,
        params: ic.params()?,
        sub_frames: ic.sub_frames.unwrap_or(defaults.sub_frames).max(1),
        direct_samples: ic.direct_samples.unwrap_or(defaults.direct_samples).max(1),
        anti_aliasing: ic.anti_aliasing()?,
        seed,
        ..defaults
    };
    ic.apply_sets(&mut settings)?;
    Ok(settings)
}

/// The configuration a render of `args` at `size` was made with, as the command-line
/// arguments that give it again (`radcache render --config-from`): the method, the size, the
/// seed and, for the cache, its options with every technique switch resolved
/// ([`IcArgs::config_args`]).
pub fn config_args(args: &RenderArgs, size: (u32, u32)) -> Result<Vec<String>> {
    let mut out = vec![
        "--method".to_string(),
        args.method.name().to_string(),
        "--resolution".to_string(),
        format!("{}x{}", size.0, size.1),
        "--seed".to_string(),
        args.seed.to_string(),
    ];
    match args.method {
        Method::Ic => {
            let settings = ic_settings(&args.ic, size, args.seed)?;
            out.extend(args.ic.config_args(&settings));
        }
        Method::Path => {
            if let Some(spp) = args.spp {
                out.extend(["--spp".to_string(), spp.to_string()]);
            }
            if let Some(t) = args.time_budget {
                out.extend(["--time-budget".to_string(), t.to_string()]);
            }
        }
    }
    Ok(out)
}

/// The frame's image with its AOV and debug layers.
pub fn image(r: &Rendered) -> Result<Image> {
    let out = &r.out;
    let mut image = Image::from_pixels(out.width, out.height, out.pixels.clone())?;
    if let Some(aovs) = &out.aovs {
        image.add_layer(Layer::albedo(aovs.albedo.clone()))?;
        image.add_layer(Layer::normal(aovs.normal.clone()))?;
        image.add_layer(Layer::depth(aovs.depth.clone()))?;
    }
    if let Some(debug) = r.ic.as_ref().and_then(|s| s.debug.as_ref()) {
        let rgb = || vec!["R".to_string(), "G".to_string(), "B".to_string()];
        let y = || vec!["Y".to_string()];
        image.add_layer(Layer::new("ic_indirect", rgb(), debug.indirect.clone())?)?;
        image.add_layer(Layer::new("ic_weight", y(), debug.weight_sum.clone())?)?;
        let per_pixel = debug.records_per_pixel.clone();
        image.add_layer(Layer::new("ic_records", y(), per_pixel)?)?;
        let positions = debug.record_positions.clone();
        image.add_layer(Layer::new("ic_positions", y(), positions)?)?;
    }
    Ok(image)
}

/// The EXR metadata of a frame.
pub fn metadata(setup: &FrameSetup<'_>, r: &Rendered, frame: u32, time: f32) -> Metadata {
    let args = setup.args;
    let (width, height) = setup.size;
    let view = setup.scene.camera_at(time);
    let mut meta = Metadata::new();
    meta.method = Some(args.method.name().into());
    meta.spp = Some(r.out.spp);
    if let Some(stats) = &r.ic {
        meta.extra.insert(
            "quality".into(),
            format!("{:?}", args.ic.quality).to_lowercase(),
        );
        meta.extra
            .insert("records".into(), stats.records.to_string());
    }
    meta.render_time_s = Some(r.out.time_s);
    meta.scene_file = Some(args.scene.display().to_string());
    meta.world_from_camera = Some(view.world_from_camera.to_cols_array());
    let aspect = width as f32 / height as f32;
    meta.projection = Some(
        vulkan_clip_from_view(view.perspective.yfov, aspect, view.perspective.znear)
            .to_cols_array(),
    );
    meta.extra.insert("seed".into(), args.seed.to_string());
    meta.extra.insert("frame".into(), frame.to_string());
    meta.extra.insert("time".into(), time.to_string());
    meta.extra
        .insert("device".into(), setup.ctx.info().name.clone());
    meta.extra.insert(CONFIG_KEY.into(), setup.config.clone());
    meta
}

/// The metadata key of the render's configuration (`radcache.extra.config` in an EXR).
pub const CONFIG_KEY: &str = "config";

/// The PNG previews' exposure and tone curve.
pub fn png_options(args: &RenderArgs) -> PngOptions {
    PngOptions {
        exposure: args.exposure,
        tone_map: if args.tonemap == "filmic" {
            ToneMap::Filmic
        } else {
            ToneMap::None
        },
    }
}

/// Writes the frame to `output` (EXR, or PNG when the path says so; a PNG preview beside the EXR
/// with `--png`), each file atomically.
pub fn write(args: &RenderArgs, output: &Path, image: &Image, meta: &Metadata) -> Result<()> {
    crate::output::make_parent(output, "output")?;
    let png_options = png_options(args);
    let png_only = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png_only {
        write_png(output, image, &png_options)?;
    } else {
        let exr = ExrOptions {
            half: args.half,
            ..ExrOptions::default()
        };
        write_exr(output, image, meta, &exr)?;
        if args.png {
            write_png(png_beside(output), image, &png_options)?;
        }
    }
    Ok(())
}

/// The frame's entry in the stats file.
pub fn stats_entry(r: &Rendered, frame: u32, time: f32) -> Value {
    let out = &r.out;
    let mut entry = json!({
        "frame": frame,
        "time": time,
        "time_s": out.time_s,
        "spp": out.spp,
        "rays": out.rays,
        "passes_ms": out.passes_ms,
        "nonfinite_pixels": out.nonfinite_pixels,
    });
    if let Some(ic) = &r.ic {
        entry["records"] = json!(ic.records);
        entry["records_kept"] = json!(ic.records_kept);
        entry["records_evicted"] = json!(ic.records_evicted);
        entry["records_refreshed"] = json!(ic.records_refreshed);
        entry["record_rays"] = json!(ic.record_rays);
        entry["lookahead_rays"] = json!(ic.lookahead_rays);
        entry["cache_passes"] = json!(ic.cache_passes);
        entry["records_created"] = json!(ic.records_per_level.iter().sum::<u64>());
        entry["records_per_level"] = json!(ic.records_per_level);
        entry["holes_left"] = json!(ic.holes_left);
        entry["unmatched_samples"] = json!(ic.unmatched_samples);
        entry["sub_frames_shaded"] = json!(ic.sub_frames_shaded);
        entry["mean_pixel_sub_frames"] = json!(ic.mean_pixel_sub_frames);
        entry["dropped_requests"] = json!(ic.dropped_requests);
        entry["rejected_records"] = json!(ic.rejected_records);
        entry["phases_wall_s"] = json!(ic.phases_s);
        if let Some(estimate) = ic.aa_relmse_estimate {
            entry["aa_relmse_estimate"] = json!(estimate);
        }
    }
    if let Some((from, to)) = r.created {
        // Creating the cache's renderer: shaders, pipelines and pass buffers (first frame only).
        entry["pipelines_s"] = json!(to.duration_since(from).as_secs_f64());
    }
    entry
}

/// The stats file's `pipelines` entry: pipelines created so far, how many the driver compiled
/// from scratch (not found in the persistent pipeline cache; on a driver whose cache keeps
/// nothing, `driver_cache_bytes` 32, every one), how many radcache's index knew from an earlier
/// run, the seconds their creation took; and the GLSL modules compiled to SPIR-V (by shaderc, or
/// read from the on-disk SPIR-V cache).
pub fn pipelines_entry(setup: &FrameSetup<'_>) -> Value {
    let p = setup.ctx.pipeline_stats();
    let s = setup.shaders.stats();
    json!({
        "created": p.created,
        "compiled_from_scratch": p.compiled_from_scratch,
        "cache_hits": p.cache_hits,
        "indexed": p.indexed,
        "creation_s": p.creation_s,
        "driver_cache_bytes": p.driver_cache_bytes,
        "cache_file": setup.ctx.pipeline_cache_file(),
        "shaders": {
            "compiled": s.compiled,
            "from_disk": s.from_disk,
            "compile_s": s.compile_s,
        },
    })
}

/// Shuts the device down after every GPU object of the run was dropped; fails when the
/// validation layer reported an error (a bug, even where the outputs are already written).
pub fn shut_down(ctx: Context) -> Result<()> {
    let first = ctx.first_validation_error();
    let report = ctx.shutdown();
    if report.validation_errors > 0 {
        anyhow::bail!(
            "{} Vulkan validation errors (first: {})",
            report.validation_errors,
            first.unwrap_or_default()
        );
    }
    Ok(())
}
