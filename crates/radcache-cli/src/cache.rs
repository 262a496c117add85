//! `radcache cache info FILE` (a cache file's header) and `radcache cache build SCENE` (the
//! prepass: records computed over every N-th frame of a static scene's camera path, like
//! V-Ray's fly-through irradiance map, so the frames rendered from them create few records).
//! `render --cache-in/--cache-out` are in `cache_io`; the format is
//! `radcache_cache::cache_file`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::{Args, Parser, Subcommand};
use radcache_cache::cache_file::{CacheFile, ParamValue};
use radcache_render::{EnvMap, GpuScene, IcRenderer, IcSettings};
use radcache_scene::{Environment, LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};
use serde_json::json;

use crate::args::ic::IcArgs;
use crate::args::{image_size, shader_root, EnvArgs};
use crate::cache_io::{identity, write};
use crate::sequence::{FrameArgs, Sequence};

#[derive(Args, Debug)]
pub struct CacheArgs {
    #[command(subcommand)]
    command: CacheCommand,
}

#[derive(Subcommand, Debug)]
enum CacheCommand {
    /// Print a cache file's header (after checking its checksums).
    Info(InfoArgs),
    /// Prepass: compute the records over every N-th frame of a static scene's camera path.
    Build(Box<BuildArgs>),
}

