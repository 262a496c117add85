//! The temporal steps of [`IcRenderer::render`] (`passes/temporal.rs`): the records whose lifespan
//! ended, and the look-ahead evaluation of them and of the frame's new records.

use radcache_scene::{CameraView, Scene};
use radcache_vk::Context;

use super::{FrameRun, IcRenderer, Temporal};
use crate::error::{Error, Result};
use crate::frame::settings::{IcSettings, IcStats};
use crate::passes::record::{RecordInputs, RecordJob};
use crate::passes::temporal::{
    Lifespans, TemporalInputs, TemporalJob, TemporalPass, WithLifespans,
};
use crate::scene::GpuScene;

impl IcRenderer {
    /// The temporal pass of a renderer made with a time step.
    fn temporal_pass(&self) -> Result<&TemporalPass<WithLifespans>> {
        match &self.temporal {
            Some(Temporal::Lifespans(t)) => Ok(t),
            _ => Err(no_time_step()),
        }
    }

    /// The records the advance listed as expired (evaluated again by [`Self::look_ahead`]).
    pub(super) fn expired(&self, stats: &mut IcStats) -> Result<u32> {
        let expired = self.temporal_pass()?.listed()?;
        stats.records_refreshed = u64::from(expired);
        Ok(expired)
    }

    /// Adopts the frame's new records, evaluates them and the `expired` ones (listed by the
    /// advance) with the scene at `settings.time + settings.time_step_s`, and derives their rates
    /// and lifespans; the scene is back at the frame's time (and `view`) afterwards.
    pub(super) fn look_ahead(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        gpu: &mut GpuScene,
        settings: &IcSettings,
        view: &CameraView,
        run: &mut FrameRun<'_>,
    ) -> Result<()> {
        // The refresh binds the G-buffer without reading or writing it, and the scene returns
        // to the frame's time and view below: `run.gbuffer_at` stays true.
        let (expired, stats, clock) = (run.expired, &mut run.stats, &mut run.clock);
        let Some(Temporal::Lifespans(t)) = self.temporal.as_mut() else {
            return Err(no_time_step());
        };
        let count = self.state.read_counters()?.record_count;
        let first = stats.records_kept as u32;
        let listed = expired
            .saturating_add(count.saturating_sub(first))
            .min(self.state.record_capacity());
        let frame = self.frames;
        let mut rec = ctx.begin("ic.adopt")?;
        let io = TemporalInputs {
            scene: gpu,
            state: &self.state,
        };
        let job = TemporalJob::Adopt {
            frame,
            first,
            records: count,
            listed,
        };
        t.record(&mut rec, &io, job)?;
        clock.submit(ctx, rec)?;
        if listed == 0 {
            clock.lap("lookahead");
            return Ok(());
        }
        let (w, h) = (self.width, self.height);
        gpu.set_time(scene, settings.time + settings.time_step_s)?;
        gpu.set_view(view, w, h, settings.frame, settings.seed)?;
        let mut rec = ctx.begin("ic.lookahead")?;
        gpu.record_update(ctx, &mut rec)?;
        let io = TemporalInputs {
            scene: gpu,
            state: &self.state,
        };
        t.record(&mut rec, &io, TemporalJob::Shift { listed })?;
        let inputs = RecordInputs {
            scene: gpu,
            gbuffer: &self.gbuffer,
            requests: &t.list,
            counters: &t.list_counters,
            job: RecordJob::Refresh {
                frame_seed: settings.seed,
            },
        };
        let radiance = t.lookahead_radiance.as_ref();
        self.records
            .record(&mut rec, &inputs, &t.lookahead, radiance)?;
        let lifespans = Lifespans {
            accuracy: self.params.temporal_accuracy,
            max_age: self.params.max_age_frames,
        };
        let next = (scene, settings.time + settings.time_step_s);
        let job = TemporalJob::Finish {
            frame,
            listed,
            lifespans,
            next,
        };
        t.record(&mut rec, &io, job)?;
        clock.submit(ctx, rec)?;
        let rays = self.records.rays()?;
        stats.lookahead_rays += rays;
        stats.record_rays += rays;

        gpu.set_time(scene, settings.time)?;
        gpu.set_view(view, w, h, settings.frame, settings.seed)?;
        let mut rec = ctx.begin("ic.restore")?;
        gpu.record_update(ctx, &mut rec)?;
        clock.submit(ctx, rec)?;
        clock.lap("lookahead");
        Ok(())
    }
}

fn no_time_step() -> Error {
    Error::Invalid("temporal caching needs a renderer created with a time step".into())
}
