//! The phases of [`IcRenderer::render`], in frame order: setup, the cache phase (hole filling
//! per sub-frame and level), the shading of one sub-frame, and the finish (emission, read-back).
//! The temporal look-ahead, between the cache phase and the shading, is in `temporal.rs`.
//! [`FrameRun`] carries what the phases share: the clock, the figures and the progress report.

use std::collections::BTreeMap;
use std::time::Instant;

use radcache_scene::{CameraView, Scene};
use radcache_vk::Context;

use super::{with_composite, IcRenderer, Shading, Temporal};
use crate::error::Result;
use crate::frame::clock::FrameClock;
use crate::frame::path::{FrameOutput, Progress};
use crate::frame::settings::{sub_frame_jitter, IcSettings, IcStats, SplatMode};
use crate::passes::composite::{
    CentreSamples, CompositeInputs, CompositeJob, OwnSamples, WithCentres,
};
use crate::passes::direct::{CompositeSubFrame, Composited, DirectImage, DirectInputs};
use crate::passes::holes::HoleSelection;
use crate::passes::neighbours::NeighbourJob;
use crate::passes::record::{creation_seed, GridJob, RecordInputs, RecordJob};
use crate::passes::splat::{SplatDraw, SplatInputs, SplatOutput, SplatScope, SplatWeights};
use crate::passes::temporal::{expires_at, KeptJob, TemporalInputs, TemporalJob};
use crate::scene::GpuScene;

/// Most passes of the cache phase over the sub-frames (see [`IcRenderer::cache_phase`]).
const MAX_CACHE_PASSES: u32 = 4;

/// What a frame's phases share.
pub(super) struct FrameRun<'p> {
    pub clock: FrameClock,
    pub stats: IcStats,
    /// Ray queries per kind of work (`records`, `direct`, `emission`).
    pub rays: BTreeMap<String, u64>,
    /// Jittered sub-frames of the cache phase (at least 1; 1 when splatting once per frame).
    pub sub_frames: u32,
    /// Sub-frames to shade: the settings' `sub_frames`, more with adaptive anti-aliasing.
    pub shade_total: u32,
    /// Sub-frames shaded so far.
    pub shaded: u32,
    /// Records kept from the previous frame, before the setup's temporal advance.
    pub kept: u32,
    /// Records the temporal advance listed as expired (evaluated again by the look-ahead).
    pub expired: u32,
    /// The sub-frame whose jitter the G-buffer holds for this frame's scene and view, if any:
    /// a pass that needs that same G-buffer does not render it again.
    pub gbuffer_at: Option<u32>,
    start: Instant,
    progress: &'p mut dyn FnMut(Progress),
}

impl<'p> FrameRun<'p> {
    pub fn new(
        levels: u32,
        cache_sub_frames: u32,
        shade_sub_frames: u32,
        progress: &'p mut dyn FnMut(Progress),
    ) -> Self {
        FrameRun {
            clock: FrameClock::new(),
            stats: IcStats {
                records_per_level: vec![0; levels as usize],
                ..IcStats::default()
            },
            rays: BTreeMap::new(),
            sub_frames: cache_sub_frames.max(1),
            shade_total: shade_sub_frames.max(1),
            shaded: 0,
            kept: 0,
            expired: 0,
            gbuffer_at: None,
            start: Instant::now(),
            progress,
        }
    }

    /// Reports `done` of the frame's `sub_frames + shade_total` steps (cache, then shade).
    fn report(&mut self, done: u32) {
        (self.progress)(Progress {
            done,
            total: self.sub_frames + self.shade_total,
            elapsed_s: self.start.elapsed().as_secs_f64(),
        });
    }

    pub fn add_rays(&mut self, kind: &str, rays: u64) {
        *self.rays.entry(kind.into()).or_default() += rays;
    }

    fn records_created(&self) -> u64 {
        self.stats.records_per_level.iter().sum()
    }
}

