//! Composite of the cache's sub-frames (`shaders/passes/composite.comp`): direct + albedo/π × the
//! normalised splat sum on surfaces, the environment along the jittered camera ray elsewhere,
//! accumulated over jittered sub-frames into a float buffer whose mean is the image; the
//! G-buffer's emission goes to its own accumulator, which the emission pass turns into the
//! box-filtered emission it adds to the image.
//!
//! Bindings: the scene (0–15), the G-buffer (16–21), then from 22: the splat sum (Σw·Ẽ, Σw), the
//! frame accumulator, the non-finite counter, the emission accumulator (read by
//! [`crate::passes::emission::EmissionPass`], which adds the box-filtered emission), the debug accumulator and the
//! splat record count, and with adaptive anti-aliasing the accumulator of squares
//! (`IC_AA_MOMENTS`, [`CompositePass::read_moments`]), and the pixels' centre samples
//! ([`CentreSamples`]: splatting once per frame). A non-finite value is replaced by 0 and
//! counted.

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::composite as b;
use crate::error::Result;
use crate::passes::gbuffer::GBuffer;
use crate::passes::splat::SplatPass;
use crate::passes::splat_glossy::GlossySplatPass;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`CompositePush` in GLSL).
    pub struct CompositePush {
        /// Jitter.
        pub jitter: [f32; 2] => "vec2",
        /// Debug.
        pub debug: u32 => "uint",
        /// 1: add the glossy splat's target (pass built with radiance; docs/radiance-caching.md
        /// §6.2).
        pub glossy: u32 => "uint",
        /// [`CentreSamples`] as a number: 0 off, 1 store, 2 match.
        pub centre: u32 => "uint",
        /// Padding.
        pub pad0: u32 => "uint",
    }
}

/// What a sub-frame's composite does with the pixels' centre samples when the records are
/// splatted once per frame ([`crate::SplatMode::Once`], docs/cache-frame.md §6.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CentreSamples {
    /// The splat was made at this sub-frame's own samples: each pixel reads its own.
    Own,
    /// As `Own`, and the samples are stored as the frame's centre samples (the sub-frame at
    /// the pixel centres, which the splat used).
    Store,
    /// The splat was made at the stored centre samples: each sample interpolates the splat
    /// bilinearly between the four nearest centres that match it (where none does, that of
    /// the closest centre of its 3×3 neighbourhood).
    Match,
}

/// Whether a composite pass keeps the frame's centre samples, fixed when it is made: the type
/// parameter of [`CompositeVariant`], [`CompositePass`] and [`CompositeInputs`], whose
/// [`CompositeInputs::centre`] is [`Centres::Samples`]. [`OwnSamples`]: each sub-frame's splat
/// is its own, and the pass holds no centre samples; [`WithCentres`] (splatting once per frame):
/// it stores them at sub-frame 0 and matches the later sub-frames against them
/// ([`CentreSamples`]). A pass made without them cannot be asked to store or match —
///
/// ```compile_fail,E0308
/// use radcache_render::passes::composite::{CentreSamples, CompositeInputs};
///
/// // `CompositeInputs<'_>` (for `CompositePass<OwnSamples>`) takes `OwnSamples` only.
/// fn matching(inputs: CompositeInputs<'_>) -> CompositeInputs<'_> {
///     CompositeInputs { centre: CentreSamples::Match, ..inputs }
/// }
/// ```
///
/// — while inputs for a pass that keeps them can:
///
/// ```
/// use radcache_render::passes::composite::{CentreSamples, CompositeInputs, WithCentres};
///
/// fn matching(inputs: CompositeInputs<'_, WithCentres>) -> CompositeInputs<'_, WithCentres> {
///     CompositeInputs { centre: CentreSamples::Match, ..inputs }
/// }
/// ```
pub trait Centres: sealed::Sealed + Copy + std::fmt::Debug + PartialEq + Eq {
    /// Whose samples a sub-frame's splat holds, as the pass's inputs name them.
    type Samples: Copy + std::fmt::Debug + PartialEq + Eq;
    /// The pass keeps centre samples (allocates their buffer).
    const KEPT: bool;
    /// `samples` as the shader's choice.
    fn samples(samples: Self::Samples) -> CentreSamples;
}

mod sealed {
    /// Only this file's choices are [`super::Centres`].
    pub trait Sealed {}
    impl Sealed for super::OwnSamples {}
    impl Sealed for super::WithCentres {}
}

/// Each sub-frame's splat was made at its own samples ([`CentreSamples::Own`]): a pass that
/// keeps no centre samples, and the only samples its inputs name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OwnSamples;

