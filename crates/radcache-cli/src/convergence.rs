//! `radcache convergence SCENE -o OUT_DIR`: error against run time for the irradiance cache and
//! the path tracer on one frame of a scene.
//!
//! One GPU context for the run; a warm-up frame of each method takes the shader compilation. The
//! reference is `--reference REF.exr` or rendered here by the path tracer at `--reference-spp`
//! (written to `OUT_DIR/reference.exr`). The path tracer is measured at 1, 2, 4, …, `--max-spp`
//! spp, the cache at its presets and over an accuracy and a hemisphere-size sweep; every point's
//! wall and GPU time and its `compare` metrics go to `points.csv`, a log–log plot of relMSE
//! against wall time to `error_vs_time.svg`/`.png`, and `summary.md` gives the Pareto front and,
//! per cache point, the path tracer's time to reach the same error and the speed-up
//! (definitions in [`radcache_image::equal_error`], which `cargo xtask bench ic` uses too).

mod ladder;
mod plot;
mod report;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use clap::Args;
use radcache_cache::WeightKind;
use radcache_image::equal_error::{self, PtPoint};
use radcache_image::{read_exr, write_exr, ExrOptions, Image, Metadata};
use radcache_render::{EnvMap, GpuScene};
use radcache_scene::{Environment, LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};

use crate::args::ic::Weight;
use crate::args::{parse_resolution, shader_root};
use crate::progress::{self, FrameBar};
use crate::sequence::{FrameArgs, Sequence};
use ladder::{Bench, Ladder, Point};

/// Options of `radcache convergence`.
#[derive(Args, Debug)]
pub struct ConvergenceArgs {
    /// The glTF scene (.gltf or .glb).
    scene: PathBuf,
    /// Output folder (created): points.csv, error_vs_time.svg/.png, summary.md.
    #[arg(short, long, value_name = "OUT_DIR")]
    output: PathBuf,
    /// Reference EXR; default: rendered with the path tracer at --reference-spp.
    #[arg(long, value_name = "REF.exr")]
    reference: Option<PathBuf>,
    /// Samples per pixel of the reference rendered by the command.
    #[arg(long, default_value_t = 1024, conflicts_with = "reference")]
    reference_spp: u32,
    /// Image size WxH; default the reference's size, else 128 pixels high at the camera's aspect.
    #[arg(long, value_name = "WxH")]
    resolution: Option<String>,
    /// The path tracer's ladder: 1, 2, 4, … up to this power of two (default 256; 16 with
    /// --quick).
    #[arg(long, value_name = "N")]
    max_spp: Option<u32>,
    /// Short ladders (CI): the path tracer to 16 spp, two accuracy and two strata points.
    #[arg(long)]
    quick: bool,
    /// The cache's weight; the accuracy sweep varies its parameter (Ward's a, or T&L's κ).
    #[arg(long, value_enum, default_value_t = Weight::Tl)]
    weight: Weight,
    /// Measure this frame of an animated scene (its time: see --fps and --start-time).
    #[arg(long)]
    frame: Option<u32>,
    /// Frames per second: frame f shows the scene at start + (f − 1)/fps.
    #[arg(long, default_value_t = 24.0)]
    fps: f32,
    /// Scene time of frame 1 (default: the animation's first key, else 0).
    #[arg(long)]
    start_time: Option<f32>,
    /// A technique switch of every cache point, `KEY=VALUE` as `radcache render --set`
    /// (repeatable; a ladder's own choice, the glossy ladder's, comes after it).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// No progress lines.
    #[arg(long, short)]
    quiet: bool,
}

/// Where the reference comes from.
enum Reference {
    /// Read from a file: the image, and its spp when its metadata says it was path-traced.
    File(PathBuf, Image, Option<u32>),
    /// To be rendered here at this spp.
    Render(u32),
}

/// Frame `--frame N` and its scene time as `radcache render --frame N` has it
/// (`start + (N − 1)/fps`, the same rule and checks).
fn frame_time(args: &ConvergenceArgs, range: Option<(f32, f32)>) -> Result<(u32, f32)> {
    let frame = args.frame.unwrap_or(1);
    if frame == 0 {
        bail!("--frame counts from 1, got 0");
    }
    let sequence = Sequence::new(
        &FrameArgs {
            frame: Some(frame),
            start_time: args.start_time,
            fps: args.fps,
            pattern: true,
            ..FrameArgs::default()
        },
        range,
    )?;
    sequence
        .frames
        .last()
        .copied()
        .context("the frame range is empty")
}

