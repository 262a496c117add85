//! Bookkeeping of the cache's counters (`shaders/passes/ic_counters.comp`): one invocation that
//! moves `IcCounters` from one step of the frame to the next (reset, begin level, begin batch,
//! end batch), so the host never reads a count to size the next dispatch or draw. It lives with
//! the state ([`super::IcState`] owns it and its buffer), not among the frame's passes.
//!
//! Reads and writes: the `IcCounters` buffer (`bindings::ic_counters::COUNTERS`).

use radcache_shared::consts::CounterStep as Step;
use radcache_vk::{Buffer, Context, Pipeline, Recorder, Resource, ShaderCompiler};

use crate::bindings::ic_counters as b;
use crate::error::Result;
use crate::scene::features::ShaderModule;

/// The shader, relative to `shaders/`.
pub const SHADER: &str = "passes/ic_counters.comp";

pub use radcache_shared::consts::CounterStep;

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`IcCountersPush` in GLSL).
    pub struct IcCountersPush {
        /// The step (`CounterStep`).
        pub step: u32 => "uint",
        /// Record capacity (stored by a reset).
        pub record_capacity: u32 => "uint",
        /// Request capacity of a batch (stored by a reset).
        pub request_capacity: u32 => "uint",
        /// Padding.
        pub pad: u32 => "uint",
    }
}

/// The bookkeeping pipeline.
pub struct IcCountersPass {
    pipeline: Pipeline,
}

impl std::fmt::Debug for IcCountersPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IcCountersPass").finish_non_exhaustive()
    }
}

impl IcCountersPass {
    /// The shader module the pass compiles.
    pub(crate) fn modules() -> Vec<ShaderModule> {
        vec![ShaderModule::plain(SHADER)]
    }

    /// Compiles the pass.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler) -> Result<IcCountersPass> {
        let spirv = Self::modules()[0].compile(shaders)?;
        let pipeline = Pipeline::compute(
            ctx,
            "ic_counters",
            &spirv,
            &b::layout(),
            std::mem::size_of::<IcCountersPush>() as u32,
        )?;
        Ok(IcCountersPass { pipeline })
    }

    /// Records `step` on `counters`; `capacities` (records, requests) are what a reset stores.
    pub fn record(
        &self,
        rec: &mut Recorder,
        counters: &Buffer,
        step: Step,
        capacities: (u32, u32),
    ) -> Result<()> {
        let push = IcCountersPush {
            step: step as u32,
            record_capacity: capacities.0,
            request_capacity: capacities.1,
            pad: 0,
        };
        rec.bind_pipeline(&self.pipeline);
        rec.push_bindings(&[(b::COUNTERS, Resource::Buffer(counters))]);
        rec.push_constants(&push);
        rec.dispatch(1, 1, 1)?;
        Ok(())
    }
}