impl Centres for OwnSamples {
    type Samples = OwnSamples;
    const KEPT: bool = false;

    fn samples(_: OwnSamples) -> CentreSamples {
        CentreSamples::Own
    }
}

/// A pass that keeps the frame's centre samples (splatting once per frame): its inputs name
/// any [`CentreSamples`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WithCentres;

impl Centres for WithCentres {
    type Samples = CentreSamples;
    const KEPT: bool = true;

    fn samples(samples: CentreSamples) -> CentreSamples {
        samples
    }
}

/// Bytes a pixel of the centre samples (two vec4: position and surface flag, normal and
/// footprint).
const CENTRE_BYTES: u64 = 32;

/// The buffers of a [`CompositePass`] that a direct pass made to composite binds
/// ([`crate::passes::direct::Composited`]).
pub(crate) struct CompositeResources<'a> {
    pub accum: &'a Buffer,
    pub nonfinite: &'a Buffer,
    pub emission_accum: &'a Buffer,
    pub centre: &'a Buffer,
}

/// The composite pipeline and the frame accumulator; `C`, whether it keeps centre samples
/// ([`Centres`]).
pub struct CompositePass<C: Centres = OwnSamples> {
    pipeline: Pipeline,
    pub(crate) accum: Buffer,
    pub(crate) emission_accum: Buffer,
    debug_accum: Buffer,
    /// With moments the accumulator holds a second vec4 array after the first: Σ radiance²
    /// per pixel.
    moments: bool,
    /// Made with radiance ([`CompositeVariant::radiance`]): it may add a glossy splat's target.
    radiance: bool,
    /// The centre samples (32 bytes a pixel when the pass keeps them, [`Centres::KEPT`]; one
    /// vec4 otherwise).
    centre: Buffer,
    /// Non-finite values dropped, then samples no centre matched (two `uint`s).
    nonfinite: Buffer,
    width: u32,
    height: u32,
    centres: std::marker::PhantomData<C>,
}

impl<C: Centres> std::fmt::Debug for CompositePass<C> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompositePass")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

/// What the composite pass is compiled for: its accumulators' size and shader variant; `C`,
/// whether it keeps centre samples ([`Centres`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompositeVariant<C: Centres = OwnSamples> {
    /// Accumulator width in pixels.
    pub width: u32,
    /// Accumulator height in pixels.
    pub height: u32,
    /// The pass can add the glossy splat's target (`HAS_RADIANCE_CACHE`,
    /// [`CompositeInputs::glossy`]).
    pub radiance: bool,
    /// It also sums the squares of the radiance (`IC_AA_MOMENTS`,
    /// [`CompositePass::read_moments`]).
    pub moments: bool,
    /// It can store and match centre samples ([`WithCentres`]) or not ([`OwnSamples`]).
    pub centres: C,
}

impl<C: Centres> CompositeVariant<C> {
    /// The same variant, keeping centre samples as `centres` says.
    pub fn with<D: Centres>(self, centres: D) -> CompositeVariant<D> {
        let CompositeVariant {
            width,
            height,
            radiance,
            moments,
            ..
        } = self;
        CompositeVariant {
            width,
            height,
            radiance,
            moments,
            centres,
        }
    }
}

impl CompositeVariant {
    /// A `width × height` accumulator of the sub-frames' own samples: no glossy target, no
    /// moments, no centre samples.
    pub fn new(width: u32, height: u32) -> CompositeVariant {
        CompositeVariant {
            width,
            height,
            radiance: false,
            moments: false,
            centres: OwnSamples,
        }
    }
}

/// What a composite recording does.
#[derive(Debug, Clone, Copy)]
pub enum CompositeJob<'a, C: Centres = OwnSamples> {
    /// Zero the accumulators and the non-finite counter (the start of a frame).
    Clear,
    /// Add the sub-frame rendered with the inputs' jitter to the accumulator: with
    /// `glossy`, the glossy target's `rgb/a` where its weight is positive; `centre` says whose
    /// samples the splat targets hold.
    Add(&'a CompositeInputs<'a, C>),
}

/// What one composite dispatch reads: the G-buffer's samples, the splat's targets, and the
/// sub-frame's parameters.
#[derive(Debug, Clone, Copy)]
pub struct CompositeInputs<'a, C: Centres = OwnSamples> {
    /// The scene.
    pub scene: &'a GpuScene,
    /// The sub-frame's samples and direct light.
    pub gbuffer: &'a GBuffer,
    /// The splat's targets (Σw·Ẽ, Σw, and the records per pixel for the debug AOVs).
    pub splat: &'a SplatPass,
    /// The glossy splat, where the frame has one.
    pub glossy: Option<&'a GlossySplatPass>,
    /// The sub-frame's jitter.
    pub jitter: [f32; 2],
    /// Whose samples the splat targets hold (for a pass without centre samples, its own:
    /// [`OwnSamples`]).
    pub centre: C::Samples,
    /// Also accumulate the debug AOVs.
    pub debug: bool,
}