#[derive(Args, Debug)]
struct InfoArgs {
    /// The cache file.
    file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct BuildArgs {
    /// The glTF scene (.gltf or .glb); only its camera may move.
    scene: PathBuf,
    /// The cache file to write.
    #[arg(short, long, value_name = "FILE.rcache")]
    output: PathBuf,
    /// The frames of the camera path, A..B inclusive (default: the animation's range).
    #[arg(long, value_name = "A..B")]
    frames: Option<String>,
    /// Compute records at every N-th frame from A (and at B).
    #[arg(long, default_value_t = 10, value_name = "N")]
    every: u32,
    /// Image size WxH of the renders that will use the file (default as `render`).
    #[arg(long, value_name = "WxH")]
    resolution: Option<String>,
    #[command(flatten)]
    ic: IcArgs,
    /// Frames per second of the renders that will use the file.
    #[arg(long, default_value_t = 24.0)]
    fps: f32,
    /// Scene time of the first frame (default: the animation's first key, else 0).
    #[arg(long)]
    start_time: Option<f32>,
    /// Use the camera with this name instead of the scene's first.
    #[arg(long)]
    camera: Option<String>,
    /// Seed of the random sequences.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    #[command(flatten)]
    env: EnvArgs,
    /// No per-frame lines.
    #[arg(long, short)]
    quiet: bool,
}

/// `radcache cache build`'s arguments alone, to check a command line before it is written into a
/// job script (`radcache farm --prepass-every`).
#[derive(Parser, Debug)]
#[command(name = "radcache cache build")]
struct BuildLine {
    #[command(flatten)]
    args: BuildArgs,
}

/// Checks that `radcache cache build` accepts `line` (its scene, `-o`, frames and options);
/// the error is clap's first line.
pub fn check_build_line(line: &[String]) -> Result<()> {
    match BuildLine::try_parse_from(
        std::iter::once("radcache-cache-build".to_string()).chain(line.iter().cloned()),
    ) {
        Ok(_) => Ok(()),
        Err(e) => {
            let text = e.render().to_string();
            let first = text
                .split("\n\n")
                .next()
                .unwrap_or(&text)
                .trim()
                .to_string();
            bail!("{}", first.trim_start_matches("error: "))
        }
    }
}

pub fn run(args: &CacheArgs) -> Result<ExitCode> {
    match &args.command {
        CacheCommand::Info(a) => info(a),
        CacheCommand::Build(a) => build(a),
    }
}

fn info(args: &InfoArgs) -> Result<ExitCode> {
    let file = CacheFile::read(&args.file)?;
    let h = &file.header;
    let text = if args.json {
        let s = &h.identity.settings;
        let params: serde_json::Map<String, serde_json::Value> = h
            .param_values()
            .into_iter()
            .map(|(name, v)| {
                let v = match v {
                    ParamValue::Int(v) => json!(v),
                    // The f32's shortest decimal (`0.3`, not `0.30000001192092896`).
                    ParamValue::Real(v) => json!(v.to_string().parse::<f64>().unwrap_or(0.0)),
                };
                (name.to_string(), v)
            })
            .collect();
        let value = json!({
            "file": args.file,
            "format_version": h.version,
            "scene_hash": format!("{:016x}", h.identity.scene_hash),
            "settings": {"width": s.width, "height": s.height, "time_step_s": s.time_step_s},
            "settings_hash": format!("{:08x}", h.settings_hash),
            "params": params,
            "records": h.record_count,
            "frames": h.frames,
            "lifespans": h.lifespans,
            "sky": h.sky,
            "radiance": h.radiance,
            "payload_bytes": h.payload_len,
            "payload_crc32": format!("{:08x}", h.payload_crc),
        });
        serde_json::to_string_pretty(&value)? + "\n"
    } else {
        format!("{}\n{}checksums: ok\n", args.file.display(), h.describe())
    };
    crate::output::emit(&text)?;
    Ok(ExitCode::SUCCESS)
}

/// The sampled frames: every `every`-th of `frames` from the first, and the last.
pub fn sampled(frames: &[(u32, f32)], every: u32) -> Vec<(u32, f32)> {
    let mut out: Vec<(u32, f32)> = frames
        .iter()
        .step_by(every.max(1) as usize)
        .copied()
        .collect();
    if let Some(&last) = frames.last() {
        if out.last() != Some(&last) {
            out.push(last);
        }
    }
    out
}

fn build(args: &BuildArgs) -> Result<ExitCode> {
    if args.every == 0 {
        bail!("--every must be at least 1");
    }
    let opts = LoadOptions {
        camera_name: args.camera.clone(),
        env: args.env.to_override()?,
    };
    let (scene, _warnings) = Scene::load(&args.scene, &opts)?;
    let plan = scene.plan();
    if !plan.keeps_records() {
        bail!(
            "{}: its geometry or lights move (plan: {:?} animation); a prepass needs a scene \
             where only the camera moves",
            args.scene.display(),
            plan.animation.kind
        );
    }
    let sequence = Sequence::new(
        &FrameArgs {
            frames: args.frames.as_deref(),
            start_time: args.start_time,
            fps: args.fps,
            pattern: true,
            ..FrameArgs::default()
        },
        plan.animation.time_range,
    )?;
    let frames = sampled(&sequence.frames, args.every);
    let size = image_size(args.resolution.as_deref(), &scene.camera_at(frames[0].1))?;
    let env_map = match &scene.environment {
        Environment::Map { path, .. } => Some(EnvMap::load(path)?),
        _ => None,
    };
    let ctx = Context::new()?;
    let shaders = ShaderCompiler::new(shader_root())?;
    let mut gpu = GpuScene::new(&ctx, &scene, env_map.as_ref())?;
    let base = IcSettings {
        settle_records: true,
        ..crate::frame::ic_settings(&args.ic, size, args.seed)?
    };
    let mut renderer = IcRenderer::new(&ctx, &shaders, &gpu, &base)?;
    let start = Instant::now();
    for &(frame, time) in &frames {
        let settings = IcSettings {
            frame,
            time,
            ..base.clone()
        };
        let t = Instant::now();
        let (_, stats) = renderer.render(&ctx, &scene, &mut gpu, &settings, &mut |_| {})?;
        if !args.quiet {
            crate::progress::line(&format!(
                "frame {frame}: {} records created, {} in all ({:.2} s)",
                stats.records_per_level.iter().sum::<u64>(),
                stats.records,
                t.elapsed().as_secs_f64()
            ));
        }
    }
    let mut records = renderer.export_cache(&ctx)?;
    // Every record was made for the path: each starts with the whole eviction window.
    let frames_done = records.frames;
    records.last_used.iter_mut().for_each(|u| *u = frames_done);
    write(&args.output, identity(&scene, &base), records, args.quiet)?;
    if !args.quiet {
        crate::progress::line(&format!(
            "prepass over {} of {} frames at {}x{}: {:.1} s",
            frames.len(),
            sequence.frames.len(),
            size.0,
            size.1,
            start.elapsed().as_secs_f64()
        ));
    }
    drop(renderer);
    drop(gpu);
    crate::frame::shut_down(ctx)?;
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::sampled;

    #[test]
    fn every_nth_frame_and_the_last_are_sampled() {
        let frames: Vec<(u32, f32)> = (1..=10).map(|f| (f, f as f32)).collect();
        let numbers = |every| -> Vec<u32> { sampled(&frames, every).iter().map(|f| f.0).collect() };
        assert_eq!(numbers(4), vec![1, 5, 9, 10]);
        assert_eq!(numbers(3), vec![1, 4, 7, 10]);
        assert_eq!(numbers(1), (1..=10).collect::<Vec<_>>());
        assert_eq!(numbers(20), vec![1, 10]);
        assert!(sampled(&[], 3).is_empty());
    }
}
