//! `radcache render SCENE -o OUT.exr`: load, upload, render, write; one frame or a sequence
//! (`-o out/frame_####.exr --frames 1..120`), resumable, with the cache kept across frames
//! where the plan allows.

use std::path::Path;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Result};
use radcache_render::{Budget, EnvMap, GpuScene};
use radcache_scene::{Environment, LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};
use serde_json::json;

use crate::args::{image_size, shader_root, Method, RenderArgs};
use crate::frame::{self, FrameSetup};
use crate::profile::Profile;
use crate::progress;
use crate::progress::WarmUp;
use crate::sequence::{Action, ContactSheet, FrameArgs, Sequence, SequenceProgress};

pub fn run(args: &RenderArgs) -> Result<ExitCode> {
    if args.ic.set_help() {
        crate::output::emit(&crate::args::ic::set_help_text())?;
        return Ok(ExitCode::SUCCESS);
    }
    let budget = match (args.spp, args.time_budget) {
        (_, Some(s)) if !(s.is_finite() && s > 0.0) => bail!("--time-budget must be positive"),
        (_, Some(s)) => Budget::Seconds(s),
        (Some(0), _) => bail!("--spp must be at least 1"),
        (Some(n), None) => Budget::Samples(n),
        (None, None) => Budget::Samples(64),
    };
    crate::cache_io::check_render_args(args)?;
    let pattern = args.output.to_string_lossy().contains('#');
    let mut profile = Profile::new();

    let t_load = Instant::now();
    let opts = LoadOptions {
        camera_name: args.camera.clone(),
        env: args.env.to_override()?,
    };
    // The loader logs its warnings as it finds them (`log::warn!`): they are not printed again.
    let (scene, _warnings) = Scene::load(&args.scene, &opts)?;
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
            start_frame: args.start_frame,
        },
        plan.animation.time_range,
    )?;

    let view = scene.camera_at(sequence.frames[0].1);
    let size = image_size(args.resolution.as_deref(), &view)?;

    let ctx = Context::new()?;
    // Compiled shaders are kept beside the pipeline cache (docs/design.md, "Pipeline cache").
    let spirv_dir = radcache_vk::pipeline_cache_dir_from_env();
    let shaders = ShaderCompiler::new(shader_root())?.with_disk_cache(spirv_dir.as_deref());
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
    let output_of = |number| -> Result<std::path::PathBuf> {
        Ok(if pattern {
            radcache_image::frame_path(&args.output, number)?
        } else {
            args.output.clone()
        })
    };
    let mut on_disk = std::collections::BTreeSet::new();
    if pattern && !args.overwrite {
        for &(number, _) in &sequence.frames {
            if output_of(number)?.exists() {
                on_disk.insert(number);
            }
        }
    }
    let warm_up = if temporal && args.method == Method::Ic {
        args.warm_up
    } else {
        0
    };
    let steps = sequence.steps(warm_up, |f| on_disk.contains(&f));
    let multi_frame = sequence.frames.len() > 1 || steps.iter().any(|s| s.action == Action::WarmUp);
    let time_step_s = if temporal && multi_frame && plan.needs_lifespans() {
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
        sequence: multi_frame,
        time_step_s,
        config: frame::config_args(args, size)?.join(" "),
    };
    let stop = interrupt_flag(sequence.frames.len() > 1);
    let mut progress = SequenceProgress::new(sequence.frames.len(), args.quiet);
    let mut ic: Option<radcache_render::IcRenderer> = None;
    let mut entries = Vec::new();
    let mut write_s = 0.0;
    let mut stopped = false;
    let mut sheet = ContactSheet::new(args.contact_sheet.clone());
    let mut warm = WarmUp::default();
    for step in &steps {
        let (number, time) = (step.frame, step.time);
        if stop.load(Ordering::SeqCst) {
            stopped = true;
            break;
        }
        let output = output_of(number)?;
        if step.action == Action::Skip {
            progress.skipped(number, &output);
            sheet.add_file(&output)?;
            continue;
        }
        if step.after_gap {
            if let Some(renderer) = ic.as_mut() {
                renderer.forget();
            }
        }
        let t_frame = Instant::now();
        let warm_up = step.action == Action::WarmUp;
        let rendered = frame::render(&setup, &mut gpu, &mut ic, number, time, warm_up)?;
        if step.action == Action::WarmUp {
            warm.add(number, t_frame.elapsed().as_secs_f64());
            continue;
        }
        warm.report(args.quiet);
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
        let written = Instant::now();
        profile.cpu("write", t_write, written, Some(number));
        let frame_write_s = written.duration_since(t_write).as_secs_f64();
        write_s += frame_write_s;
        sheet.add(&image);
        let mut entry = frame::stats_entry(&rendered, number, time);
        entry["write_s"] = json!(frame_write_s);
        entry["device_memory_bytes"] = json!(ctx.memory_by_category());
        entries.push(entry);
        if let Some(path) = &args.stats {
            let memory = memory_entry(&gpu.stats().memory_need);
            write_stats(path, &setup, &entries, [load_s, upload_s, write_s], memory)?;
        }
        if !args.quiet && sequence.frames.len() == 1 {
            let out = &rendered.out;
            let rays: u64 = out.rays.values().sum();
            progress::line(&format!(
                "wrote {} ({}x{}, {}, {} spp, {:.2} s, {:.2} Mrays/s)",
                output.display(),
                size.0,
                size.1,
                args.method.name(),
                out.spp,
                out.time_s,
                rays as f64 / out.time_s.max(1e-9) / 1e6
            ));
        }
        progress.rendered(number, t_frame.elapsed().as_secs_f64());
    }
    progress.finish(stopped);
    if let Some(path) = &args.cache_out {
        let settings = radcache_render::IcSettings {
            time_step_s,
            ..frame::ic_settings(&args.ic, size, args.seed)?
        };
        crate::cache_io::export(path, ic.as_ref(), &ctx, &scene, &settings, args.quiet)?;
    }
    sheet.write(&frame::png_options(args))?;
    if let Some(path) = &args.profile {
        profile.write(path)?;
    }
    if !args.quiet {
        eprint!("{}", profile.table());
    }
    drop(ic);
    drop(gpu);
    // The images are written; the run still fails on a validation error, since it is a bug.
    frame::shut_down(ctx)?;
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
                progress::line("abandoning the frame in flight");
                std::process::exit(130);
            }
            progress::line("finishing the frame in flight (Ctrl-C again to abandon it)");
        });
        if let Err(e) = installed {
            log::warn!("Ctrl-C will stop at once: {e}");
        }
    }
    flag
}

