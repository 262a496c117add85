//! Neighbour clamping (`shaders/passes/neighbours.comp`, IC reference §7.5) of the batch of records
//! just created, dispatched indirectly with one workgroup per new record.

use radcache_vk::{
    Access, BindingKind, BindingLayout, Context, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::PASS_BASE;
use crate::error::Result;
use crate::ic_state::IcState;

/// The neighbour-clamping pipeline.
pub struct NeighbourPass {
    pipeline: Pipeline,
}

impl std::fmt::Debug for NeighbourPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NeighbourPass").finish_non_exhaustive()
    }
}

impl NeighbourPass {
    /// Compiles the pass.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler) -> Result<NeighbourPass> {
        let spirv = shaders.compile("passes/neighbours.comp", &[])?;
        let bindings = [
            BindingLayout::new(PASS_BASE, BindingKind::StorageBuffer),
            BindingLayout::new(PASS_BASE + 1, BindingKind::StorageBuffer),
            BindingLayout::new(PASS_BASE + 2, BindingKind::StorageBuffer),
        ];
        let pipeline = Pipeline::compute(ctx, "neighbours", &spirv, &bindings, 0)?;
        Ok(NeighbourPass { pipeline })
    }

    /// Records clamping the new batch against every record (after `IcState::record_end_batch`).
    pub fn record(&self, rec: &mut Recorder, state: &IcState) -> Result<()> {
        rec.barrier(Access::ALL_WRITES, Access::COMPUTE_READ_WRITE);
        rec.pass("neighbours", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&[
                (PASS_BASE, Resource::Buffer(&state.counters)),
                (PASS_BASE + 1, Resource::Buffer(&state.records)),
                (PASS_BASE + 2, Resource::Buffer(&state.records)),
            ]);
            rec.dispatch_indirect(&state.counters, 16);
        });
        rec.barrier(Access::COMPUTE_WRITE, Access::ALL);
        Ok(())
    }
}
