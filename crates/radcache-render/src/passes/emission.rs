//! Box-filtered emission (`shaders/passes/emission.comp`): after the sub-frames, pixels at or next
//! to emitters get their emission from 64 camera rays on a Hammersley (0,6,2)-net, digitally
//! shifted per pixel (every 8×8 stratum and every 1/64 row and column of the pixel holds one ray,
//! so an axis-aligned edge's coverage is exact to 1/64), so emitter edges are filtered like the
//! reference's instead of being quantised by the few sub-frame jitters.

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::emission as b;
use crate::error::Result;
use crate::passes::composite::{Centres, CompositePass};
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;

/// The emission pipeline and its ray counter.
pub struct EmissionPass {
    pipeline: Pipeline,
    rays: Buffer,
}

impl std::fmt::Debug for EmissionPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EmissionPass").finish_non_exhaustive()
    }
}

impl EmissionPass {
    /// The shader module the pass compiles for a scene with `features`.
    pub(crate) fn modules(features: &SceneFeatures) -> Vec<ShaderModule> {
        vec![ShaderModule::new(
            "passes/emission.comp",
            features.defines(),
        )]
    }

    /// Compiles the pass.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler, scene: &GpuScene) -> Result<EmissionPass> {
        let spirv = Self::modules(&scene.features())[0].compile(shaders)?;
        let pipeline = Pipeline::compute(ctx, "emission", &spirv, &b::layout(), 0)?;
        let rays = Buffer::new(
            ctx,
            &BufferDesc {
                name: "emission.ray_count",
                size: 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
                alignment: 0,
            },
        )?;
        Ok(EmissionPass { pipeline, rays })
    }

    /// Records adding the box-filtered emission to `composite`'s accumulator (once, after the
    /// last sub-frame; the scene's view must be the unjittered one of this image).
    pub fn record<C: Centres>(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        composite: &CompositePass<C>,
    ) -> Result<()> {
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        let mut bindings = scene.bindings();
        bindings.extend([
            (b::ACCUM, Resource::Buffer(&composite.accum)),
            (
                b::EMISSION_ACCUM,
                Resource::Buffer(&composite.emission_accum),
            ),
            (b::RAY_COUNT, Resource::Buffer(&self.rays)),
        ]);
        let (w, h) = composite.size();
        rec.pass("emission", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            let [x, y, z] = image_dispatch(w, h);
            rec.dispatch(x, y, z)
        })?;
        Ok(())
    }

    /// Ray queries of the last submitted pass.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}
