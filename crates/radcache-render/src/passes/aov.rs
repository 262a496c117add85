//! The AOV pass (`shaders/passes/aov.comp`): first-hit diffuse albedo, world shading normal and
//! depth per pixel, box-filtered over 4×4 sub-pixel positions.

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::aov as b;
use crate::error::Result;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;

/// The shader, relative to `shaders/`.
pub const SHADER: &str = "passes/aov.comp";

/// AOVs of one image (rows top to bottom).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Aovs {
    /// Diffuse albedo, RGB interleaved.
    pub albedo: Vec<f32>,
    /// Unit world-space shading normal facing the camera (zero where the pixel sees nothing), XYZ.
    pub normal: Vec<f32>,
    /// Mean hit distance from the camera (0 where the pixel sees nothing).
    pub depth: Vec<f32>,
}

/// The AOV pass for one image size.
pub struct AovPass {
    pipeline: Pipeline,
    albedo: Buffer,
    normal: Buffer,
    depth: Buffer,
    width: u32,
    height: u32,
}

impl std::fmt::Debug for AovPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AovPass")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

impl AovPass {
    /// The shader module the pass compiles for a scene with `features`.
    pub(crate) fn modules(features: &SceneFeatures) -> Vec<ShaderModule> {
        vec![ShaderModule::new(SHADER, features.material_defines())]
    }

    /// Compiles the pass for `scene`'s materials (the alpha test where the plan has it) and
    /// allocates its outputs.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        width: u32,
        height: u32,
    ) -> Result<AovPass> {
        let spirv = Self::modules(&scene.features())[0].compile(shaders)?;
        let bindings = b::layout();
        let pipeline = Pipeline::compute(ctx, "aov", &spirv, &bindings, 0)?;
        let pixels = u64::from(width) * u64::from(height);
        let buffer = |name, texel: u64| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size: pixels * texel,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                    alignment: 0,
                },
            )
        };
        Ok(AovPass {
            pipeline,
            albedo: buffer("aov.albedo", 16)?,
            normal: buffer("aov.normal", 16)?,
            depth: buffer("aov.depth", 4)?,
            width,
            height,
        })
    }

    /// Records the pass (the scene's view must be set for this image size).
    pub fn record(&self, rec: &mut Recorder, scene: &GpuScene) -> Result<()> {
        let mut bindings = scene.bindings();
        bindings.push((b::ALBEDO, Resource::Buffer(&self.albedo)));
        bindings.push((b::NORMAL, Resource::Buffer(&self.normal)));
        bindings.push((b::DEPTH, Resource::Buffer(&self.depth)));
        let (w, h) = (self.width, self.height);
        rec.pass("aov", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            let [x, y, z] = image_dispatch(w, h);
            rec.dispatch(x, y, z)
        })?;
        Ok(())
    }

    /// Reads the AOVs back (after the submission's fence).
    pub fn read(&self, ctx: &Context) -> Result<Aovs> {
        let n = (self.width * self.height) as usize;
        let rgb = |v: Vec<[f32; 4]>| -> Vec<f32> {
            v.iter()
                .flat_map(|p| [p[0], p[1], p[2]])
                .map(|c| if c.is_finite() { c } else { 0.0 })
                .collect()
        };
        Ok(Aovs {
            albedo: rgb(ctx.read_buffer(&self.albedo, n)?),
            normal: rgb(ctx.read_buffer(&self.normal, n)?),
            depth: ctx
                .read_buffer::<f32>(&self.depth, n)?
                .into_iter()
                .map(|d| if d.is_finite() { d } else { 0.0 })
                .collect(),
        })
    }
}

/// Computes the AOVs of the current view of `scene` (after `GpuScene::set_view` for this size and
/// a TLAS update) in one submission.
pub fn render_aovs(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &GpuScene,
    width: u32,
    height: u32,
) -> Result<Aovs> {
    let pass = AovPass::new(ctx, shaders, scene, width, height)?;
    let mut rec = ctx.begin("aov")?;
    pass.record(&mut rec, scene)?;
    ctx.submit(rec)?.wait()?;
    pass.read(ctx)
}