impl IcRenderer {
    /// **Setup**: the scene at the frame's time and view; eviction of records unused for
    /// `evict_after_frames`; the kept records moved with their instances (temporal caching) or
    /// re-clamped to a new view; the neighbour grid rebuilt; the accumulators cleared. Returns
    /// the camera view of the frame.
    pub(super) fn setup(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        gpu: &mut GpuScene,
        settings: &IcSettings,
        run: &mut FrameRun<'_>,
    ) -> Result<CameraView> {
        gpu.set_time(scene, settings.time)?;
        let view = scene.camera_at(settings.time);
        gpu.set_view(
            &view,
            self.width,
            self.height,
            settings.frame,
            settings.seed,
        )?;
        self.frames += 1;
        let now = self.frames;
        if self.has_records {
            let limit = settings.evict_after_frames;
            let recent = |used: u32| used != 0 && now - used <= limit;
            let evicted = if settings.time_step_s > 0.0 && self.temporal.is_some() {
                // With lifespans, a record that no pixel used in the previous frame is dropped
                // when its lifespan ends rather than evaluated again (docs/temporal.md §2.3).
                self.state.compact_temporal(ctx, |_, used, t| {
                    recent(used) && !(now - used > 1 && expires_at(t, now))
                })?
            } else {
                self.state.compact(ctx, |_, used| recent(used))?
            };
            run.stats.records_evicted = u64::from(evicted);
            run.kept = self.state.read_counters()?.record_count;
        }
        let temporal = settings.time_step_s > 0.0;
        let mut rec = ctx.begin("ic.setup")?;
        gpu.record_update(ctx, &mut rec)?;
        // Records kept with lifespans keep the radiance grid too: the frame ages it by a slice,
        // so that no cell is older than a record may be (`Δt_max`, docs/temporal.md §3.8).
        let lifespans = self.temporal.as_ref().is_some_and(Temporal::lifespans);
        let life = self.params.max_age_frames.round().max(1.0) as u32;
        if let Some(grid) = self.records.grid() {
            let job = if temporal && lifespans && self.has_records {
                GridJob::Age { frame: now, life }
            } else {
                GridJob::Reset
            };
            grid.record(&mut rec, job);
        }
        if !self.has_records {
            self.state.record_reset(&mut rec)?;
        }
        // Kept records take the radius clamp of the new view when the camera moved.
        let clip = gpu.constants().clip_from_world;
        let view_changed = self.reclamp_next || self.last_view.is_some_and(|v| v != clip);
        self.last_view = Some(clip);
        self.reclamp_next = false;
        if let Some(t) = self.temporal.as_mut() {
            if !self.has_records {
                t.forget();
            }
            let (frame, records) = (now, run.kept);
            let io = TemporalInputs {
                scene: gpu,
                state: &self.state,
            };
            let reclamp = view_changed.then_some(&self.params);
            match t {
                Temporal::Lifespans(t) if temporal || view_changed => {
                    let lifespans = temporal.then_some((scene, settings.time, &self.params));
                    let job = TemporalJob::Advance {
                        frame,
                        records,
                        lifespans,
                        reclamp,
                    };
                    t.record(&mut rec, &io, job)?;
                }
                Temporal::Kept(t) => {
                    if let Some(reclamp) = reclamp {
                        let job = KeptJob::Advance {
                            frame,
                            records,
                            reclamp,
                        };
                        t.record(&mut rec, &io, job)?;
                    }
                }
                Temporal::Lifespans(_) => {}
            }
        }
        let scale = gpu.scene_scale();
        self.neighbours
            .record(&mut rec, &self.state, scale, NeighbourJob::Rebuild)?;
        with_composite!(&self.shading, |c| c.record(&mut rec, CompositeJob::Clear))?;
        run.clock.submit(ctx, rec)?;
        run.stats.records_kept = u64::from(self.state.read_counters()?.record_count);
        run.clock.lap("setup");
        if temporal {
            run.expired = self.expired(&mut run.stats)?;
        }
        Ok(view)
    }

