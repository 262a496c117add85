//! Irradiance records (`shaders/passes/record.comp`): one workgroup per requested pixel, dispatched
//! indirectly from the counters (the host never learns the request count), M×N stratified gather
//! rays each, the record formed as `radcache_cache::compute_record` + `finalize_radius` do.

use bytemuck::{Pod, Zeroable};
use radcache_cache::IcParams;
use radcache_vk::{
    vk, Access, BindingKind, BindingLayout, Buffer, BufferDesc, Context, ImageUse, MemoryLocation,
    Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::{with_scene, PASS_BASE};
use crate::error::{Error, Result};
use crate::gbuffer::{GBuffer, GBUFFER_BINDINGS};
use crate::gpu_scene::GpuScene;
use crate::ic_state::IcState;

const BASE: u32 = PASS_BASE + GBUFFER_BINDINGS;
/// Most strata a record may have (the shader's shared-memory arrays).
pub const MAX_STRATA: u32 = 1728;
/// Distances at or below this fraction of the scene's size are invalid samples (self-hits).
pub const R_EPS_REL: f32 = 1.0e-5;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    m: u32,
    n: u32,
    seed: u32,
    level_subframe: u32,
    min_px: f32,
    max_px: f32,
    v_scale: f32,
    r_eps_rel: f32,
}

/// The record pipeline, its parameters and its ray counter.
pub struct RecordPass {
    pipeline: Pipeline,
    rays: Buffer,
    params: IcParams,
}

impl std::fmt::Debug for RecordPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordPass")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl RecordPass {
    /// Compiles the pass for `scene`'s plan with the cache parameters `params`.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        params: &IcParams,
    ) -> Result<RecordPass> {
        if params.sample_count() > MAX_STRATA || params.strata_n < 3 {
            return Err(Error::Invalid(format!(
                "{}×{} strata: at most {MAX_STRATA} in all and N ≥ 3",
                params.strata_m, params.strata_n
            )));
        }
        let spirv = shaders.compile("passes/record.comp", &scene.defines())?;
        let mut pass = GBuffer::layout().to_vec();
        for i in 0..4 {
            pass.push(BindingLayout::new(BASE + i, BindingKind::StorageBuffer));
        }
        let pipeline = Pipeline::compute(
            ctx,
            "records",
            &spirv,
            &with_scene(&pass),
            std::mem::size_of::<Push>() as u32,
        )?;
        let rays = Buffer::new(
            ctx,
            &BufferDesc {
                name: "records.ray_count",
                size: 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
                alignment: 0,
            },
        )?;
        Ok(RecordPass {
            pipeline,
            rays,
            params: *params,
        })
    }

    /// Records computing the pending batch (after `IcState::record_begin_batch`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        state: &IcState,
        level: u32,
        sub_frame: u32,
        seed: u32,
    ) -> Result<()> {
        let p = &self.params;
        let push = Push {
            m: p.strata_m,
            n: p.strata_n,
            seed,
            level_subframe: (level & 0xffff) | (sub_frame << 16),
            min_px: p.min_spacing_px,
            max_px: p.max_spacing_px,
            v_scale: p.validity_scale(),
            r_eps_rel: R_EPS_REL,
        };
        for image in gbuffer.images() {
            rec.use_image(image, ImageUse::ComputeStorage);
        }
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        rec.barrier(Access::TRANSFER_WRITE, Access::COMPUTE_READ_WRITE);
        let mut bindings = scene.bindings();
        bindings.extend(gbuffer.bindings());
        bindings.push((BASE, Resource::Buffer(&state.requests)));
        bindings.push((BASE + 1, Resource::Buffer(&state.counters)));
        bindings.push((BASE + 2, Resource::Buffer(&state.records)));
        bindings.push((BASE + 3, Resource::Buffer(&self.rays)));
        rec.pass("records", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.dispatch_indirect(&state.counters, 16);
        });
        rec.barrier(Access::COMPUTE_WRITE, Access::ALL);
        Ok(())
    }

    /// Ray queries of the last submitted batch.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}
