//! Direct lighting of the cache's frame (`shaders/passes/direct.comp`): next-event estimation with
//! MIS per surface pixel, compiled with the plan's defines (only the scene's light sources; a
//! constant environment only where the sky does not go through the records, [`SkyLight`]).

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, Access, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource,
    ShaderCompiler,
};

use crate::bindings::direct as b;
use crate::error::{Error, Result};
use crate::frame::settings::{EmitterLight, SkyLight};
use crate::passes::gbuffer::GBuffer;
use crate::passes::splat_glossy::GlossySplatPass;
use crate::scene::GpuScene;

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`DirectPush` in GLSL).
    pub struct DirectPush {
        /// Samples.
        pub samples: u32 => "uint",
        /// Seed.
        pub seed: u32 => "uint",
        /// Sub-frame (its samples continue the previous sub-frames' sequences).
        pub sub_frame: u32 => "uint",
        /// Paths of the specular lobe's indirect light per pixel (scenes with specular
        /// materials; [`specular_paths`]).
        pub specular_paths: u32 => "uint",
        /// 1: glossy lobes at or above `GLOSSY_ROUGHNESS_MIN` take their indirect light from the
        /// radiance records (pass built with radiance; docs/radiance-caching.md §6.2).
        pub radiance_cache: u32 => "uint",
        /// 1: after sub-frame 0, pixels whose neighbourhood saw the emitters wholly visible or
        /// wholly hidden (and no neighbour a penumbra) cast one emitter shadow ray instead of a
        /// quarter of the samples, none where every 3×3 neighbour saw the same, and punctual
        /// lights' shadow rays are left out there likewise
        /// ([`DirectPass::with_adaptive_shadows`]; docs/cache-frame.md §8.2).
        pub adaptive_shadows: u32 => "uint",
        /// 1: a pixel's specular paths are pooled with those of its 3×3 neighbours whose lobes
        /// overlap its own ([`DirectPass::with_specular_pool`]; docs/materials.md §10).
        pub specular_pool: u32 => "uint",
        /// Padding.
        pub pad2: u32 => "uint",
    }
}

/// Paths per pixel and sub-frame that trace the specular lobe's indirect light (scenes with
/// specular materials): as many as the direct samples, at least one. A path costs a few rays
/// (a gather path's length), a direct sample one, but the paths carry the noise: on
/// `metal_spheres` (256², default preset) a quarter of the direct samples gave relMSE 1.083e-3
/// in 10.2–10.7 s, as many 8.17e-4 in 10.0–10.4 s (the frame meets its anti-aliasing target at 8
/// sub-frames instead of 17), twice as many 6.38e-4 in 8.4–12.5 s; on `glossy_room` (128²)
/// 6.70e-4 and 6.39e-4 in the same 4.3–4.4 s (docs/materials.md §10).
pub fn specular_paths(direct_samples: u32) -> u32 {
    direct_samples.max(1)
}

/// The direct-lighting pipeline and its ray counter.
pub struct DirectPass {
    pipeline: Pipeline,
    rays: Buffer,
    /// Bound for the glossy weights and table when the pass has no glossy splat to write for.
    placeholder: Buffer,
    /// The emitters' light is taken in closed form (`HAS_ANALYTIC_EMITTERS`).
    analytic: bool,
    /// The scene has punctual lights (`HAS_LIGHTS`).
    punctual: bool,
    /// Two `uint` a pixel: what its neighbourhood saw of the emitters in this frame's
    /// sub-frames so far, and what sub-frame 0 saw of them and of the punctual lights
    /// ([`DirectPass::with_adaptive_shadows`]).
    shadows: Option<Buffer>,
    /// The specular paths are pooled over the neighbourhood ([`DirectPass::with_specular_pool`]).
    specular_pool: bool,
}

impl std::fmt::Debug for DirectPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DirectPass").finish_non_exhaustive()
    }
}