    /// **Cache phase**: hole filling for every sub-frame's jitter. Records created for a later
    /// sub-frame shrink earlier ones (neighbour clamping), which can uncover a pixel an earlier
    /// sub-frame had covered: with `settle_records`, passes repeat until one creates nothing (at
    /// most [`MAX_CACHE_PASSES`]), so the records left are a fixed point and the next frame of a
    /// static scene creates none and shades identically. A pass after which no record's used
    /// radius was lowered (`IcCounters::radii_shrunk`) and whose every sub-frame ended on a
    /// selection that found no hole is already that fixed point: coverage only grew since those
    /// selections, so the next pass would create nothing, and it is skipped (its first splat
    /// redraws every record; a kept frame's few new records rarely shrink one).
    pub(super) fn cache_phase(
        &self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        run: &mut FrameRun<'_>,
    ) -> Result<()> {
        // Splatting once, the one cache sub-frame is the only chance to cover the centres, so
        // its passes also repeat: a record created late in a pass can shrink (neighbour
        // clamping) one that covered a centre the pass had already passed.
        let passes = if settings.settle_records || self.splat_mode == SplatMode::Once {
            MAX_CACHE_PASSES
        } else {
            1
        };
        for pass in 0..passes {
            let before = run.records_created();
            let shrunk_before = self.state.read_counters()?.radii_shrunk;
            let mut covered = true;
            for k in 0..run.sub_frames {
                covered &= self.fill_holes(ctx, gpu, settings, k, run)?;
                if pass == 0 {
                    run.report(k + 1);
                }
            }
            run.stats.cache_passes = pass + 1;
            let shrunk = self.state.read_counters()?.radii_shrunk != shrunk_before;
            if run.records_created() == before || (covered && !shrunk) {
                break;
            }
        }
        Ok(())
    }

