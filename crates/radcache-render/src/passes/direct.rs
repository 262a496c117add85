//! Direct lighting of the cache's frame (`shaders/passes/direct.comp`): next-event estimation with
//! MIS per surface pixel, compiled with the plan's defines (only the scene's light sources; a
//! constant environment only where the sky does not go through the records, [`SkyLight`]).
//!
//! Made to composite ([`DirectCompositing`], `DIRECT_COMPOSITE`), the pass can also add
//! a sub-frame's samples to the frame's accumulators itself, against the centre samples of a
//! splat made once per frame ([`crate::passes::composite::CentreSamples::Match`]), instead of writing the direct
//! image for [`CompositePass`]: the composite's own pass would load the G-buffer and that image
//! again, which on lavapipe was half of its time (docs/cache-frame.md §6.5).

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::{direct as b, direct_composite as c, direct_composite_layout};
use crate::error::{Error, Result};
use crate::passes::composite::{CompositePass, WithCentres};
use crate::passes::gbuffer::GBuffer;
use crate::passes::splat::SplatPass;
use crate::passes::splat_glossy::GlossySplatPass;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;
use crate::technique::{EmitterLight, SkyLight, SpecularPaths};

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
        /// ([`DirectVariant::shadows`]; docs/cache-frame.md §8.2).
        pub adaptive_shadows: u32 => "uint",
        /// 1: a pixel's specular paths are pooled with those of its 3×3 neighbours whose lobes
        /// overlap its own ([`DirectVariant::specular_paths`]; docs/materials.md §10).
        pub specular_pool: u32 => "uint",
        /// 1: the samples go to the frame's accumulators against the stored centre samples
        /// instead of the direct image (a pass made to composite, [`DirectCompositing`]).
        pub composite: u32 => "uint",
        /// The sub-frame's jitter (read where `composite` is set).
        pub jitter: [f32; 2] => "vec2",
        /// Padding.
        pub pad3: u32 => "uint",
        /// Padding.
        pub pad4: u32 => "uint",
    }
}

/// Where a direct pass's light goes, fixed when the pass is made: the type parameter of
/// [`DirectVariant`] and [`DirectPass`], and the type of what [`DirectPass::record`] writes to
/// ([`DirectTarget::Outputs`]). [`DirectImage`]: the G-buffer's direct image;
/// [`DirectCompositing`]: the composite's accumulators ([`Composited`]). A pass is given only
/// the outputs its target takes: one made for the image cannot be handed the composite's
/// resources, nor one made to composite the bare image —
///
/// ```compile_fail,E0308
/// use radcache_render::passes::direct::{Composited, DirectInputs, DirectPass};
/// use radcache_vk::Recorder;
///
/// // A pass made for the direct image (`DirectPass<DirectImage>`) takes no composite.
/// fn shade(pass: &DirectPass, rec: &mut Recorder, inputs: &DirectInputs<'_>, to: &Composited<'_>) {
///     pass.record(rec, inputs, to).unwrap();
/// }
/// ```
///
/// — while the same call on a pass made to composite compiles:
///
/// ```
/// use radcache_render::passes::direct::{Composited, DirectCompositing, DirectInputs, DirectPass};
/// use radcache_vk::Recorder;
///
/// fn shade(
///     pass: &DirectPass<DirectCompositing>,
///     rec: &mut Recorder,
///     inputs: &DirectInputs<'_>,
///     to: &Composited<'_>,
/// ) {
///     pass.record(rec, inputs, to).unwrap();
/// }
/// ```
pub trait DirectTarget: sealed::Sealed + Copy + std::fmt::Debug + PartialEq + Eq + 'static {
    /// What one recording writes to.
    type Outputs<'a>: DirectOutputs<'a>;
    /// The compositing the pass is compiled for (`DIRECT_COMPOSITE`); `None`: the image.
    fn compositing(&self) -> Option<DirectCompositing>;
}