/// Runs the command.
pub fn run(args: &ConvergenceArgs) -> Result<ExitCode> {
    let started = Instant::now();
    let max_spp = args.max_spp.unwrap_or(if args.quick { 16 } else { 256 });
    if max_spp == 0 || !max_spp.is_power_of_two() {
        bail!("--max-spp must be a power of two (1, 2, 4, …), got {max_spp}");
    }
    // The switches are checked before anything is rendered.
    crate::args::ic::apply_sets(&args.set, &mut radcache_render::IcSettings::default())?;
    if args.reference_spp == 0 {
        bail!("--reference-spp must be at least 1");
    }
    if !args.scene.is_file() {
        bail!("the scene file {} does not exist", args.scene.display());
    }
    let font = plot::load_font()?;
    log::info!("plot font: {}", font.display());

    let reference = match &args.reference {
        Some(path) => {
            let (image, meta) = read_exr(path).context("reading the reference")?;
            let spp = meta.spp.filter(|_| meta.method.as_deref() == Some("path"));
            Reference::File(path.clone(), image, spp)
        }
        None => Reference::Render(args.reference_spp),
    };
    // The loader's errors name the file, and it logs its warnings itself.
    let (scene, _warnings) = Scene::load(&args.scene, &LoadOptions::default())?;
    let env_map = match &scene.environment {
        Environment::Map { path, .. } => Some(EnvMap::load(path)?),
        _ => None,
    };
    let (frame, time) = frame_time(args, scene.plan().animation.time_range)?;
    let size = match (&args.resolution, &reference) {
        (Some(r), Reference::File(path, image, _)) => {
            let size = parse_resolution(r)?;
            if size != (image.width(), image.height()) {
                bail!(
                    "--resolution {r} differs from the reference {} ({}x{})",
                    path.display(),
                    image.width(),
                    image.height()
                );
            }
            size
        }
        (Some(r), _) => parse_resolution(r)?,
        (None, Reference::File(_, image, _)) => (image.width(), image.height()),
        (None, _) => {
            let aspect = scene.camera_at(time).perspective.aspect_or(1.0);
            (((128.0 * aspect).round() as u32).max(1), 128)
        }
    };
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating the output folder {}", args.output.display()))?;

    let ctx = Context::new()?;
    let device = ctx.info().name.clone();
    // Compiled shaders are kept beside the pipeline cache (docs/design.md, "Pipeline cache").
    let spirv_dir = radcache_vk::pipeline_cache_dir_from_env();
    let shaders = ShaderCompiler::new(shader_root())?.with_disk_cache(spirv_dir.as_deref());
    let mut gpu = GpuScene::new(&ctx, &scene, env_map.as_ref())?;
    let bench = Bench {
        ctx: &ctx,
        shaders: &shaders,
        scene: &scene,
        size,
        frame,
        time,
        sets: &args.set,
    };
    let say = |text: String| {
        if !args.quiet {
            progress::line(&text);
        }
    };
    bench.warm_up(&mut gpu)?;
    let (reference, reference_spp, how) = match reference {
        Reference::File(path, image, spp) => {
            let how = match spp {
                Some(s) => format!(
                    "read from `{}` (path-traced, {s} spp per its metadata)",
                    path.display()
                ),
                None => format!(
                    "read from `{}` (not marked as path-traced with a spp: taken as noise-free)",
                    path.display()
                ),
            };
            (image, spp, how)
        }
        Reference::Render(spp) => {
            let bar = FrameBar::new("reference", "spp", args.quiet);
            let (image, out) = bench.reference(&mut gpu, spp, &mut |d, t, _| bar.update(d, t))?;
            bar.finish();
            let path = args.output.join("reference.exr");
            write_exr(
                &path,
                &image,
                &reference_meta(args, &device, spp, frame, time, out.time_s),
                &ExrOptions::default(),
            )?;
            say(format!(
                "reference: {spp} spp in {:.2} s, written to {}",
                out.time_s,
                path.display()
            ));
            let how = format!(
                "rendered by this command with the path tracer at {spp} spp (seed {}, unlike \
                 every ladder point) in {:.2} s, written to `reference.exr`",
                ladder::REFERENCE_SEED,
                out.time_s
            );
            (image, Some(spp), how)
        }
    };

    let mut points = Vec::new();
    for spp in ladder::pt_ladder(max_spp) {
        let p = bench.path(&mut gpu, &reference, spp)?;
        say(format!(
            "PT {spp:>5} spp: {:8.3} s, relMSE {:.3e}",
            p.wall_s, p.metrics.relmse
        ));
        points.push(p);
    }
    let weight = match args.weight {
        Weight::Tl => WeightKind::TabellionLamorlette,
        Weight::Ward => WeightKind::Ward,
    };
    let glossy = scene.plan().radiance_cache();
    for case in ladder::ic_cases(weight, args.quick, glossy) {
        let p = bench.ic(&mut gpu, &reference, &case)?;
        say(format!(
            "IC {:>14}: {:8.3} s, relMSE {:.3e}",
            p.label, p.wall_s, p.metrics.relmse
        ));
        points.push(p);
    }
    drop(gpu);
    crate::frame::shut_down(ctx)?;

    let (c, e_ref) = analyse(&mut points, reference_spp);
    let info = report::RunInfo {
        scene: args.scene.display().to_string(),
        frame: (frame, time),
        size,
        device,
        reference: how,
        reference_spp,
        noise_constant: c,
        reference_noise: e_ref,
        weight: ladder::weight_name(weight),
        total_s: started.elapsed().as_secs_f64(),
    };
    write_outputs(&args.output, &info, &points)?;
    say(format!(
        "wrote {}/{{points.csv, error_vs_time.svg, error_vs_time.png, summary.md}}",
        args.output.display()
    ));
    Ok(ExitCode::SUCCESS)
}

