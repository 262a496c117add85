//! Hole selection (`shaders/passes/holes.comp`): at a level's spacing S, one record request per
//! S×S block that has uncovered surface pixels, appended to the request list with an atomic
//! counter; or, with `count_only`, just the number of holes left.

use bytemuck::{Pod, Zeroable};
use radcache_vk::{
    BindingKind, BindingLayout, Context, ImageUse, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::PASS_BASE;
use crate::error::Result;
use crate::gbuffer::{GBuffer, GBUFFER_BINDINGS};
use crate::ic_state::IcState;
use crate::splat::SplatPass;

const BASE: u32 = PASS_BASE + GBUFFER_BINDINGS;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    spacing: u32,
    threshold: f32,
    seed: u32,
    count_only: u32,
}

/// The hole-selection pipeline.
pub struct HolePass {
    pipeline: Pipeline,
}

impl std::fmt::Debug for HolePass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HolePass").finish_non_exhaustive()
    }
}

impl HolePass {
    /// Compiles the pass.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler) -> Result<HolePass> {
        let spirv = shaders.compile("passes/holes.comp", &[])?;
        let mut bindings: Vec<BindingLayout> = GBuffer::layout().to_vec();
        bindings.push(BindingLayout::new(BASE, BindingKind::StorageImage));
        bindings.push(BindingLayout::new(BASE + 1, BindingKind::StorageBuffer));
        bindings.push(BindingLayout::new(BASE + 2, BindingKind::StorageBuffer));
        let pipeline = Pipeline::compute(
            ctx,
            "holes",
            &spirv,
            &bindings,
            std::mem::size_of::<Push>() as u32,
        )?;
        Ok(HolePass { pipeline })
    }

    /// Records the selection at `spacing` pixels with coverage `threshold` (Σw below it is a hole).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        gbuffer: &GBuffer,
        splat: &SplatPass,
        state: &IcState,
        spacing: u32,
        threshold: f32,
        seed: u32,
        count_only: bool,
    ) -> Result<()> {
        let spacing = spacing.max(1);
        let push = Push {
            spacing,
            threshold,
            seed,
            count_only: u32::from(count_only),
        };
        for image in gbuffer.images() {
            rec.use_image(image, ImageUse::ComputeStorage);
        }
        rec.use_image(&splat.sum, ImageUse::ComputeStorage);
        let mut bindings = gbuffer.bindings().to_vec();
        bindings.push((BASE, Resource::StorageImage(&splat.sum)));
        bindings.push((BASE + 1, Resource::Buffer(&state.requests)));
        bindings.push((BASE + 2, Resource::Buffer(&state.counters)));
        let blocks_x = gbuffer.width.div_ceil(spacing);
        let blocks_y = gbuffer.height.div_ceil(spacing);
        rec.pass("holes", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.dispatch(blocks_x.div_ceil(8), blocks_y.div_ceil(8), 1)
        })?;
        Ok(())
    }
}