/// What [`DirectTarget::Outputs`] name: the composite's resources and the sub-frame a
/// recording composites, if any.
pub trait DirectOutputs<'a>: sealed::Sealed + Copy {
    /// The composite's resources (`None`: the direct image).
    fn composite(self) -> Option<Composited<'a>>;
}

impl<'a> DirectOutputs<'a> for DirectImage {
    fn composite(self) -> Option<Composited<'a>> {
        None
    }
}

impl<'a> DirectOutputs<'a> for Composited<'a> {
    fn composite(self) -> Option<Composited<'a>> {
        Some(self)
    }
}

mod sealed {
    /// Only this file's targets and outputs are [`super::DirectTarget`]s and
    /// [`super::DirectOutputs`].
    pub trait Sealed {}
    impl Sealed for super::DirectImage {}
    impl Sealed for super::DirectCompositing {}
    impl Sealed for super::Composited<'_> {}
}

/// The G-buffer's direct image: the target of a pass made without compositing, and its
/// outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DirectImage;

impl DirectTarget for DirectImage {
    type Outputs<'a> = DirectImage;

    fn compositing(&self) -> Option<DirectCompositing> {
        None
    }
}

impl DirectTarget for DirectCompositing {
    type Outputs<'a> = Composited<'a>;

    fn compositing(&self) -> Option<DirectCompositing> {
        Some(*self)
    }
}

/// Where a pass made to composite ([`DirectCompositing`]) records: beside the direct pass's own
/// resources, the composite's accumulators and centre samples and the splat's targets (and the
/// glossy splat's target, [`DirectInputs::glossy`]). With `sub_frame` the sub-frame's samples
/// go to the frame's accumulators against the centre samples stored by the composite pass at
/// sub-frame 0 ([`crate::passes::composite::CentreSamples::Match`]), as the composite pass would add them, and the
/// direct image is left as it is; without it the pass writes the direct image as any other.
#[derive(Clone, Copy, Debug)]
pub struct Composited<'a> {
    /// The accumulators and the centre samples.
    pub composite: &'a CompositePass<WithCentres>,
    /// The splat made at the centre samples.
    pub splat: &'a SplatPass,
    /// What this sub-frame composites.
    pub sub_frame: Option<CompositeSubFrame>,
}

/// A sub-frame composited by the direct pass (never one with the debug AOVs, whose
/// accumulators the pass does not bind): its jitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompositeSubFrame {
    /// The sub-frame's sample within its pixel, from the pixel's centre.
    pub jitter: [f32; 2],
}

/// What the direct pass is compiled for: its shader variant and its own buffers; `T`, where
/// its light goes ([`DirectTarget`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectVariant<T: DirectTarget = DirectImage> {
    /// With [`SkyLight::Records`] the pass leaves a constant environment out (the records bring
    /// it).
    pub sky: SkyLight,
    /// With [`EmitterLight::Analytic`] it takes the emitters' unshadowed light in closed form
    /// where the plan allows.
    pub emitters: EmitterLight,
    /// Glossy lobes may leave their indirect light to the radiance records
    /// (`HAS_RADIANCE_CACHE`), writing each such pixel's glossy world weights
    /// ([`DirectInputs::glossy`]).
    pub radiance: bool,
    /// Where its light goes: the direct image ([`DirectImage`]), or, made to composite
    /// ([`DirectCompositing`], `DIRECT_COMPOSITE`), every recording binds the composite's
    /// resources ([`Composited`]), and a sub-frame composited against the centre samples adds
    /// its samples to the frame's accumulators itself instead of writing the direct image.
    pub target: T,
    /// How many shadow rays the emitters and punctual lights cast after sub-frame 0.
    pub shadows: DirectShadows,
    /// Whose paths a pixel's specular lobe takes its indirect light from.
    pub specular_paths: SpecularPaths,
}