impl<'a, C: Centres> CompositeInputs<'a, C> {
    /// The same inputs for a pass that keeps centre samples as `D` says, whose splat holds
    /// `centre`'s.
    pub fn at<D: Centres>(self, centre: D::Samples) -> CompositeInputs<'a, D> {
        let CompositeInputs {
            scene,
            gbuffer,
            splat,
            glossy,
            jitter,
            debug,
            ..
        } = self;
        CompositeInputs {
            scene,
            gbuffer,
            splat,
            glossy,
            jitter,
            centre,
            debug,
        }
    }
}

impl<'a> CompositeInputs<'a> {
    /// The sub-frame at `jitter` over its own splat, without glossy target or debug AOVs.
    pub fn own(
        scene: &'a GpuScene,
        gbuffer: &'a GBuffer,
        splat: &'a SplatPass,
        jitter: [f32; 2],
    ) -> CompositeInputs<'a> {
        CompositeInputs {
            scene,
            gbuffer,
            splat,
            glossy: None,
            jitter,
            centre: OwnSamples,
            debug: false,
        }
    }
}

impl<C: Centres> CompositePass<C> {
    /// The shader module the pass compiles for a scene with `features` and `variant`.
    pub(crate) fn modules(
        features: &SceneFeatures,
        variant: &CompositeVariant<C>,
    ) -> Vec<ShaderModule> {
        let mut defines = features.defines();
        if variant.radiance {
            defines.push(("HAS_RADIANCE_CACHE", "1"));
        }
        if variant.moments {
            defines.push(("IC_AA_MOMENTS", "1"));
        }
        vec![ShaderModule::new("passes/composite.comp", defines)]
    }