/// Fills the derived columns: own relMSE, the path tracer's time to match and the Pareto front.
/// Returns the fit's `c` and the reference's own relMSE.
fn analyse(points: &mut [Point], reference_spp: Option<u32>) -> (Option<f64>, f64) {
    let pt: Vec<(u32, f64)> = points
        .iter()
        .filter_map(|p| Some((p.spp?, p.metrics.relmse)))
        .collect();
    let c = equal_error::noise_constant(&pt, reference_spp);
    let e_ref = equal_error::reference_noise(c, reference_spp);
    for p in points.iter_mut() {
        p.own_relmse = p.metrics.relmse - e_ref;
    }
    let curve: Vec<PtPoint> = points
        .iter()
        .filter(|p| p.ladder == Ladder::Spp)
        .map(|p| PtPoint {
            spp: p.spp.unwrap_or(0),
            time_s: p.wall_s,
            error: p.own_relmse,
        })
        .collect();
    for p in points.iter_mut().filter(|p| p.ic.is_some()) {
        p.matched = equal_error::pt_time_to_match(&curve, p.own_relmse);
    }
    // The per-pixel glossy paths' curve, over the presets (scenes with radiance records).
    let paths: Vec<PtPoint> = points
        .iter()
        .filter(|p| p.ladder == Ladder::GlossyPaths)
        .enumerate()
        .map(|(i, p)| PtPoint {
            spp: i as u32 + 1,
            time_s: p.wall_s,
            error: p.own_relmse,
        })
        .collect();
    if !paths.is_empty() {
        for p in points.iter_mut().filter(|p| p.ladder == Ladder::Preset) {
            p.matched_paths = equal_error::pt_time_to_match(&paths, p.own_relmse);
        }
    }
    let xy: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.wall_s, p.metrics.relmse))
        .collect();
    for i in equal_error::pareto_front(&xy) {
        points[i].pareto = true;
    }
    (c, e_ref)
}

fn reference_meta(
    args: &ConvergenceArgs,
    device: &str,
    spp: u32,
    frame: u32,
    time: f32,
    time_s: f64,
) -> Metadata {
    let mut meta = Metadata::new();
    meta.method = Some("path".into());
    meta.spp = Some(spp);
    meta.render_time_s = Some(time_s);
    meta.scene_file = Some(args.scene.display().to_string());
    meta.extra
        .insert("seed".into(), ladder::REFERENCE_SEED.to_string());
    meta.extra.insert("frame".into(), frame.to_string());
    meta.extra.insert("time".into(), time.to_string());
    meta.extra.insert("device".into(), device.to_string());
    meta
}

fn write_outputs(dir: &Path, info: &report::RunInfo, points: &[Point]) -> Result<()> {
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))
    };
    write("points.csv", report::csv(points))?;
    let title = format!(
        "{} (frame {}, {}x{}): relMSE against wall time",
        Path::new(&info.scene)
            .file_name()
            .map_or(info.scene.clone(), |n| n.to_string_lossy().into_owned()),
        info.frame.0,
        info.size.0,
        info.size.1
    );
    plot::write(
        &dir.join("error_vs_time.svg"),
        &dir.join("error_vs_time.png"),
        &title,
        points,
        info.reference_noise,
    )?;
    write("summary.md", report::summary(info, points))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: ConvergenceArgs,
    }

    fn args(extra: &[&str]) -> ConvergenceArgs {
        let mut argv = vec!["radcache", "scene.gltf", "-o", "out"];
        argv.extend_from_slice(extra);
        Cli::try_parse_from(argv).unwrap().args
    }

    #[test]
    fn frame_n_shows_the_scene_at_start_plus_n_minus_one_over_fps() {
        let animated = Some((0.25, 2.0));
        assert_eq!(frame_time(&args(&[]), animated).unwrap(), (1, 0.25));
        let (frame, time) = frame_time(&args(&["--frame", "13"]), animated).unwrap();
        assert_eq!(frame, 13);
        assert!((time - (0.25 + 12.0 / 24.0)).abs() < 1e-6, "{time}");
        let a = args(&["--frame", "5", "--fps", "10", "--start-time", "1"]);
        let (_, time) = frame_time(&a, None).unwrap();
        assert!((time - 1.4).abs() < 1e-6, "{time}");
        let err = frame_time(&args(&["--frame", "0"]), None).unwrap_err();
        assert!(err.to_string().contains("--frame"), "{err}");
        assert!(frame_time(&args(&["--fps", "0"]), None).is_err());
    }
}