impl<T: DirectTarget> DirectVariant<T> {
    /// Whether the pass takes the emitters' light in closed form in a scene whose plan allows
    /// it (`analytic_allowed`).
    fn analytic(&self, analytic_allowed: bool) -> bool {
        self.emitters.define(analytic_allowed).is_some()
    }

    /// The same variant with its light going to `target`.
    pub fn to<U: DirectTarget>(self, target: U) -> DirectVariant<U> {
        let DirectVariant {
            sky,
            emitters,
            radiance,
            shadows,
            specular_paths,
            ..
        } = self;
        DirectVariant {
            sky,
            emitters,
            radiance,
            target,
            shadows,
            specular_paths,
        }
    }
}

impl DirectVariant {
    /// Writing the direct image, every shadow ray at every sub-frame, no radiance records, the
    /// specular paths pooled.
    pub fn new(sky: SkyLight, emitters: EmitterLight) -> DirectVariant {
        DirectVariant {
            sky,
            emitters,
            radiance: false,
            target: DirectImage,
            shadows: DirectShadows::Fixed,
            specular_paths: SpecularPaths::Pooled,
        }
    }
}

/// A direct pass made to composite ([`DirectVariant::target`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectCompositing {
    /// The composite pass sums the squares of the radiance too (`IC_AA_MOMENTS`, adaptive
    /// anti-aliasing).
    pub moments: bool,
}

/// How many shadow rays the direct pass casts after sub-frame 0 (docs/cache-frame.md §8.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectShadows {
    /// A quarter of the samples toward the emitters and one ray per punctual light, at every
    /// pixel and sub-frame.
    Fixed,
    /// Where they are needed, for images of `pixels` pixels
    /// ([`crate::technique::EmitterShadows::Adaptive`]; the pass's buffer holds what each
    /// pixel's neighbourhood saw at sub-frame 0).
    Adaptive {
        /// Pixels of the images the pass shades.
        pixels: u32,
    },
}

/// What one direct dispatch reads.
#[derive(Clone, Copy, Debug)]
pub struct DirectInputs<'a> {
    /// The scene.
    pub scene: &'a GpuScene,
    /// The sub-frame's samples.
    pub gbuffer: &'a GBuffer,
    /// Estimates per pixel.
    pub samples: u32,
    /// The sub-frame.
    pub sub_frame: u32,
    /// The frame's seed.
    pub seed: u32,
    /// The glossy splat whose weights rough lobes write (a pass made with radiance), where the
    /// frame has one.
    pub glossy: Option<&'a GlossySplatPass>,
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

/// The direct-lighting pipeline and its ray counter; `T`, where its light goes
/// ([`DirectTarget`]).
pub struct DirectPass<T: DirectTarget = DirectImage> {
    pipeline: Pipeline,
    rays: Buffer,
    /// Bound for the glossy weights and table when the pass has no glossy splat to write for.
    placeholder: Buffer,
    /// The emitters' light is taken in closed form (`HAS_ANALYTIC_EMITTERS`).
    analytic: bool,
    /// The scene has punctual lights (`HAS_LIGHTS`).
    punctual: bool,
    /// [`DirectPass::shadow_bytes`] a pixel: what its neighbourhood saw of the emitters in
    /// this frame's sub-frames so far, what sub-frame 0 saw of them and of the punctual lights,
    /// its sample's distance (and, with emitters in closed form, its normal and their unshadowed
    /// irradiance) ([`DirectVariant::shadows`]).
    shadows: Option<Buffer>,
    /// The specular paths are pooled over the neighbourhood ([`DirectVariant::specular_paths`]).
    specular_pool: bool,
    /// Where its light goes ([`DirectVariant::target`]).
    target: T,
    /// Made with radiance ([`DirectVariant::radiance`]): it may take a glossy splat.
    radiance: bool,
}

impl<T: DirectTarget> std::fmt::Debug for DirectPass<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DirectPass").finish_non_exhaustive()
    }
}

