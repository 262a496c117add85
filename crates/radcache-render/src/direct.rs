//! Direct lighting of the cache's frame (`shaders/passes/direct.comp`): next-event estimation with
//! MIS per surface pixel, compiled with the plan's defines (only the scene's light sources).

use bytemuck::{Pod, Zeroable};
use radcache_vk::{
    vk, Access, BindingKind, BindingLayout, Buffer, BufferDesc, Context, MemoryLocation, Pipeline,
    Recorder, Resource, ShaderCompiler,
};

use crate::bindings::with_scene;
use crate::error::Result;
use crate::gbuffer::{GBuffer, GBUFFER_BINDINGS};
use crate::gpu_scene::GpuScene;

const RAYS: u32 = crate::bindings::PASS_BASE + GBUFFER_BINDINGS;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    samples: u32,
    seed: u32,
    first_sample: u32,
    pad: u32,
}

/// The direct-lighting pipeline and its ray counter.
pub struct DirectPass {
    pipeline: Pipeline,
    rays: Buffer,
}

impl std::fmt::Debug for DirectPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DirectPass").finish_non_exhaustive()
    }
}

impl DirectPass {
    /// Compiles the pass for `scene`'s plan.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler, scene: &GpuScene) -> Result<DirectPass> {
        let spirv = shaders.compile("passes/direct.comp", &scene.defines())?;
        let mut pass = GBuffer::layout().to_vec();
        pass.push(BindingLayout::new(RAYS, BindingKind::StorageBuffer));
        let pipeline = Pipeline::compute(
            ctx,
            "direct",
            &spirv,
            &with_scene(&pass),
            std::mem::size_of::<Push>() as u32,
        )?;
        let rays = Buffer::new(
            ctx,
            &BufferDesc {
                name: "direct.ray_count",
                size: 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
                alignment: 0,
            },
        )?;
        Ok(DirectPass { pipeline, rays })
    }

    /// Records `samples` estimates per pixel into the G-buffer's direct image: samples
    /// `first_sample .. first_sample + samples` of the pixel's low-discrepancy sequence for the
    /// frame's `seed` (sub-frames continue one sequence: pass `k × samples` for sub-frame k).
    pub fn record(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        samples: u32,
        first_sample: u32,
        seed: u32,
    ) -> Result<()> {
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        rec.barrier(Access::TRANSFER_WRITE, Access::COMPUTE_READ_WRITE);
        let mut bindings = scene.bindings();
        bindings.extend(gbuffer.bindings());
        bindings.push((RAYS, Resource::Buffer(&self.rays)));
        let push = Push {
            samples: samples.max(1),
            seed,
            first_sample,
            pad: 0,
        };
        let (w, h) = (gbuffer.width, gbuffer.height);
        rec.pass("direct", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.dispatch(w.div_ceil(8), h.div_ceil(8), 1)
        })?;
        rec.barrier(Access::COMPUTE_WRITE, Access::ALL);
        Ok(())
    }

    /// Ray queries of the last submitted pass.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}