impl DirectPass {
    /// Compiles the pass for `scene`'s plan; with [`SkyLight::Records`] it leaves a constant
    /// environment out (the records bring it), with [`EmitterLight::Analytic`] it takes the
    /// emitters' unshadowed light in closed form where the plan allows.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        sky: SkyLight,
        emitters: EmitterLight,
    ) -> Result<DirectPass> {
        Self::with_radiance(ctx, shaders, scene, sky, emitters, false)
    }

    /// As [`DirectPass::new`]; with `radiance` the pass can leave glossy lobes' indirect light to
    /// the radiance records (`HAS_RADIANCE_CACHE`), writing each such pixel's glossy world
    /// weights ([`DirectPass::record_glossy`]).
    pub fn with_radiance(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        sky: SkyLight,
        emitters: EmitterLight,
        radiance: bool,
    ) -> Result<DirectPass> {
        let mut defines = scene.defines();
        defines.extend(sky.define(scene.has_constant_environment()));
        let analytic = emitters.define(scene.plan().analytic_emitters);
        defines.extend(analytic);
        if radiance {
            defines.push(("HAS_RADIANCE_CACHE", "1"));
        }
        let spirv = shaders.compile("passes/direct.comp", &defines)?;
        let pipeline = Pipeline::compute(
            ctx,
            "direct",
            &spirv,
            &b::layout(),
            std::mem::size_of::<DirectPush>() as u32,
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
        let placeholder = Buffer::new(
            ctx,
            &BufferDesc {
                name: "direct.placeholder",
                size: 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
                alignment: 0,
            },
        )?;
        Ok(DirectPass {
            pipeline,
            rays,
            placeholder,
            analytic: analytic.is_some(),
            punctual: scene.plan().has_punctual_lights(),
            shadows: None,
            specular_pool: true,
        })
    }

    /// Whether a pixel's specular lobe takes its indirect light from its own paths alone
    /// (`false`) or from those of the pixels of its 3×3 neighbourhood (within its 8×8 workgroup)
    /// whose lobes overlap its own (`true`, the default; [`crate::SpecularPaths`]): each
    /// neighbour's paths, weighed by this pixel's BRDF over the neighbour's density, are an
    /// unbiased estimate of this pixel's integral but for the radiance being seen from a point a
    /// pixel away (docs/materials.md §10).
    pub fn with_specular_pool(mut self, pool: bool) -> DirectPass {
        self.specular_pool = pool;
        self
    }

    /// Makes a pass whose emitters' light is in closed form, or whose scene has punctual
    /// lights, spend its shadow rays where they are needed ([`crate::EmitterShadows::Adaptive`]),
    /// for images of `pixels` pixels (12 bytes each): sub-frame 0 casts every pixel's rays (a
    /// quarter of the samples toward the emitters, one per punctual light) and stores what its
    /// 3×3 neighbourhood saw of the emitters (lit, hidden, or a penumbra, dilated by the
    /// neighbourhood), what it saw of each punctual light, whether its neighbours' samples lay on
    /// its surface, and its sample's distance; later sub-frames cast no ray where every 3×3
    /// neighbour, on the pixel's surface, saw the same as the pixel and the sample lies on the
    /// surface of the pixel's first, one toward the emitters at other
    /// lit and hidden pixels, and mark the penumbrae their rays find (docs/cache-frame.md
    /// §8.2). Other passes are returned as they are, and so is every pass for `pixels` `None`
    /// (every ray always).
    pub fn with_adaptive_shadows(
        mut self,
        ctx: &Context,
        pixels: Option<u32>,
    ) -> Result<DirectPass> {
        if let (true, Some(pixels)) = (self.analytic || self.punctual, pixels) {
            self.shadows = Some(Buffer::new(
                ctx,
                &BufferDesc {
                    name: "direct.shadows",
                    size: u64::from(pixels.max(1)) * 12,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                    alignment: 0,
                },
            )?);
        }
        Ok(self)
    }

    /// Records `samples` estimates per pixel into the G-buffer's direct image for sub-frame
    /// `sub_frame` of the frame's `seed`: the pixel's low-discrepancy sequences continue from
    /// one sub-frame to the next (sub-frame k takes their samples `k × count ..`).
    pub fn record(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        samples: u32,
        sub_frame: u32,
        seed: u32,
    ) -> Result<()> {
        self.record_glossy(rec, scene, gbuffer, samples, sub_frame, seed, None)
    }

    /// As [`DirectPass::record`]; with `glossy` (a pass built with radiance), pixels whose lobe
    /// is rough enough leave their specular indirect light to the radiance records and write
    /// their world weights into `glossy.weights`.
    #[allow(clippy::too_many_arguments)]
    pub fn record_glossy(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        samples: u32,
        sub_frame: u32,
        seed: u32,
        glossy: Option<&GlossySplatPass>,
    ) -> Result<()> {
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        rec.barrier(Access::TRANSFER_WRITE, Access::COMPUTE_READ_WRITE);
        let mut bindings = scene.bindings();
        bindings.extend(gbuffer.bindings());
        bindings.push((b::RAY_COUNT, Resource::Buffer(&self.rays)));
        let (weights, table) = glossy.map_or((&self.placeholder, &self.placeholder), |g| {
            (&g.weights, &g.table)
        });
        bindings.push((b::GLOSSY_WEIGHTS, Resource::Buffer(weights)));
        bindings.push((b::GLOSSY_TABLE, Resource::Buffer(table)));
        let (w, h) = (gbuffer.width, gbuffer.height);
        let shadows = self.shadows.as_ref();
        if let Some(buffer) = shadows {
            if buffer.size() < u64::from(w) * u64::from(h) * 8 {
                return Err(Error::Invalid(format!(
                    "the direct pass's shadow marks hold {} pixels, the G-buffer has {w}x{h}",
                    buffer.size() / 8
                )));
            }
        }
        bindings.push((
            b::SHADOWS,
            Resource::Buffer(shadows.unwrap_or(&self.placeholder)),
        ));
        let push = DirectPush {
            samples: samples.max(1),
            seed,
            sub_frame,
            specular_paths: specular_paths(samples),
            radiance_cache: u32::from(glossy.is_some()),
            adaptive_shadows: u32::from(shadows.is_some()),
            specular_pool: u32::from(self.specular_pool),
            pad2: 0,
        };
        rec.pass("direct", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            let [x, y, z] = image_dispatch(w, h);
            rec.dispatch(x, y, z)
        })?;
        rec.barrier(Access::COMPUTE_WRITE, Access::ALL);
        Ok(())
    }

    /// Ray queries of the last submitted pass.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}