impl<T: DirectTarget> DirectPass<T> {
    /// The shader module the pass compiles for a scene with `features` and `variant`.
    pub(crate) fn modules(
        features: &SceneFeatures,
        variant: &DirectVariant<T>,
    ) -> Vec<ShaderModule> {
        let mut defines = features.defines();
        defines.extend(variant.sky.define(features.env_constant));
        defines.extend(variant.emitters.define(features.analytic_emitters));
        if variant.radiance {
            defines.push(("HAS_RADIANCE_CACHE", "1"));
        }
        if let Some(DirectCompositing { moments }) = variant.target.compositing() {
            defines.push(("DIRECT_COMPOSITE", "1"));
            if moments {
                defines.push(("IC_AA_MOMENTS", "1"));
            }
        }
        vec![ShaderModule::new("passes/direct.comp", defines)]
    }

    /// Compiles the pass for `scene`'s plan and `variant`.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        variant: &DirectVariant<T>,
    ) -> Result<DirectPass<T>> {
        let DirectVariant {
            target,
            shadows,
            specular_paths,
            ..
        } = *variant;
        let module = &Self::modules(&scene.features(), variant)[0];
        let spirv = module.compile(shaders)?;
        let layout = match target.compositing() {
            Some(_) => direct_composite_layout(),
            None => b::layout(),
        };
        let pipeline = Pipeline::compute(
            ctx,
            "direct",
            &spirv,
            &layout,
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
        let pass = DirectPass {
            pipeline,
            rays,
            placeholder,
            analytic: variant.analytic(scene.plan().analytic_emitters),
            punctual: scene.plan().has_punctual_lights(),
            shadows: None,
            specular_pool: specular_paths == SpecularPaths::Pooled,
            target,
            radiance: variant.radiance,
        };
        match shadows {
            DirectShadows::Adaptive { pixels } => pass.with_adaptive_shadows(ctx, pixels),
            DirectShadows::Fixed => Ok(pass),
        }
    }

    /// Gives a pass whose emitters' light is in closed form, or whose scene has punctual
    /// lights, spend its shadow rays where they are needed ([`crate::EmitterShadows::Adaptive`]),
    /// for images of `pixels` pixels ([`DirectPass::shadow_bytes`] each): sub-frame
    /// 0 casts every pixel's rays (a quarter of the samples toward the emitters, one per
    /// punctual light) and stores what its 3×3 neighbourhood saw of the emitters (lit, hidden,
    /// or a penumbra, dilated by the neighbourhood), what it saw of each punctual light, whether
    /// its neighbours' samples lay on its surface, its sample's distance and, with emitters in
    /// closed form, its normal and the emitters' unshadowed irradiance; later sub-frames cast no
    /// ray where every 3×3 neighbour, on the pixel's surface, saw the same as the pixel and the
    /// sample lies on the surface of the pixel's first, one toward the emitters at other lit and
    /// hidden pixels, mark the penumbrae their rays find, and take the stored irradiance where
    /// the sample lies on the first one's surface with its normal (docs/cache-frame.md §8.2).
    /// Other passes are returned as they are.
    fn with_adaptive_shadows(mut self, ctx: &Context, pixels: u32) -> Result<DirectPass<T>> {
        if self.analytic || self.punctual {
            self.shadows = Some(Buffer::new(
                ctx,
                &BufferDesc {
                    name: "direct.shadows",
                    size: u64::from(pixels.max(1)) * self.shadow_bytes(),
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                    alignment: 0,
                },
            )?);
        }
        Ok(self)
    }

    /// Bytes a pixel of the adaptive shadows' buffer: `SHADOW_WORDS` words of `direct.comp`,
    /// [`radcache_shared::consts::SHADOW_WORDS_ANALYTIC`] with emitters in closed form,
    /// [`radcache_shared::consts::SHADOW_WORDS_SAMPLED`] without.
    fn shadow_bytes(&self) -> u64 {
        use radcache_shared::consts::{SHADOW_WORDS_ANALYTIC, SHADOW_WORDS_SAMPLED};
        let words = if self.analytic {
            SHADOW_WORDS_ANALYTIC
        } else {
            SHADOW_WORDS_SAMPLED
        };
        4 * u64::from(words)
    }

    /// Records `inputs.samples` estimates per pixel for sub-frame `inputs.sub_frame` of the
    /// frame's `inputs.seed` (the pixel's low-discrepancy sequences continue from one sub-frame
    /// to the next: sub-frame k takes their samples `k × count ..`) into `outputs` (the direct
    /// image, or for a pass made to composite [`Composited`]). With `inputs.glossy` (a pass
    /// built with radiance), pixels whose lobe is rough enough leave their specular indirect
    /// light to the radiance records and write their world weights into `glossy.weights`.
    pub fn record(
        &self,
        rec: &mut Recorder,
        inputs: &DirectInputs<'_>,
        outputs: &T::Outputs<'_>,
    ) -> Result<()> {
        let DirectInputs {
            scene,
            gbuffer,
            samples,
            sub_frame,
            seed,
            glossy,
        } = *inputs;
        if glossy.is_some() && !self.radiance {
            // Its shader has no radiance records: the glossy weights would never be written.
            return Err(Error::Invalid(
                "the direct pass was made without radiance records: it takes no glossy splat"
                    .into(),
            ));
        }
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
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
        let per_pixel = self.shadow_bytes();
        if let Some(buffer) = shadows {
            if buffer.size() < u64::from(w) * u64::from(h) * per_pixel {
                return Err(Error::Invalid(format!(
                    "the direct pass's shadow marks hold {} pixels, the G-buffer has {w}x{h}",
                    buffer.size() / per_pixel
                )));
            }
        }
        bindings.push((
            b::SHADOWS,
            Resource::Buffer(shadows.unwrap_or(&self.placeholder)),
        ));
        let composite = outputs.composite();
        let sub_frame_composite = composite.and_then(|c| c.sub_frame);
        if let Some(targets) = composite {
            bindings.extend(composite_bindings(targets, glossy));
        }
        let push = DirectPush {
            samples: samples.max(1),
            seed,
            sub_frame,
            specular_paths: specular_paths(samples),
            radiance_cache: u32::from(glossy.is_some()),
            adaptive_shadows: u32::from(shadows.is_some()),
            specular_pool: u32::from(self.specular_pool),
            composite: u32::from(sub_frame_composite.is_some()),
            jitter: sub_frame_composite.map_or([0.0; 2], |s| s.jitter),
            pad3: 0,
            pad4: 0,
        };
        rec.pass("direct", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            let [x, y, z] = image_dispatch(w, h);
            rec.dispatch(x, y, z)
        })?;
        Ok(())
    }

    /// Where the pass's light goes ([`DirectVariant::target`]).
    pub fn target(&self) -> T {
        self.target
    }

    /// Ray queries of the last submitted pass.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}

/// The composite's resources at the bindings of the pass made to composite, with `glossy`'s
/// target where the frame has one.
fn composite_bindings<'a>(
    targets: Composited<'a>,
    glossy: Option<&'a GlossySplatPass>,
) -> Vec<(u32, Resource<'a>)> {
    let Composited {
        composite, splat, ..
    } = targets;
    // Without a glossy splat the target is not read; the splat's own stands in.
    let glossy_sum = glossy.map_or(&splat.sum, |g| &g.sum);
    let r = composite.resources();
    vec![
        (c::SPLAT_SUM, Resource::StorageImage(&splat.sum)),
        (c::ACCUM, Resource::Buffer(r.accum)),
        (c::NONFINITE, Resource::Buffer(r.nonfinite)),
        (c::EMISSION_ACCUM, Resource::Buffer(r.emission_accum)),
        (c::GLOSSY_SUM, Resource::StorageImage(glossy_sum)),
        (c::CENTRE, Resource::Buffer(r.centre)),
    ]
}
