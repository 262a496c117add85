//! The anti-aliasing phase of a cache frame (docs/cache-frame.md §7.1, §7.2): more sub-frames
//! after the cache's, for the whole frame or for the pixels that still need them.

use radcache_vk::Context;

use super::phases::FrameRun;
use super::{with_composite, IcRenderer, Shading};
use crate::error::Result;
use crate::frame::aa::{mean_count, next_sub_frames, plan_pixels, sampling_relmse};
use crate::frame::settings::{AntiAliasing, IcSettings};
use crate::scene::GpuScene;

impl IcRenderer {
    /// **Adaptive anti-aliasing** (docs/cache-frame.md §7.1): while the sampling relMSE estimated
    /// from the accumulated moments is above `aa.target`, shades more sub-frames with the
    /// records as they are, up to `aa.max_sub_frames`. Per pixel (`aa.per_pixel`, §7.2) each
    /// batch shades only the pixels [`plan_pixels`] says still need samples, as far as it says;
    /// otherwise every pixel, as far as `1/n` predicts for the whole frame
    /// ([`next_sub_frames`]). The G-buffer's activity mask is all 1 again afterwards.
    pub(super) fn anti_alias(
        &mut self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        aa: AntiAliasing,
        run: &mut FrameRun<'_>,
    ) -> Result<()> {
        let result = self.anti_alias_batches(ctx, gpu, settings, aa, run);
        // The batches' own error, if any, is the one to report.
        let reset = self.gbuffer.set_active(None);
        result.and(reset)
    }

    fn anti_alias_batches(
        &mut self,
        ctx: &Context,
        gpu: &GpuScene,
        settings: &IcSettings,
        aa: AntiAliasing,
        run: &mut FrameRun<'_>,
    ) -> Result<()> {
        loop {
            let Some((sums, squares)) = with_composite!(&self.shading, |c| c.read_moments(ctx))?
            else {
                return Ok(());
            };
            let estimate = sampling_relmse(&sums, &squares);
            run.stats.aa_relmse_estimate = Some(estimate);
            run.stats.mean_pixel_sub_frames = mean_count(&sums);
            run.clock.lap("anti_aliasing");
            let done = run.shaded;
            if estimate <= aa.target || done >= aa.max_sub_frames {
                return Ok(());
            }
            let next = if aa.per_pixel {
                let plan = plan_pixels(
                    &sums,
                    &squares,
                    self.width,
                    self.height,
                    done,
                    aa.target,
                    aa.max_sub_frames,
                );
                if plan.active == 0 {
                    return Ok(());
                }
                self.gbuffer.set_active(Some(&plan.mask))?;
                plan.next
            } else {
                next_sub_frames(done, estimate, aa.target, aa.max_sub_frames)
            };
            run.shade_total = next;
            for k in done..next {
                self.shade_sub_frame(ctx, gpu, settings, k, run)?;
            }
        }
    }
}
