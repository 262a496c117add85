//! One frame rendered with the irradiance cache (`--method ic`): the frame structure of the cache
//! issue, each pass in its own profiler scope.
//!
//! For each of `sub_frames` jittered sub-frames (anti-aliasing: the jittered G-buffers are
//! composited and averaged, which box-filters edges like the reference):
//! 1. **G-buffer** (raster) and **direct lighting** (compute, NEE + MIS).
//! 2. **Hole filling**, coarse to fine over the levels: splat the records with the stricter
//!    creation weights, pick one hole per S×S block (GPU, atomic append), compute those records
//!    (indirect dispatch), clamp radii against their neighbours. The CPU only loops over levels
//!    and reads the counters for the statistics; it stops early when a level finds no hole.
//! 3. **Splat** every record with the final weights and **composite**
//!    `L = direct + albedo/π · Σw·Ẽ / Σw` into the frame accumulator.
//!
//! Finally the **emission** pass adds the box-filtered emission (8×8 stratified rays at pixels
//! near emitters, the sub-frames' samples elsewhere).
//!
//! Records persist across sub-frames (they are world-space), so later sub-frames mostly reuse
//! the first one's records and only fill the holes their jitter uncovers.

use std::collections::BTreeMap;
use std::time::Instant;

use radcache_cache::IcParams;
use radcache_scene::Scene;
use radcache_shared::gpu::GpuRecord;
use radcache_vk::{Context, PassTiming, ShaderCompiler};

use crate::composite::CompositePass;
use crate::direct::DirectPass;
use crate::emission::EmissionPass;
use crate::error::{Error, Result};
use crate::gbuffer::GBuffer;
use crate::gbuffer_pass::GBufferPass;
use crate::gpu_scene::GpuScene;
use crate::holes::HolePass;
use crate::ic_state::IcState;
use crate::neighbours::NeighbourPass;
use crate::records::RecordPass;
use crate::render::{FrameOutput, Progress};
use crate::splat::{SplatPass, SplatWeights};

/// Settings of one frame rendered with the cache.
#[derive(Debug, Clone, PartialEq)]
pub struct IcSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Cache parameters (`IcParams::preset`).
    pub params: IcParams,
    /// Jittered sub-frames averaged into the image (anti-aliasing).
    pub sub_frames: u32,
    /// Direct-lighting samples per pixel and sub-frame.
    pub direct_samples: u32,
    /// Seed of the random sequences.
    pub seed: u32,
    /// Frame number.
    pub frame: u32,
    /// Scene time in seconds.
    pub time: f32,
    /// Largest number of records (memory: 176 bytes each).
    pub record_capacity: u32,
    /// Also produce the debug AOVs ([`IcDebug`]).
    pub debug_aovs: bool,
}

impl Default for IcSettings {
    fn default() -> Self {
        IcSettings {
            width: 512,
            height: 512,
            params: IcParams::default(),
            sub_frames: 4,
            direct_samples: 16,
            seed: 0,
            frame: 1,
            time: 0.0,
            record_capacity: 1 << 18,
            debug_aovs: false,
        }
    }
}

/// Cache figures of one frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IcStats {
    /// Records created at each level (summed over sub-frames), coarsest first.
    pub records_per_level: Vec<u64>,
    /// Records at the end of the frame.
    pub records: u64,
    /// Surface pixels left uncovered by the final splat (summed over sub-frames).
    pub holes_left: u64,
    /// Requests dropped because the record buffer was full.
    pub dropped_requests: u64,
    /// Records whose irradiance was invalid (stored as black).
    pub rejected_records: u64,
    /// Wall time of the hole-filling submissions (splat, holes, records, neighbours), s.
    pub hole_filling_s: f64,
    /// The debug AOVs, when asked for.
    pub debug: Option<IcDebug>,
}

/// Debug AOVs of a cache frame (rows top to bottom, averaged over the sub-frames).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IcDebug {
    /// Indirect radiance albedo/π·E only (RGB interleaved).
    pub indirect: Vec<f32>,
    /// Σw of the final splat.
    pub weight_sum: Vec<f32>,
    /// Records whose zone reaches the pixel.
    pub records_per_pixel: Vec<f32>,
    /// 1 at the pixels where records were created, 0 elsewhere (record positions).
    pub record_positions: Vec<f32>,
}