/// The stats file's `memory`: the device memory the scene's upload was planned for at its peak,
/// by part, and the process's peak resident host memory so far (`VmHWM`, Linux; null elsewhere).
/// Each frame's live device allocations are in its own entry (`device_memory_bytes`).
fn memory_entry(need: &radcache_render::scene::budget::MemoryNeed) -> serde_json::Value {
    let peak_host = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
                .map(|kb| kb * 1024)
        });
    json!({
        "upload_peak_device_bytes": need.total(),
        "upload_peak_by_part": {
            "geometry": need.geometry,
            "textures": need.textures,
            "environment": need.environment,
            "instances": need.instances,
            "acceleration_structures": need.acceleration,
        },
        "peak_host_bytes": peak_host,
    })
}

/// Writes the stats file (atomically, after every frame, so an interrupted run keeps it).
fn write_stats(
    path: &Path,
    setup: &FrameSetup<'_>,
    frames: &[serde_json::Value],
    cpu_s: [f64; 3],
    memory: serde_json::Value,
) -> Result<()> {
    let [load_s, upload_s, write_s] = cpu_s;
    let value = json!({
        "scene": setup.args.scene,
        "method": setup.args.method.name(),
        "device": setup.ctx.info().name,
        "resolution": [setup.size.0, setup.size.1],
        "temporal": setup.temporal,
        "time_step_s": setup.time_step_s,
        "config": setup.config,
        // Host seconds outside the frames; "write" sums the frames' `write_s`.
        "cpu_s": {"scene_load": load_s, "upload": upload_s, "write": write_s},
        "pipelines": frame::pipelines_entry(setup),
        "memory": memory,
        "frames": frames,
    });
    crate::output::write_text(path, &serde_json::to_string_pretty(&value)?, "stats")
}
