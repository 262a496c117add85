//! Neighbour clamping (`shaders/passes/neighbours.comp`, docs/irradiance-cache.md §4.5,
//! docs/cache-frame.md §5) of the batch of records just created, through a world-space hash grid
//! kept on the GPU (`IcState::grid_heads`, `IcState::grid_next`): the batch is inserted, then each
//! new record reads the 27 cells around it at its own level and the coarser ones, all with indirect
//! dispatches (one workgroup per new record). The result equals the all-pairs clamp (see the
//! shader), at a cost that grows with the number of nearby records instead of with all records.

use radcache_vk::{vk, Context, Pipeline, Recorder, Resource, ShaderCompiler};

use crate::bindings::neighbours as b;
use crate::error::Result;
use crate::scene::features::ShaderModule;
use crate::state::IcState;

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`NeighboursPush` in GLSL).
    pub struct NeighboursPush {
        /// Step.
        pub step: u32 => "uint",
        /// Level max.
        pub level_max: i32 => "int",
        /// Padding.
        pub pad: [u32; 2] => "uvec2",
    }
}

use radcache_shared::consts::NeighbourStep as Mode;

/// What a neighbour dispatch does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NeighbourJob {
    /// Rebuild the grid from every record outside the pending batch (the batch is inserted by
    /// [`NeighbourJob::Batch`]); needed whenever records were added, moved or removed other than
    /// through this pass, e.g. at the start of a frame.
    Rebuild,
    /// Clamp the new batch against every record (after `IcState::record_end_batch`): the
    /// batch's radii are capped at their R⁺ and inserted into the grid, then clamped.
    Batch,
}

/// The neighbour-clamping pipeline.
pub struct NeighbourPass {
    pipeline: Pipeline,
}

impl std::fmt::Debug for NeighbourPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NeighbourPass").finish_non_exhaustive()
    }
}

/// The grid's coarsest level for a scene of size `scene_scale` (its bounding-box diagonal):
/// cells of 2^level ≥ 2 × the scale, so the 27 cells around any record hold every record of the
/// scene at that level.
pub fn grid_level_max(scene_scale: f32) -> i32 {
    let s = if scene_scale.is_finite() && scene_scale > 0.0 {
        scene_scale
    } else {
        1.0
    };
    (s.log2().ceil() as i32 + 1).clamp(-100, 100)
}

impl NeighbourPass {
    /// The shader module the pass compiles.
    pub(crate) fn modules() -> Vec<ShaderModule> {
        vec![ShaderModule::plain("passes/neighbours.comp")]
    }

    /// Compiles the pass.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler) -> Result<NeighbourPass> {
        let spirv = Self::modules()[0].compile(shaders)?;
        let bindings = b::layout();
        let pipeline = Pipeline::compute(
            ctx,
            "neighbours",
            &spirv,
            &bindings,
            std::mem::size_of::<NeighboursPush>() as u32,
        )?;
        Ok(NeighbourPass { pipeline })
    }

    fn bind(&self, rec: &mut Recorder, state: &IcState, mode: Mode, scene_scale: f32) {
        rec.bind_pipeline(&self.pipeline);
        rec.push_bindings(&[
            (b::COUNTERS, Resource::Buffer(&state.counters)),
            (b::RECORDS, Resource::Buffer(&state.records)),
            (b::RECORD_WORDS, Resource::Buffer(&state.records)),
            (b::HEADS, Resource::Buffer(&state.grid_heads)),
            (b::NEXT, Resource::Buffer(&state.grid_next)),
        ]);
        rec.push_constants(&NeighboursPush {
            step: mode as u32,
            level_max: grid_level_max(scene_scale),
            pad: [0; 2],
        });
    }

    /// Records `job` against `state`'s records, `scene_scale` the scene's (the same for a
    /// rebuild and the batches after it).
    pub fn record(
        &self,
        rec: &mut Recorder,
        state: &IcState,
        scene_scale: f32,
        job: NeighbourJob,
    ) -> Result<()> {
        match job {
            NeighbourJob::Rebuild => {
                rec.fill_buffer(&state.grid_heads, 0, vk::WHOLE_SIZE, 0);
                rec.pass("neighbours.grid", |rec| -> Result<()> {
                    self.bind(rec, state, Mode::InsertOld, scene_scale);
                    rec.dispatch(state.record_capacity().div_ceil(64).max(1), 1, 1)?;
                    Ok(())
                })?;
            }
            NeighbourJob::Batch => {
                rec.pass("neighbours", |rec| {
                    self.bind(rec, state, Mode::InsertBatch, scene_scale);
                    rec.dispatch_indirect(&state.counters, 16);
                    self.bind(rec, state, Mode::Clamp, scene_scale);
                    rec.dispatch_indirect(&state.counters, 16);
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::grid_level_max;

    #[test]
    fn the_coarsest_cells_hold_the_whole_scene() {
        for scale in [1e-3f32, 0.7, 1.0, 3.0, 555.0, 1e4] {
            let l = grid_level_max(scale);
            assert!(2f32.powi(l) >= 2.0 * scale, "{scale}: {l}");
            assert!(2f32.powi(l) < 8.0 * scale, "{scale}: {l}");
        }
        assert_eq!(grid_level_max(f32::NAN), 1);
        assert_eq!(grid_level_max(0.0), 1);
    }
}
