//! The irradiance cache's frame loop: [`IcRenderer`] owns the passes, the G-buffer and the cache
//! state, so a sequence creates its pipelines once and can keep its records from frame to frame.
//!
//! A frame has two phases over the `sub_frames` jittered sub-frames:
//! 1. **Cache**: for each sub-frame's jitter, rasterize the **G-buffer**, then fill holes coarse to
//!    fine: splat the records with the stricter creation weights, pick one hole per S×S block (GPU,
//!    atomic append), compute those **records** (indirect dispatch), clamp radii against their
//!    **neighbours** (hash grid). The CPU only loops over levels and reads counters for the
//!    statistics; it stops early when a level finds no hole.
//! 2. **Shade**: for each sub-frame, the G-buffer again, **direct** lighting (NEE + MIS), the
//!    **splat** of every record with the final weights and the **composite**
//!    `L = direct + albedo/π · Σw·Ẽ / Σw` into the frame accumulator.
//!
//! Every sub-frame is therefore shaded with the same, final set of records, and a frame whose
//! holes are all covered by kept records creates none and shades exactly as the frame before it.
//! Finally the **emission** pass adds the box-filtered emission.
//!
//! With `IcSettings::time_step_s` (animated geometry or lights), records also carry temporal
//! state (`crate::temporal`, steps in `ic_renderer/lifecycle.rs`): the setup moves them with
//! their instances and lists the expired ones, and after the cache phase the frame's new and
//! expired records are evaluated (again, at their own points) at the next frame's time.

use std::collections::BTreeMap;
use std::time::Instant;

use radcache_cache::IcParams;
use radcache_scene::Scene;
use radcache_shared::gpu::GpuRecord;
use radcache_vk::{Context, ShaderCompiler};

use crate::clock::FrameClock;
use crate::composite::CompositePass;
use crate::direct::DirectPass;
use crate::emission::EmissionPass;
use crate::error::{Error, Result};
use crate::gbuffer::GBuffer;
use crate::gbuffer_pass::GBufferPass;
use crate::gpu_scene::GpuScene;
use crate::holes::HolePass;
use crate::ic::{sub_frame_jitter, IcDebug, IcSettings, IcStats};
use crate::ic_state::IcState;
use crate::neighbours::NeighbourPass;
use crate::records::{creation_seed, RecordPass};
use crate::render::{FrameOutput, Progress};
use crate::splat::{SplatPass, SplatScope, SplatWeights};
use crate::temporal::TemporalPass;

mod lifecycle;

/// Most passes of the cache phase over the sub-frames (see [`IcRenderer::render`]).
const MAX_CACHE_PASSES: u32 = 4;

/// The cache's passes and state for one image size and one set of cache parameters.
pub struct IcRenderer {
    width: u32,
    height: u32,
    params: IcParams,
    gbuffer: GBuffer,
    gbuffer_pass: GBufferPass,
    direct: DirectPass,
    splat: SplatPass,
    holes: HolePass,
    neighbours: NeighbourPass,
    records: RecordPass,
    composite: CompositePass,
    emission: EmissionPass,
    state: IcState,
    /// Records kept across frames (created for sequences: `settle_records` or a time step).
    temporal: Option<TemporalPass>,
    /// The previous frame's `clip_from_world` (kept records are re-clamped when it changes).
    last_view: Option<[[f32; 4]; 4]>,
    /// False until a frame has left records to keep.
    has_records: bool,
    /// Frames rendered (the last-use marks of `IcState::last_used`).
    frames: u32,
}