    /// Compiles the pass for `scene`'s plan and `variant`, and allocates its accumulators.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        variant: &CompositeVariant<C>,
    ) -> Result<CompositePass<C>> {
        let CompositeVariant {
            width,
            height,
            moments,
            ..
        } = *variant;
        let module = &Self::modules(&scene.features(), variant)[0];
        let spirv = module.compile(shaders)?;
        let pipeline = Pipeline::compute(
            ctx,
            "composite",
            &spirv,
            &b::layout(),
            std::mem::size_of::<CompositePush>() as u32,
        )?;
        let buffer = |name, size, location| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location,
                    alignment: 0,
                },
            )
        };
        let pixels = u64::from(width) * u64::from(height);
        Ok(CompositePass {
            pipeline,
            accum: buffer(
                "composite.accum",
                pixels * 16 * if moments { 2 } else { 1 },
                MemoryLocation::GpuOnly,
            )?,
            emission_accum: buffer("composite.emission", pixels * 16, MemoryLocation::GpuOnly)?,
            debug_accum: buffer("composite.debug", pixels * 32, MemoryLocation::GpuOnly)?,
            moments,
            radiance: variant.radiance,
            centre: buffer(
                "composite.centre",
                if C::KEPT { pixels * CENTRE_BYTES } else { 16 },
                MemoryLocation::GpuOnly,
            )?,
            nonfinite: buffer("composite.nonfinite", 16, MemoryLocation::GpuToCpu)?,
            width,
            height,
            centres: std::marker::PhantomData,
        })
    }

    /// Records `job`: zeroing the accumulators and the non-finite counter, or adding a
    /// sub-frame.
    pub fn record(&self, rec: &mut Recorder, job: CompositeJob<'_, C>) -> Result<()> {
        let inputs = match job {
            CompositeJob::Clear => {
                rec.fill_buffer(&self.accum, 0, vk::WHOLE_SIZE, 0);
                rec.fill_buffer(&self.emission_accum, 0, vk::WHOLE_SIZE, 0);
                rec.fill_buffer(&self.debug_accum, 0, vk::WHOLE_SIZE, 0);
                rec.fill_buffer(&self.nonfinite, 0, vk::WHOLE_SIZE, 0);
                return Ok(());
            }
            CompositeJob::Add(inputs) => inputs,
        };
        let CompositeInputs {
            scene,
            gbuffer,
            splat,
            glossy,
            jitter,
            centre,
            debug,
        } = *inputs;
        if glossy.is_some() && !self.radiance {
            return Err(crate::error::Error::Invalid(
                "the composite pass was made without radiance records: it takes no glossy splat"
                    .into(),
            ));
        }
        // Without a glossy splat the target is not read; the splat's own stands in.
        let glossy_sum = glossy.map_or(&splat.sum, |g| &g.sum);
        let mut bindings = scene.bindings();
        bindings.extend(gbuffer.bindings());
        bindings.extend([
            (b::SPLAT_SUM, Resource::StorageImage(&splat.sum)),
            (b::ACCUM, Resource::Buffer(&self.accum)),
            (b::NONFINITE, Resource::Buffer(&self.nonfinite)),
            (b::EMISSION_ACCUM, Resource::Buffer(&self.emission_accum)),
            (b::DEBUG_ACCUM, Resource::Buffer(&self.debug_accum)),
            (b::SPLAT_COUNT, Resource::StorageImage(&splat.count)),
            (b::GLOSSY_SUM, Resource::StorageImage(glossy_sum)),
            (b::CENTRE, Resource::Buffer(&self.centre)),
        ]);
        let push = CompositePush {
            jitter,
            debug: u32::from(debug),
            glossy: u32::from(glossy.is_some()),
            centre: match C::samples(centre) {
                CentreSamples::Own => 0,
                CentreSamples::Store => 1,
                CentreSamples::Match => 2,
            },
            pad0: 0,
        };
        let (w, h) = (self.width, self.height);
        rec.pass("composite", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            let [x, y, z] = image_dispatch(w, h);
            rec.dispatch(x, y, z)
        })?;
        Ok(())
    }

    /// The debug AOVs averaged over `sub_frames`: indirect radiance (RGB), Σw, records per pixel.
    pub fn read_debug(
        &self,
        ctx: &Context,
        sub_frames: u32,
    ) -> Result<(Vec<f32>, Vec<f32>, Vec<f32>)> {
        let n = (self.width * self.height) as usize;
        let raw: Vec<[f32; 4]> = ctx.read_buffer(&self.debug_accum, 2 * n)?;
        // Each pixel's own sub-frames (per-pixel adaptive anti-aliasing stops some early).
        let sums: Vec<[f32; 4]> = ctx.read_buffer(&self.accum, n)?;
        let mut indirect = Vec::with_capacity(3 * n);
        let mut weight = Vec::with_capacity(n);
        let mut count = Vec::with_capacity(n);
        for (px, s) in raw.chunks_exact(2).zip(&sums) {
            let k = if s[3] > 0.0 {
                s[3]
            } else {
                sub_frames.max(1) as f32
            };
            indirect.extend(px[0][..3].iter().map(|v| v / k));
            weight.push(px[0][3] / k);
            count.push(px[1][0] / k);
        }
        Ok((indirect, weight, count))
    }

    /// The buffers a direct pass made to composite binds.
    pub(crate) fn resources(&self) -> CompositeResources<'_> {
        CompositeResources {
            accum: &self.accum,
            nonfinite: &self.nonfinite,
            emission_accum: &self.emission_accum,
            centre: &self.centre,
        }
    }

    /// Width and height of the accumulator.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Each pixel's sums `(Σl rgb, n)` and `(Σl² rgb, ·)` over the sub-frames accumulated so
    /// far; `None` for a pass made without moments.
    #[allow(clippy::type_complexity)]
    pub fn read_moments(&self, ctx: &Context) -> Result<Option<(Vec<[f32; 4]>, Vec<[f32; 4]>)>> {
        if !self.moments {
            return Ok(None);
        }
        let n = (self.width * self.height) as usize;
        let mut sums: Vec<[f32; 4]> = ctx.read_buffer(&self.accum, 2 * n)?;
        let squares = sums.split_off(n);
        Ok(Some((sums, squares)))
    }

    /// Samples of the sub-frames composited with [`CentreSamples::Match`] that no centre of
    /// their neighbourhood matched, since the last clear.
    pub fn read_unmatched(&self) -> Result<u64> {
        Ok(u64::from(self.nonfinite.read::<u32>(2)?[1]))
    }

    /// The mean over the accumulated sub-frames, and the number of non-finite values dropped.
    pub fn read_mean(&self, ctx: &Context) -> Result<(Vec<[f32; 3]>, u64)> {
        let sums: Vec<[f32; 4]> =
            ctx.read_buffer(&self.accum, (self.width * self.height) as usize)?;
        let dropped = u64::from(self.nonfinite.read::<u32>(1)?[0]);
        let pixels = sums
            .iter()
            .map(|s| {
                let n = s[3].max(1.0);
                [s[0] / n, s[1] / n, s[2] / n]
            })
            .collect();
        Ok((pixels, dropped))
    }
}