/// The sub-pixel jitter of sub-frame `k` in pixels: the centre first, then the R2 sequence
/// (Roberts 2018), which covers the pixel evenly for any count.
pub fn sub_frame_jitter(k: u32) -> [f32; 2] {
    if k == 0 {
        return [0.0, 0.0];
    }
    const G: f64 = 1.324_717_957_244_746;
    let (a1, a2) = (1.0 / G, 1.0 / (G * G));
    let n = f64::from(k);
    [
        ((0.5 + a1 * n).fract() - 0.5) as f32,
        ((0.5 + a2 * n).fract() - 0.5) as f32,
    ]
}

fn add_timings(map: &mut BTreeMap<String, f64>, timings: Vec<PassTiming>) {
    for t in timings {
        *map.entry(t.name).or_default() += t.duration_ms;
    }
}

/// Renders `scene` at `settings.time` with the irradiance cache.
pub fn render_ic(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    settings: &IcSettings,
    progress: &mut dyn FnMut(Progress),
) -> Result<(FrameOutput, IcStats)> {
    let (w, h) = (settings.width, settings.height);
    if w == 0 || h == 0 {
        return Err(Error::Invalid(format!("the image size {w}x{h} is empty")));
    }
    if !settings.params.is_valid() {
        return Err(Error::Invalid(format!(
            "invalid cache parameters: {:?}",
            settings.params
        )));
    }
    let start = Instant::now();
    let params = settings.params;
    let creation = params.for_creation();
    gpu.set_time(scene, settings.time)?;
    let view = scene.camera_at(settings.time);
    gpu.set_view(&view, w, h, settings.frame, settings.seed)?;

    let gbuffer = GBuffer::new(ctx, w, h)?;
    let gbuffer_pass = GBufferPass::new(ctx, shaders)?;
    let direct = DirectPass::new(ctx, shaders, gpu)?;
    let splat = SplatPass::new(ctx, shaders, w, h)?;
    let holes = HolePass::new(ctx, shaders)?;
    let neighbours = NeighbourPass::new(ctx, shaders)?;
    let records = RecordPass::new(ctx, shaders, gpu, &params)?;
    let composite = CompositePass::new(ctx, shaders, gpu, w, h)?;
    let emission = EmissionPass::new(ctx, shaders, gpu)?;
    let request_capacity = w.div_ceil(1) * h.div_ceil(1);
    let state = IcState::new(ctx, shaders, settings.record_capacity, request_capacity)?;

    let mut passes_ms = BTreeMap::new();
    let mut rays: BTreeMap<String, u64> = BTreeMap::new();
    let mut stats = IcStats {
        records_per_level: vec![0; params.levels as usize],
        ..IcStats::default()
    };
    let final_weights = SplatWeights::from_params(&params);
    let creation_weights = SplatWeights::from_params(&creation);
    let sub_frames = settings.sub_frames.max(1);

    let mut rec = ctx.begin("ic.setup")?;
    gpu.record_update(ctx, &mut rec)?;
    state.record_reset(&mut rec)?;
    composite.record_clear(&mut rec);
    add_timings(&mut passes_ms, ctx.submit(rec)?.wait()?);

    for k in 0..sub_frames {
        let jitter = sub_frame_jitter(k);
        let seed = settings.seed.wrapping_mul(0x9e37_79b9) ^ k;
        let mut rec = ctx.begin("ic.gbuffer")?;
        gbuffer_pass.record(&mut rec, gpu, &gbuffer, jitter)?;
        direct.record(&mut rec, gpu, &gbuffer, settings.direct_samples, seed)?;
        add_timings(&mut passes_ms, ctx.submit(rec)?.wait()?);
        *rays.entry("direct".into()).or_default() += direct.rays()?;

        for level in 0..params.levels {
            let level_start = Instant::now();
            let mut rec = ctx.begin("ic.level")?;
            state.record_begin_level(&mut rec)?;
            splat.record(
                &mut rec,
                "splat.coverage",
                gpu,
                &gbuffer,
                &state,
                &creation_weights,
            )?;
            holes.record(
                &mut rec,
                &gbuffer,
                &splat,
                &state,
                params.level_spacing_px(level),
                creation.coverage_threshold(),
                seed ^ (level << 16),
                false,
            )?;
            state.record_begin_batch(&mut rec)?;
            records.record(
                &mut rec,
                gpu,
                &gbuffer,
                &state.requests,
                &state.counters,
                &state.records,
                level,
                k,
                seed,
            )?;
            state.record_end_batch(&mut rec)?;
            neighbours.record(&mut rec, &state)?;
            add_timings(&mut passes_ms, ctx.submit(rec)?.wait()?);
            // Wall time of hole filling (lavapipe's timestamps miss asynchronous compute work).
            stats.hole_filling_s += level_start.elapsed().as_secs_f64();
            *rays.entry("records".into()).or_default() += records.rays()?;
            let c = state.read_counters()?;
            let created = c.dispatch[0];
            stats.records_per_level[level as usize] += u64::from(created);
            if c.counts[3] == 0 {
                break; // no hole at this spacing: finer levels would find none either
            }
        }

        let mut rec = ctx.begin("ic.composite")?;
        splat.record(&mut rec, "splat", gpu, &gbuffer, &state, &final_weights)?;
        state.record_begin_level(&mut rec)?;
        holes.record(
            &mut rec,
            &gbuffer,
            &splat,
            &state,
            1,
            f32::MIN_POSITIVE,
            0,
            true,
        )?;
        composite.record(&mut rec, gpu, &gbuffer, &splat, jitter, settings.debug_aovs)?;
        add_timings(&mut passes_ms, ctx.submit(rec)?.wait()?);
        let c = state.read_counters()?;
        stats.holes_left += u64::from(c.counts[3]);
        stats.records = u64::from(c.counts[0]);
        stats.dropped_requests = u64::from(c.limits[2]);
        stats.rejected_records = u64::from(c.limits[3]);
        progress(Progress {
            done: k + 1,
            total: sub_frames,
            elapsed_s: start.elapsed().as_secs_f64(),
        });
    }
    let mut rec = ctx.begin("ic.emission")?;
    emission.record(&mut rec, gpu, &composite)?;
    add_timings(&mut passes_ms, ctx.submit(rec)?.wait()?);
    *rays.entry("emission".into()).or_default() += emission.rays()?;
    let (pixels, nonfinite_pixels) = composite.read_mean(ctx)?;
    if settings.debug_aovs {
        let (indirect, weight_sum, records_per_pixel) = composite.read_debug(ctx, sub_frames)?;
        let mut record_positions = vec![0.0f32; (w * h) as usize];
        let all: Vec<GpuRecord> = ctx.read_buffer(&state.records, stats.records as usize)?;
        for r in &all {
            if let Some(p) = record_positions.get_mut(r.info[0] as usize) {
                *p = 1.0;
            }
        }
        stats.debug = Some(IcDebug {
            indirect,
            weight_sum,
            records_per_pixel,
            record_positions,
        });
    }
    Ok((
        FrameOutput {
            width: w,
            height: h,
            pixels,
            spp: sub_frames,
            time_s: start.elapsed().as_secs_f64(),
            rays,
            passes_ms,
            nonfinite_pixels,
            aovs: None,
        },
        stats,
    ))
}

#[cfg(test)]
mod tests {
    use super::sub_frame_jitter;

    #[test]
    fn jitter_starts_at_the_centre_and_stays_in_the_pixel() {
        assert_eq!(sub_frame_jitter(0), [0.0, 0.0]);
        for k in 1..64 {
            let j = sub_frame_jitter(k);
            assert!(j.iter().all(|v| (-0.5..0.5).contains(v)), "{j:?}");
        }
        // Four sub-frames fall in four different quadrants of the pixel.
        let quads: std::collections::BTreeSet<(bool, bool)> = (0..4)
            .map(|k| {
                let j = sub_frame_jitter(k);
                (j[0] >= 0.0, j[1] >= 0.0)
            })
            .collect();
        assert!(quads.len() >= 3, "{quads:?}");
    }
}