impl std::fmt::Debug for IcRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IcRenderer")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl IcRenderer {
    /// Creates the passes for `settings` (size, parameters, record capacity) and `gpu`'s plan.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        gpu: &GpuScene,
        settings: &IcSettings,
    ) -> Result<IcRenderer> {
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
        let params = settings.params;
        Ok(IcRenderer {
            width: w,
            height: h,
            params,
            gbuffer: GBuffer::new(ctx, w, h)?,
            gbuffer_pass: GBufferPass::new(ctx, shaders)?,
            direct: DirectPass::new(ctx, shaders, gpu)?,
            splat: SplatPass::new(ctx, shaders, w, h)?,
            holes: HolePass::new(ctx, shaders)?,
            neighbours: NeighbourPass::new(ctx, shaders)?,
            records: RecordPass::new(ctx, shaders, gpu, &params)?,
            composite: CompositePass::new(ctx, shaders, gpu, w, h)?,
            emission: EmissionPass::new(ctx, shaders, gpu)?,
            state: IcState::new(ctx, shaders, settings.record_capacity, w * h)?,
            temporal: if settings.time_step_s > 0.0 || settings.settle_records {
                let lifespans = settings.time_step_s > 0.0;
                let capacity = settings.record_capacity;
                Some(TemporalPass::new(ctx, shaders, gpu, capacity, lifespans)?)
            } else {
                None
            },
            last_view: None,
            has_records: false,
            frames: 0,
        })
    }

    /// Drops every record: the next frame builds its cache from scratch.
    pub fn forget(&mut self) {
        self.has_records = false;
    }

    /// The cache's GPU state (records, counters).
    pub fn state(&self) -> &IcState {
        &self.state
    }

    /// Renders `scene` at `settings.time`, keeping the records of the previous frame unless
    /// [`IcRenderer::forget`] was called (records are world-space: right for a static scene
    /// under any camera motion). `settings` must have the size and parameters the renderer was
    /// created with.
    pub fn render(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        gpu: &mut GpuScene,
        settings: &IcSettings,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<(FrameOutput, IcStats)> {
        if (settings.width, settings.height, settings.params)
            != (self.width, self.height, self.params)
            || (settings.time_step_s > 0.0
                && !self.temporal.as_ref().is_some_and(|t| t.lifespans()))
        {
            return Err(Error::Invalid(format!(
                "the renderer was made for {}x{} and {:?}{}, not {}x{} and {:?} with a time step \
                 of {} s",
                self.width,
                self.height,
                self.params,
                if self.temporal.is_some() {
                    " with temporal caching"
                } else {
                    ""
                },
                settings.width,
                settings.height,
                settings.params,
                settings.time_step_s
            )));
        }
        let mut clock = FrameClock::new();
        let start = Instant::now();
        let (w, h) = (self.width, self.height);
        gpu.set_time(scene, settings.time)?;
        let view = scene.camera_at(settings.time);
        gpu.set_view(&view, w, h, settings.frame, settings.seed)?;

        let mut rays: BTreeMap<String, u64> = BTreeMap::new();
        let mut stats = IcStats {
            records_per_level: vec![0; self.params.levels as usize],
            ..IcStats::default()
        };
        let sub_frames = settings.sub_frames.max(1);
        let total = 2 * sub_frames;
        let mut report = |done: u32| {
            progress(Progress {
                done,
                total,
                elapsed_s: start.elapsed().as_secs_f64(),
            })
        };

        self.frames += 1;
        let now = self.frames;
        if self.has_records {
            let limit = settings.evict_after_frames;
            let evicted = self
                .state
                .compact(ctx, |_, used| used != 0 && now - used <= limit)?;
            stats.records_evicted = u64::from(evicted);
        }
        let kept = if self.has_records {
            self.state.read_counters()?.counts[0]
        } else {
            0
        };
        let temporal = settings.time_step_s > 0.0;
        let mut rec = ctx.begin("ic.setup")?;
        gpu.record_update(ctx, &mut rec)?;
        if !self.has_records {
            self.state.record_reset(&mut rec)?;
        }
        // Kept records take the radius clamp of the new view when the camera moved.
        let clip = gpu.constants().clip_from_world;
        let view_changed = self.last_view.is_some_and(|v| v != clip);
        self.last_view = Some(clip);
        if let Some(t) = self.temporal.as_mut() {
            if !self.has_records {
                t.forget();
            }
            if temporal || view_changed {
                let reclamp = view_changed.then_some(&self.params);
                let lifespans = temporal.then_some((scene, settings.time, &self.params));
                t.record_advance(&mut rec, gpu, &self.state, now, kept, lifespans, reclamp)?;
            }
        }
        self.neighbours
            .record_rebuild(&mut rec, &self.state, gpu.scene_scale())?;
        self.composite.record_clear(&mut rec);
        clock.submit(ctx, rec)?;
        stats.records_kept = u64::from(self.state.read_counters()?.counts[0]);
        clock.lap("setup");
        let expired = if temporal {
            self.expired(&mut stats)?
        } else {
            0
        };

        // Records created for a later sub-frame shrink earlier ones (neighbour clamping), which
        // can uncover a pixel an earlier sub-frame had covered: with `settle_records`, passes
        // repeat until one creates nothing (at most MAX_CACHE_PASSES), so the records left are a
        // fixed point and the next frame of a static scene creates none and shades identically.
        let passes = if settings.settle_records {
            MAX_CACHE_PASSES
        } else {
            1
        };
        for pass in 0..passes {
            let before = stats.records_per_level.iter().sum::<u64>();
            for k in 0..sub_frames {
                self.fill_holes(ctx, gpu, settings, k, &mut stats, &mut clock)?;
                if pass == 0 {
                    report(k + 1);
                }
            }
            stats.cache_passes = pass + 1;
            if stats.records_per_level.iter().sum::<u64>() == before {
                break;
            }
        }
        if temporal {
            self.look_ahead(
                ctx, scene, gpu, settings, &view, expired, &mut stats, &mut clock,
            )?;
        }
        *rays.entry("records".into()).or_default() += stats.record_rays;
        self.has_records = true;

        let final_weights = SplatWeights {
            mark_frame: now,
            ..SplatWeights::from_params(&self.params)
        };
        for k in 0..sub_frames {
            let jitter = sub_frame_jitter(k);
            let mut rec = ctx.begin("ic.shade")?;
            self.gbuffer_pass
                .record(&mut rec, gpu, &self.gbuffer, jitter)?;
            let first_sample = k * settings.direct_samples.max(1);
            self.direct.record(
                &mut rec,
                gpu,
                &self.gbuffer,
                settings.direct_samples,
                first_sample,
                settings.seed,
            )?;
            self.splat.record(
                &mut rec,
                "splat",
                SplatScope::All,
                gpu,
                &self.gbuffer,
                &self.state,
                &final_weights,
            )?;
            self.state.record_begin_level(&mut rec)?;
            self.holes.record(
                &mut rec,
                &self.gbuffer,
                &self.splat,
                &self.state,
                1,
                f32::MIN_POSITIVE,
                0,
                true,
            )?;
            self.composite.record(
                &mut rec,
                gpu,
                &self.gbuffer,
                &self.splat,
                jitter,
                settings.debug_aovs,
            )?;
            clock.submit(ctx, rec)?;
            *rays.entry("direct".into()).or_default() += self.direct.rays()?;
            let c = self.state.read_counters()?;
            stats.holes_left += u64::from(c.counts[3]);
            stats.records = u64::from(c.counts[0]);
            stats.dropped_requests = u64::from(c.limits[2]);
            stats.rejected_records = u64::from(c.limits[3]);
            clock.lap("shade");
            report(sub_frames + k + 1);
        }
        let mut rec = ctx.begin("ic.emission")?;
        self.emission.record(&mut rec, gpu, &self.composite)?;
        if let Some(t) = self.temporal.as_mut().filter(|_| temporal) {
            t.record_keep_instances(&mut rec, gpu);
        }
        clock.submit(ctx, rec)?;
        *rays.entry("emission".into()).or_default() += self.emission.rays()?;
        clock.lap("emission");
        let (pixels, nonfinite_pixels) = self.composite.read_mean(ctx)?;
        if settings.debug_aovs {
            stats.debug = Some(self.read_debug(ctx, sub_frames, stats.records)?);
        }
        clock.lap("readback");
        stats.phases_s = std::mem::take(&mut clock.phases_s);
        Ok((
            FrameOutput {
                width: w,
                height: h,
                pixels,
                spp: sub_frames,
                time_s: clock.elapsed_s(),
                rays,
                passes_ms: std::mem::take(&mut clock.passes_ms),
                spans: clock.spans,
                nonfinite_pixels,
                aovs: None,
            },
            stats,
        ))
    }

    /// The cache phase of sub-frame `k`: its G-buffer, then hole filling level by level. Each
    /// level is two submissions, selection (coverage splat, holes) and creation (records,
    /// neighbours), so the creation's wall time is the record pass's own.
    #[allow(clippy::too_many_arguments)]
    fn fill_holes(
        &self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        k: u32,
        stats: &mut IcStats,
        clock: &mut FrameClock,
    ) -> Result<()> {
        let creation = self.params.for_creation();
        let creation_weights = SplatWeights::from_params(&creation);
        let seed = creation_seed(settings.seed, k);
        let mut rec = ctx.begin("ic.gbuffer")?;
        self.gbuffer_pass
            .record(&mut rec, gpu, &self.gbuffer, sub_frame_jitter(k))?;
        clock.submit(ctx, rec)?;
        clock.lap("cache_gbuffer");
        for level in 0..self.params.levels {
            let selection = Instant::now();
            let mut rec = ctx.begin("ic.select")?;
            self.state.record_begin_level(&mut rec)?;
            // The first level splats every record; each later one adds what the level before
            // created (radii that neighbour clamping shrank since are not redrawn: the final
            // splat uses them).
            let scope = if level == 0 {
                SplatScope::All
            } else {
                SplatScope::LastBatch
            };
            self.splat.record(
                &mut rec,
                "splat.coverage",
                scope,
                gpu,
                &self.gbuffer,
                &self.state,
                &creation_weights,
            )?;
            self.holes.record(
                &mut rec,
                &self.gbuffer,
                &self.splat,
                &self.state,
                self.params.level_spacing_px(level),
                creation.coverage_threshold(),
                seed ^ (level << 16),
                false,
            )?;
            self.state.record_begin_batch(&mut rec)?;
            clock.submit(ctx, rec)?;
            let c = self.state.read_counters()?;
            stats.hole_filling_s += selection.elapsed().as_secs_f64();
            clock.lap("hole_selection");
            if c.dispatch[0] == 0 {
                if c.counts[3] == 0 {
                    break; // no hole at this spacing: finer levels would find none either
                }
                continue;
            }
            let creation_start = Instant::now();
            let mut rec = ctx.begin("ic.create")?;
            self.records.record(
                &mut rec,
                gpu,
                &self.gbuffer,
                &self.state.requests,
                &self.state.counters,
                &self.state.records,
                level,
                k,
                seed,
            )?;
            self.state.record_end_batch(&mut rec)?;
            self.neighbours
                .record(&mut rec, &self.state, gpu.scene_scale())?;
            clock.submit(ctx, rec)?;
            let created_s = creation_start.elapsed().as_secs_f64();
            stats.record_pass_s += created_s;
            stats.hole_filling_s += created_s;
            stats.record_rays += self.records.rays()?;
            stats.records_per_level[level as usize] += u64::from(c.dispatch[0]);
            clock.lap("record_creation");
        }
        Ok(())
    }

    fn read_debug(&self, ctx: &Context, sub_frames: u32, records: u64) -> Result<IcDebug> {
        let (indirect, weight_sum, records_per_pixel) =
            self.composite.read_debug(ctx, sub_frames)?;
        let mut record_positions = vec![0.0f32; (self.width * self.height) as usize];
        let all: Vec<GpuRecord> = ctx.read_buffer(&self.state.records, records as usize)?;
        for r in &all {
            if let Some(p) = record_positions.get_mut(r.info[0] as usize) {
                *p = 1.0;
            }
        }
        Ok(IcDebug {
            indirect,
            weight_sum,
            records_per_pixel,
            record_positions,
        })
    }
}