    /// The cache phase of sub-frame `k`: its G-buffer, then hole filling level by level. Each
    /// level is two submissions, selection (coverage splat, holes) and creation (records,
    /// neighbours), so the creation's wall time is the record pass's own. A level that finds no
    /// hole ends the sub-frame (finer levels would find none either); whether one did is
    /// returned (false: the last level created records or left holes no request reached).
    fn fill_holes(
        &self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        k: u32,
        run: &mut FrameRun<'_>,
    ) -> Result<bool> {
        let creation = self.params.for_creation();
        let creation_weights = SplatWeights::from_params(&creation);
        let seed = creation_seed(settings.seed, k);
        // A repeated pass over the same sub-frame (splatting once: sub-frame 0 alone) finds the
        // G-buffer it needs already there.
        if run.gbuffer_at != Some(k) {
            let mut rec = ctx.begin("ic.gbuffer")?;
            self.gbuffer_pass
                .record(&mut rec, gpu, &self.gbuffer, sub_frame_jitter(k))?;
            run.clock.submit(ctx, rec)?;
            run.gbuffer_at = Some(k);
            run.clock.lap("cache_gbuffer");
        }
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
            let (gbuffer, state) = (&self.gbuffer, &self.state);
            let inputs = SplatInputs {
                scene: gpu,
                gbuffer,
                state,
            };
            let draw = SplatDraw {
                name: "splat.coverage",
                scope,
                output: SplatOutput::Coverage,
                weights: &creation_weights,
            };
            self.splat.record(&mut rec, &inputs, &draw)?;
            let selection_mode = HoleSelection::Request {
                spacing: self.params.level_spacing_px(level),
                threshold: creation.coverage_threshold(),
                seed: seed ^ (level << 16),
            };
            self.holes
                .record(&mut rec, gbuffer, &self.splat, state, selection_mode)?;
            self.state.record_begin_batch(&mut rec)?;
            run.clock.submit(ctx, rec)?;
            let c = self.state.read_counters()?;
            run.stats.hole_filling_s += selection.elapsed().as_secs_f64();
            run.clock.lap("hole_selection");
            if c.dispatch.x == 0 {
                if c.holes == 0 {
                    return Ok(true);
                }
                continue;
            }
            let creation_start = Instant::now();
            let mut rec = ctx.begin("ic.create")?;
            let inputs = RecordInputs {
                scene: gpu,
                gbuffer,
                requests: &state.requests,
                counters: &state.counters,
                job: RecordJob::Create {
                    level,
                    sub_frame: k,
                    seed,
                },
            };
            let radiance = state.radiance.as_ref();
            self.records
                .record(&mut rec, &inputs, &state.records, radiance)?;
            self.state.record_end_batch(&mut rec)?;
            let scale = gpu.scene_scale();
            self.neighbours
                .record(&mut rec, &self.state, scale, NeighbourJob::Batch)?;
            run.clock.submit(ctx, rec)?;
            let created_s = creation_start.elapsed().as_secs_f64();
            run.stats.record_pass_s += created_s;
            run.stats.hole_filling_s += created_s;
            run.stats.record_rays += self.records.rays()?;
            run.stats.records_per_level[level as usize] += u64::from(c.dispatch.x);
            run.clock.lap("record_creation");
        }
        Ok(false)
    }

    /// **Shade** sub-frame `k`: its G-buffer, direct light, the splat of every record with the
    /// final weights (marking the records used this frame), the count of the holes left, and
    /// the composite into the frame accumulator. Splatting once per frame ([`SplatMode::Once`])
    /// only sub-frame 0 (the pixel centres) splats, counts holes and stores its samples; every
    /// later one composites against those centres (docs/cache-frame.md §6.5).
    pub(super) fn shade_sub_frame(
        &self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        k: u32,
        run: &mut FrameRun<'_>,
    ) -> Result<()> {
        let final_weights = SplatWeights {
            mark_frame: self.frames,
            ..SplatWeights::from_params(&self.params)
        };
        let jitter = sub_frame_jitter(k);
        let (gbuffer, state) = (&self.gbuffer, &self.state);
        let splats = k == 0 || self.splat_mode == SplatMode::PerSubFrame;
        let centre = match k {
            0 => CentreSamples::Store,
            _ => CentreSamples::Match,
        };
        let mut rec = ctx.begin("ic.shade")?;
        // Sub-frame 0 after a cache phase that ended on it (splatting once) has its G-buffer.
        if run.gbuffer_at != Some(k) {
            self.gbuffer_pass.record(&mut rec, gpu, gbuffer, jitter)?;
            run.gbuffer_at = Some(k);
        }
        let glossy = self.glossy();
        let debug = settings.debug_aovs;
        // Splatting once, the direct pass composites the later sub-frames itself (it has their
        // samples loaded; docs/cache-frame.md §6.5) but for the debug AOVs; sub-frame 0 writes
        // the direct image for the composite after the splat.
        let composited = match &self.shading {
            Shading::Once { .. } => centre == CentreSamples::Match && !debug,
            Shading::PerSubFrame { .. } => false,
        };
        let inputs = DirectInputs {
            scene: gpu,
            gbuffer,
            samples: settings.direct_samples,
            sub_frame: k,
            seed: settings.seed,
            glossy,
        };
        match &self.shading {
            Shading::Once { direct, composite } => {
                let outputs = Composited {
                    composite,
                    splat: &self.splat,
                    sub_frame: composited.then_some(CompositeSubFrame { jitter }),
                };
                direct.record(&mut rec, &inputs, &outputs)?
            }
            Shading::PerSubFrame { direct, .. } => {
                direct.record(&mut rec, &inputs, &DirectImage)?
            }
        }
        if splats {
            // The records per pixel only for the debug AOVs (a second blended target).
            let output = if settings.debug_aovs {
                SplatOutput::IrradianceAndCount
            } else {
                SplatOutput::Irradiance
            };
            let inputs = SplatInputs {
                scene: gpu,
                gbuffer,
                state,
            };
            let draw = SplatDraw {
                output,
                ..SplatDraw::all(&final_weights)
            };
            self.splat.record(&mut rec, &inputs, &draw)?;
            if let Some(g) = glossy {
                g.record(&mut rec, gpu, gbuffer, state, &final_weights)?;
            }
            self.state.record_begin_level(&mut rec)?;
            self.holes.record(
                &mut rec,
                gbuffer,
                &self.splat,
                state,
                HoleSelection::CountOnly,
            )?;
        }
        if !composited {
            let inputs = CompositeInputs {
                scene: gpu,
                gbuffer,
                splat: &self.splat,
                glossy,
                jitter,
                centre: OwnSamples,
                debug,
            };
            match &self.shading {
                Shading::PerSubFrame { composite, .. } => {
                    composite.record(&mut rec, CompositeJob::Add(&inputs))?
                }
                Shading::Once { composite, .. } => {
                    let inputs = inputs.at::<WithCentres>(centre);
                    composite.record(&mut rec, CompositeJob::Add(&inputs))?
                }
            }
        }
        run.clock.submit(ctx, rec)?;
        let direct_rays = match &self.shading {
            Shading::Once { direct, .. } => direct.rays()?,
            Shading::PerSubFrame { direct, .. } => direct.rays()?,
        };
        run.add_rays("direct", direct_rays);
        if splats {
            let c = self.state.read_counters()?;
            run.stats.holes_left += u64::from(c.holes);
            run.stats.records = u64::from(c.record_count);
            run.stats.dropped_requests = u64::from(c.dropped_requests);
            run.stats.rejected_records = u64::from(c.rejected_records);
        }
        run.clock.lap("shade");
        run.shaded = k + 1;
        run.report(run.sub_frames + k + 1);
        Ok(())
    }

    /// **Finish**: the box-filtered emission, the instances kept for the next frame's motion,
    /// the look-ahead's radiance blocks promoted for the next frame, the read-back of the mean over the sub-frames (and of the debug AOVs), the figures.
    pub(super) fn finish(
        &mut self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        mut run: FrameRun<'_>,
    ) -> Result<(FrameOutput, IcStats)> {
        let mut rec = ctx.begin("ic.emission")?;
        with_composite!(&self.shading, |c| self.emission.record(&mut rec, gpu, c))?;
        if let Some(Temporal::Lifespans(t)) = self
            .temporal
            .as_mut()
            .filter(|_| settings.time_step_s > 0.0)
        {
            let io = TemporalInputs {
                scene: gpu,
                state: &self.state,
            };
            t.record(&mut rec, &io, TemporalJob::KeepInstances)?;
            t.record(&mut rec, &io, TemporalJob::PromoteRadiance)?;
        }
        run.clock.submit(ctx, rec)?;
        run.add_rays("emission", self.emission.rays()?);
        run.clock.lap("emission");
        let (pixels, nonfinite_pixels) = with_composite!(&self.shading, |c| c.read_mean(ctx))?;
        if settings.debug_aovs {
            let debug = self.read_debug(ctx, run.shaded, run.stats.records)?;
            run.stats.debug = Some(debug);
        }
        run.clock.lap("readback");
        run.stats.sub_frames_shaded = run.shaded;
        if settings.anti_aliasing.is_none() || run.stats.mean_pixel_sub_frames == 0.0 {
            run.stats.mean_pixel_sub_frames = f64::from(run.shaded);
        }
        run.stats.unmatched_samples = with_composite!(&self.shading, |c| c.read_unmatched())?;
        let mut clock = run.clock;
        run.stats.phases_s = std::mem::take(&mut clock.phases_s);
        let output = FrameOutput {
            width: self.width,
            height: self.height,
            pixels,
            spp: run.shaded,
            time_s: clock.elapsed_s(),
            rays: run.rays,
            passes_ms: std::mem::take(&mut clock.passes_ms),
            spans: clock.spans,
            nonfinite_pixels,
            aovs: None,
        };
        Ok((output, run.stats))
    }
}
