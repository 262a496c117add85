//! Hole selection (`shaders/passes/holes.comp`): at a level's spacing S, one record request per
//! S×S block that has uncovered surface pixels, appended to the request list with an atomic
//! counter; or ([`HoleSelection::CountOnly`]) just the number of holes left.
//!
//! Reads the G-buffer and the coverage splat (`bindings::holes`); writes the requests and
//! `IcCounters::{requested, holes, dropped_requests}`.

use radcache_vk::{Context, Pipeline, Recorder, Resource, ShaderCompiler};

use crate::bindings::holes as b;
use crate::error::Result;
use crate::passes::gbuffer::GBuffer;
use crate::passes::splat::SplatPass;
use crate::scene::features::ShaderModule;
use crate::state::IcState;

/// What a selection does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HoleSelection {
    /// One request per `spacing`×`spacing` block that has a surface pixel whose Σw is below
    /// `threshold`; `seed` picks the pixel among the block's holes.
    Request {
        /// Block size in pixels (at least 1).
        spacing: u32,
        /// Coverage below which a pixel is a hole.
        threshold: f32,
        /// Seed of the choice within a block.
        seed: u32,
    },
    /// Count the surface pixels no record reaches (Σw = 0); request nothing.
    CountOnly,
}

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`HolesPush` in GLSL).
    pub struct HolesPush {
        /// Block size S in pixels.
        pub spacing: u32 => "uint",
        /// Coverage Σw below which a pixel is a hole.
        pub threshold: f32 => "float",
        /// Seed of the choice within a block.
        pub seed: u32 => "uint",
        /// 1: count the holes, request nothing.
        pub count_only: u32 => "uint",
    }
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
    /// The shader module the pass compiles.
    pub(crate) fn modules() -> Vec<ShaderModule> {
        vec![ShaderModule::plain("passes/holes.comp")]
    }

    /// Compiles the pass.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler) -> Result<HolePass> {
        let spirv = Self::modules()[0].compile(shaders)?;
        let bindings = b::layout();
        let pipeline = Pipeline::compute(
            ctx,
            "holes",
            &spirv,
            &bindings,
            std::mem::size_of::<HolesPush>() as u32,
        )?;
        Ok(HolePass { pipeline })
    }

    /// Records the selection `what` over the splat's coverage.
    pub fn record(
        &self,
        rec: &mut Recorder,
        gbuffer: &GBuffer,
        splat: &SplatPass,
        state: &IcState,
        what: HoleSelection,
    ) -> Result<()> {
        let push = match what {
            HoleSelection::Request {
                spacing,
                threshold,
                seed,
            } => HolesPush {
                spacing: spacing.max(1),
                threshold,
                seed,
                count_only: 0,
            },
            HoleSelection::CountOnly => HolesPush {
                spacing: 1,
                threshold: f32::MIN_POSITIVE,
                seed: 0,
                count_only: 1,
            },
        };
        let spacing = push.spacing;
        let mut bindings = gbuffer.bindings().to_vec();
        bindings.extend([
            (b::SPLAT_SUM, Resource::StorageImage(&splat.sum)),
            (b::REQUESTS, Resource::Buffer(&state.requests)),
            (b::COUNTERS, Resource::Buffer(&state.counters)),
        ]);
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
