//! One rendered image: drives the passes for a frame and gathers its statistics.

use std::collections::BTreeMap;
use std::time::Instant;

use radcache_scene::Scene;
use radcache_vk::{Context, ShaderCompiler};

use crate::error::{Error, Result};
use crate::frame::clock::{FrameClock, Span};
use crate::passes::aov::{AovPass, Aovs};
use crate::passes::path_trace::{PathTraceJob, PathTracer};
use crate::scene::GpuScene;

/// When to stop sampling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    /// A fixed number of samples per pixel.
    Samples(u32),
    /// Sample until this many seconds have passed (at least one sample per pixel).
    Seconds(f64),
}

/// Settings of one path-traced frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel or time budget.
    pub budget: Budget,
    /// Seed of the random sequences (the same seed reproduces the image).
    pub seed: u32,
    /// Frame number (written to the frame constants; mixes into nothing else).
    pub frame: u32,
    /// Scene time in seconds.
    pub time: f32,
    /// Target duration of one submission, ms.
    pub chunk_target_ms: f64,
    /// Also compute the albedo, normal and depth AOVs.
    pub aovs: bool,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            width: 512,
            height: 512,
            budget: Budget::Samples(64),
            seed: 0,
            frame: 1,
            time: 0.0,
            chunk_target_ms: 250.0,
            aovs: false,
        }
    }
}

/// Progress of a frame, reported after every submission.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    /// Samples per pixel done.
    pub done: u32,
    /// Samples per pixel planned (an estimate under a time budget).
    pub total: u32,
    /// Seconds since the frame started.
    pub elapsed_s: f64,
}

/// A finished frame and its figures.
#[derive(Debug, Clone)]
pub struct FrameOutput {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB radiance per pixel, rows top to bottom.
    pub pixels: Vec<[f32; 3]>,
    /// Samples per pixel.
    pub spp: u32,
    /// Wall time of the frame, s.
    pub time_s: f64,
    /// Ray queries per pass.
    pub rays: BTreeMap<String, u64>,
    /// GPU time per pass name, ms (summed over submissions).
    pub passes_ms: BTreeMap<String, f64>,
    /// The frame's timeline: GPU passes and host phases.
    pub spans: Vec<Span>,
    /// Pixels whose value was non-finite and replaced by black (0 unless something is wrong).
    pub nonfinite_pixels: u64,
    /// The AOVs, when asked for.
    pub aovs: Option<Aovs>,
}

/// Renders `scene` at `settings.time` with the reference path tracer: setup, samples until the
/// budget is spent, finish (see [`crate::frame`]).
pub fn render_path(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    settings: &PathSettings,
    progress: &mut dyn FnMut(Progress),
) -> Result<FrameOutput> {
    let (w, h) = (settings.width, settings.height);
    if w == 0 || h == 0 {
        return Err(Error::Invalid(format!("the image size {w}x{h} is empty")));
    }
    let start = Instant::now();
    let (mut run, aovs) = path_setup(ctx, shaders, scene, gpu, settings)?;
    path_sample(ctx, gpu, settings, &mut run, start, progress)?;
    path_finish(ctx, run, start, aovs)
}

/// What the path tracer's phases share.
struct PathRun {
    tracer: PathTracer,
    clock: FrameClock,
    rays: u64,
}

/// **Setup**: the scene at the frame's time and view, the pipelines, the cleared accumulators
/// and the AOVs (when asked for).
fn path_setup(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    settings: &PathSettings,
) -> Result<(PathRun, Option<Aovs>)> {
    let (w, h) = (settings.width, settings.height);
    gpu.set_time(scene, settings.time)?;
    let view = scene.camera_at(settings.time);
    gpu.set_view(&view, w, h, settings.frame, settings.seed)?;
    let mut clock = FrameClock::new();
    let mut tracer = PathTracer::new(ctx, shaders, gpu, w, h)?;
    clock.lap("pipelines");
    let aov_pass = if settings.aovs {
        Some(AovPass::new(ctx, shaders, gpu, w, h)?)
    } else {
        None
    };
    let mut rec = ctx.begin("frame.setup")?;
    gpu.record_update(ctx, &mut rec)?;
    tracer.record(&mut rec, PathTraceJob::Clear)?;
    if let Some(pass) = &aov_pass {
        pass.record(&mut rec, gpu)?;
    }
    clock.submit(ctx, rec)?;
    let aovs = match &aov_pass {
        Some(pass) => Some(pass.read(ctx)?),
        None => None,
    };
    drop(aov_pass);
    clock.lap("setup");
    let run = PathRun {
        tracer,
        clock,
        rays: 0,
    };
    Ok((run, aovs))
}

/// **Samples**: submissions of `chunk` samples per pixel, each sized from the last one's time
/// to take about `chunk_target_ms`, until the budget (samples, or seconds since `start`) is
/// spent.
fn path_sample(
    ctx: &Context,
    gpu: &GpuScene,
    settings: &PathSettings,
    run: &mut PathRun,
    start: Instant,
    progress: &mut dyn FnMut(Progress),
) -> Result<()> {
    let target = match settings.budget {
        Budget::Samples(n) => n.max(1),
        Budget::Seconds(_) => u32::MAX,
    };
    let tracer = &mut run.tracer;
    let mut chunk = 1u32;
    while tracer.samples() < target {
        let count = chunk.min(target - tracer.samples());
        let mut rec = ctx.begin("frame.path_trace")?;
        tracer.record(&mut rec, PathTraceJob::Samples { scene: gpu, count })?;
        let submitted = Instant::now();
        let timings = ctx.submit(rec)?.wait()?;
        let gpu_ms: f64 = timings.iter().map(|t| t.duration_ms).sum();
        run.clock.gpu(submitted, timings);
        run.rays += tracer.last_chunk_rays()?;
        let elapsed_s = start.elapsed().as_secs_f64();
        let total = match settings.budget {
            Budget::Samples(_) => target,
            Budget::Seconds(s) => {
                let rate = f64::from(tracer.samples()) / elapsed_s.max(1e-9);
                (rate * s).max(f64::from(tracer.samples())) as u32
            }
        };
        progress(Progress {
            done: tracer.samples(),
            total,
            elapsed_s,
        });
        if let Budget::Seconds(s) = settings.budget {
            if elapsed_s >= s {
                break;
            }
        }
        chunk = PathTracer::chunk_size(count, gpu_ms, settings.chunk_target_ms);
        if let Budget::Seconds(s) = settings.budget {
            // Do not overshoot the budget by more than about one chunk's share.
            let left = (s - elapsed_s).max(0.0) * 1000.0;
            chunk = chunk.min(PathTracer::chunk_size(count, gpu_ms, left).max(1));
        }
    }
    run.clock.lap("path_trace");
    Ok(())
}

/// **Finish**: the read-back of the mean over the samples, and the figures.
fn path_finish(
    ctx: &Context,
    mut run: PathRun,
    start: Instant,
    aovs: Option<Aovs>,
) -> Result<FrameOutput> {
    let (pixels, nonfinite_pixels) = run.tracer.read_mean(ctx)?;
    run.clock.lap("readback");
    let (w, h) = run.tracer.size();
    Ok(FrameOutput {
        width: w,
        height: h,
        pixels,
        spp: run.tracer.samples(),
        time_s: start.elapsed().as_secs_f64(),
        rays: BTreeMap::from([("path_trace".to_string(), run.rays)]),
        passes_ms: run.clock.passes_ms,
        spans: run.clock.spans,
        nonfinite_pixels,
        aovs,
    })
}
