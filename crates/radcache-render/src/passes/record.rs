//! Irradiance records (`shaders/passes/record.comp`, docs/cache-frame.md §4;
//! docs/irradiance-cache.md §2, §2.6, §3, §4, §7): one workgroup per requested pixel, dispatched
//! indirectly from the counters (the host never learns the request count), M×N stratified gather
//! rays each, the record formed as `radcache_cache::compute_record` + `finalize_radius` do (the
//! shader's header has the details).
//!
//! Bindings (`bindings::record`), after the scene's and the G-buffer's:
//!
//! - `REQUESTS`: `uint[]` pixel indices `y·width + x` (or record indices);
//! - `COUNTERS`: `IcCounters`: request `i < min(requested, request_capacity)` creates record
//!   `batch_first + i`; the indirect dispatch is read at [`DISPATCH_OFFSET`];
//!   `dropped_requests`/`rejected_records` count dropped requests and rejected records;
//! - `RECORDS`: `GpuRecord[]`;
//! - `RAY_COUNT`: the ray count (`uint`, host-readable, [`RecordPass::rays`]);
//! - `SAMPLES`: the optional sample dump, `vec4[]` of `(L_jk, r_jk)`
//!   ([`RecordOutputs::samples`]);
//! - `RADIANCE`: the records' radiance coefficients (`HAS_RADIANCE_CACHE`);
//! - `PATH_GRID`, `PATH_GRID_SUMS`: the frame's radiance grid (`PATH_GRID`, docs/cache-frame.md
//!   §4.1), the pass's own buffers ([`RecordVariant::path_grid`]).
//!
//! Push constants ([`RecordPush`], 56 bytes): `M`, `N`, seed, level | sub-frame << 16, then
//! `min_px`, `max_px` (R⁻/R⁺ as validity radii in pixel footprints), the validity scale
//! (`IcParams::validity_scale`) and `r_eps` relative to the scene scale, then the source
//! ([`RecordSource`]: pixel requests, or record indices evaluated again,
//! [`RecordJob::Refresh`]), the fine level and strata and whether they fall off below it,
//! and the dispatch's epoch in the radiance grid (0: not used).

use radcache_cache::{ErrorControl, IcParams};
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::record as b;
use crate::error::{Error, Result};
use crate::passes::gbuffer::GBuffer;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;
use crate::technique::{GlossySpacing, PathGridMode, SkyLight};
use radcache_shared::consts::RecordSource;
use radcache_shared::gpu::IcCounters;

mod path_grid;
mod push;
pub use path_grid::{GridJob, PathGrid};
pub use push::{creation_seed, record_seed, RecordPush};

/// The shader, relative to `shaders/`.
pub const SHADER: &str = "passes/record.comp";
/// Distances at or below this fraction of the scene's size are invalid samples (self-hits).
pub const R_EPS_REL: f32 = 1.0e-5;
/// Byte offset of the record pass's `VkDispatchIndirectCommand` in `IcCounters`.
pub const DISPATCH_OFFSET: u64 = std::mem::offset_of!(IcCounters, dispatch) as u64;

pub use radcache_shared::consts::{
    MAX_STRATA, RECORD_FLAGS_MASK, RECORD_FLAG_CLAMPED_DOWN, RECORD_FLAG_CLAMPED_UP,
    RECORD_FLAG_FOLDED, RECORD_FLAG_GLOSSY, RECORD_FLAG_INVALID_IRRADIANCE, RECORD_FLAG_NO_SURFACE,
    RECORD_INSTANCE_SHIFT,
};

/// Whether a record pass projects its strata onto radiance coefficients too, fixed when the
/// pass is made: the type parameter of [`RecordVariant`], [`RecordPass`] and [`RecordOutputs`],
/// whose [`RecordOutputs::radiance`] is [`RadianceBlocks::Blocks`]. [`NoRadiance`]: irradiance
/// records alone; [`WithRadiance`] (`HAS_RADIANCE_CACHE`, docs/radiance-caching.md §6.1): each
/// record writes its radiance block too, into the buffer the outputs must name. A pass made
/// without them cannot be handed a buffer of blocks to write —
///
/// ```compile_fail,E0308
/// use radcache_render::passes::record::RecordOutputs;
/// use radcache_vk::Buffer;
///
/// // `RecordOutputs<'_>` (for `RecordPass<NoRadiance>`) holds no radiance blocks.
/// fn with_blocks<'a>(records: &'a Buffer, blocks: &'a Buffer) -> RecordOutputs<'a> {
///     RecordOutputs { radiance: blocks, ..RecordOutputs::records(records) }
/// }
/// ```
///
/// — nor one made with them be recorded without:
///
/// ```compile_fail,E0308
/// use radcache_render::passes::record::{RecordOutputs, WithRadiance};
/// use radcache_vk::Buffer;
///
/// fn without_blocks(records: &Buffer) -> RecordOutputs<'_, WithRadiance> {
///     RecordOutputs::records(records)
/// }
/// ```
///
/// — while outputs for a pass made with them compile:
///
/// ```
/// use radcache_render::passes::record::{RecordOutputs, WithRadiance};
/// use radcache_vk::Buffer;
///
/// fn with_blocks<'a>(records: &'a Buffer, blocks: &'a Buffer) -> RecordOutputs<'a, WithRadiance> {
///     RecordOutputs::with_radiance(records, blocks)
/// }
/// ```
pub trait RadianceBlocks: sealed::Sealed + Copy + std::fmt::Debug + PartialEq + 'static {
    /// What a recording's outputs name for the blocks.
    type Blocks<'a>: BlocksBuffer<'a>;
    /// How records for glossy lobes are spaced (`None`: no radiance).
    fn glossy_spacing(&self) -> Option<GlossySpacing>;
}

/// What [`RadianceBlocks::Blocks`] names: the buffer of blocks, if any.
pub trait BlocksBuffer<'a>: sealed::Sealed + Copy + std::fmt::Debug {
    /// The buffer the blocks go to.
    fn buffer(self) -> Option<&'a Buffer>;
}

impl<'a> BlocksBuffer<'a> for NoRadiance {
    fn buffer(self) -> Option<&'a Buffer> {
        None
    }
}

impl<'a> BlocksBuffer<'a> for &'a Buffer {
    fn buffer(self) -> Option<&'a Buffer> {
        Some(self)
    }
}

mod sealed {
    /// Only this file's choices are [`super::RadianceBlocks`] and [`super::BlocksBuffer`].
    pub trait Sealed {}
    impl Sealed for super::NoRadiance {}
    impl Sealed for super::WithRadiance {}
    impl Sealed for &radcache_vk::Buffer {}
}

/// Irradiance records alone: a pass made without radiance coefficients, and what its outputs
/// name for the blocks (nothing).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoRadiance;

impl RadianceBlocks for NoRadiance {
    type Blocks<'a> = NoRadiance;

    fn glossy_spacing(&self) -> Option<GlossySpacing> {
        None
    }
}

/// Records with radiance coefficients (`HAS_RADIANCE_CACHE`): their outputs name the buffer
/// of blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WithRadiance {
    /// How records for glossy lobes are spaced (docs/radiance-caching.md §9:
    /// `GLOSSY_DENSITY` with [`GlossySpacing::Lobe`]).
    pub glossy_spacing: GlossySpacing,
}

impl RadianceBlocks for WithRadiance {
    type Blocks<'a> = &'a Buffer;

    fn glossy_spacing(&self) -> Option<GlossySpacing> {
        Some(self.glossy_spacing)
    }
}

/// The record pipeline, its parameters and its ray counter; `R`, whether it writes radiance
/// blocks ([`RadianceBlocks`]).
pub struct RecordPass<R: RadianceBlocks = NoRadiance> {
    pipeline: Pipeline,
    rays: Buffer,
    no_samples: Buffer,
    /// One vec4: too small for any record's radiance, so nothing is written there.
    no_radiance: Buffer,
    params: IcParams,
    radiance: std::marker::PhantomData<R>,
    grid: Option<PathGrid>,
}

impl<R: RadianceBlocks> std::fmt::Debug for RecordPass<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordPass")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

/// What the record pass is compiled for: its shader variant and its own buffers; `R`, whether
/// it writes radiance blocks ([`RadianceBlocks`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordVariant<R: RadianceBlocks = NoRadiance> {
    /// The cache parameters: strata, spacing limits and weight kind (which sets the validity
    /// scale of `R⁻`/`R⁺`); the Hessian error control is compiled in (`IC_HESSIAN`).
    pub params: IcParams,
    /// With [`SkyLight::Records`] a gather ray that escapes brings a constant environment's
    /// radiance.
    pub sky: SkyLight,
    /// With [`WithRadiance`] the records also project their strata onto the SH coefficients of
    /// the incoming radiance (`HAS_RADIANCE_CACHE`, docs/radiance-caching.md §6.1), written to
    /// [`RecordOutputs::radiance`].
    pub radiance: R,
    /// With [`PathGridMode::On`] and a scene whose plan allows it (`ScenePlan::path_grid`: some
    /// material is Lambertian) the gathers share a radiance grid (`PATH_GRID`,
    /// docs/cache-frame.md §4.1), which the frame readies at the start ([`RecordPass::grid`])
    /// of each frame.
    pub path_grid: PathGridMode,
}

impl RecordVariant {
    /// Irradiance records with `params`, the sky as `sky`: no radiance coefficients, no grid.
    pub fn new(params: IcParams, sky: SkyLight) -> RecordVariant {
        RecordVariant {
            params,
            sky,
            radiance: NoRadiance,
            path_grid: PathGridMode::Off,
        }
    }
}

impl<R: RadianceBlocks> RecordVariant<R> {
    /// The same variant, with radiance blocks as `radiance` says.
    pub fn with<S: RadianceBlocks>(self, radiance: S) -> RecordVariant<S> {
        let RecordVariant {
            params,
            sky,
            path_grid,
            ..
        } = self;
        RecordVariant {
            params,
            sky,
            radiance,
            path_grid,
        }
    }

    /// The gathers share a grid in a scene with `features`.
    fn grid(&self, features: &SceneFeatures) -> bool {
        self.path_grid == PathGridMode::On && features.path_grid
    }

    /// The shader's defines for a scene with `features`.
    fn defines(&self, features: &SceneFeatures) -> Vec<(&'static str, &'static str)> {
        let mut defines = features.defines();
        defines.extend(self.sky.define(features.env_constant));
        if self.params.error_control == ErrorControl::Hessian {
            defines.push(("IC_HESSIAN", "1"));
        }
        if features.closed_form_gathers {
            // The emitters' light at each gather vertex in closed form less a one-sample
            // estimate of its hidden part (`shaders/common/path.glsl`).
            defines.push(("PATH_CLOSED_FORM_EMITTERS", "1"));
        }
        if let Some(spacing) = self.radiance.glossy_spacing() {
            defines.push(("HAS_RADIANCE_CACHE", "1"));
            if spacing == GlossySpacing::Lobe {
                defines.push(("GLOSSY_DENSITY", "1"));
            }
        }
        if self.grid(features) {
            defines.push(("PATH_GRID", "1"));
        }
        defines
    }
}

/// What a record dispatch computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordJob {
    /// New records for the pending batch of pixel requests: request `i` of the requests
    /// (`i < min(requested, request_capacity)` of the counters) becomes record `batch_first + i`
    /// of the records. `level` and `sub_frame` are stored in the record's `info`; `seed`
    /// selects the jitter ([`record_seed`]).
    Create {
        /// The creation level.
        level: u32,
        /// The sub-frame.
        sub_frame: u32,
        /// The pass seed.
        seed: u32,
    },
    /// Records refreshed in place (temporal caching, docs/temporal.md §3.5): each request is a
    /// record index; that record is computed again at its own point, normal and footprint,
    /// with its own pixel, level and sub-frame, and the pass seed
    /// [`creation_seed`]`(frame_seed, sub-frame)`, so under unchanged lighting its irradiance
    /// and gradients come out bit for bit as they were (its radius comes back before neighbour
    /// clamping). Rejected records are left as they are; the G-buffer is bound but not read.
    Refresh {
        /// The frame's seed.
        frame_seed: u32,
    },
}

/// What a record dispatch reads.
#[derive(Debug, Clone, Copy)]
pub struct RecordInputs<'a> {
    /// The scene.
    pub scene: &'a GpuScene,
    /// The G-buffer the pixel requests point into.
    pub gbuffer: &'a GBuffer,
    /// `uint[]`: pixel indices `y·width + x` ([`RecordJob::Create`]) or record indices
    /// ([`RecordJob::Refresh`]).
    pub requests: &'a Buffer,
    /// `IcCounters`: the request count and the indirect dispatch (read at [`DISPATCH_OFFSET`],
    /// which must be visible to indirect reads); the pass counts dropped requests and rejected
    /// records there.
    pub counters: &'a Buffer,
    /// What the dispatch computes.
    pub job: RecordJob,
}

/// What a record dispatch writes.
#[derive(Debug, Clone, Copy)]
pub struct RecordOutputs<'a, R: RadianceBlocks = NoRadiance> {
    /// `GpuRecord[]`.
    pub records: &'a Buffer,
    /// The records' radiance blocks (a pass made [`WithRadiance`]): record `r` writes its
    /// `RECORD_RADIANCE_VEC4S` vec4 of coefficients and gradients at `radiance[r·48..]`.
    pub radiance: R::Blocks<'a>,
    /// For tests and diagnostics: request `i` also writes the samples of its strata,
    /// `(L_jk.rgb, r_jk)` as `[f32; 4]`, at `samples[i·M·N + j·N + k]`, when the buffer holds at
    /// least `(i + 1)·M·N` of them.
    pub samples: Option<&'a Buffer>,
}

impl<'a> RecordOutputs<'a> {
    /// Records alone: no radiance blocks, no sample dump.
    pub fn records(records: &'a Buffer) -> RecordOutputs<'a> {
        RecordOutputs {
            records,
            radiance: NoRadiance,
            samples: None,
        }
    }
}

impl<'a> RecordOutputs<'a, WithRadiance> {
    /// Records and their radiance blocks, no sample dump.
    pub fn with_radiance(records: &'a Buffer, radiance: &'a Buffer) -> Self {
        RecordOutputs {
            records,
            radiance,
            samples: None,
        }
    }
}

impl<R: RadianceBlocks> RecordPass<R> {
    /// The shader module the pass compiles for a scene with `features` and `variant`.
    pub(crate) fn modules(
        features: &SceneFeatures,
        variant: &RecordVariant<R>,
    ) -> Vec<ShaderModule> {
        vec![ShaderModule::new(SHADER, variant.defines(features))]
    }

    /// Compiles the pass for `scene`'s plan and `variant`.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        variant: &RecordVariant<R>,
    ) -> Result<RecordPass<R>> {
        let params = &variant.params;
        let strata = [
            (params.strata_m, params.strata_n),
            (params.fine_strata_m, params.fine_strata_n),
        ];
        for (m, n) in strata {
            if m < 1 || n < 3 || m.saturating_mul(n) > MAX_STRATA {
                return Err(Error::Invalid(format!(
                    "{m}×{n} strata: M ≥ 1, N ≥ 3 and at most {MAX_STRATA} in all"
                )));
            }
        }
        let features = scene.features();
        let grid = variant.grid(&features);
        let module = &Self::modules(&features, variant)[0];
        let spirv = module.compile(shaders)?;
        let pipeline = Pipeline::compute(
            ctx,
            "records",
            &spirv,
            &b::layout(),
            std::mem::size_of::<RecordPush>() as u32,
        )?;
        let buffer = |name, location| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size: 16,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location,
                    alignment: 0,
                },
            )
        };
        Ok(RecordPass {
            pipeline,
            rays: buffer("records.ray_count", MemoryLocation::GpuToCpu)?,
            // One vec4: too small for any request's strata, so nothing is dumped.
            no_samples: buffer("records.no_samples", MemoryLocation::GpuOnly)?,
            no_radiance: buffer("records.no_radiance", MemoryLocation::GpuOnly)?,
            params: *params,
            radiance: std::marker::PhantomData,
            grid: if grid {
                Some(PathGrid::new(ctx)?)
            } else {
                None
            },
        })
    }

    /// Whether the gathers share a radiance grid ([`RecordVariant::path_grid`]).
    pub fn path_grid(&self) -> bool {
        self.grid.is_some()
    }

    /// The radiance grid its gathers share ([`RecordVariant::path_grid`]), which the frame
    /// readies at its start ([`PathGrid::record`]); `None` without one.
    pub fn grid(&self) -> Option<&PathGrid> {
        self.grid.as_ref()
    }

    /// The parameters the pass was built with.
    pub fn params(&self) -> &IcParams {
        &self.params
    }

    /// Records the dispatch of `inputs.job` in a pass named `records`: one workgroup per
    /// request, dispatched from the counters' indirect arguments.
    pub fn record(
        &self,
        rec: &mut Recorder,
        inputs: &RecordInputs<'_>,
        outputs: &RecordOutputs<'_, R>,
    ) -> Result<()> {
        let (level, sub_frame, seed, source) = match inputs.job {
            RecordJob::Create {
                level,
                sub_frame,
                seed,
            } => (level, sub_frame, seed, RecordSource::Pixels),
            RecordJob::Refresh { frame_seed } => (0, 0, frame_seed, RecordSource::Records),
        };
        if level > 0xffff || sub_frame > 0xffff {
            return Err(Error::Invalid(format!(
                "record level {level} / sub-frame {sub_frame}: both must fit 16 bits"
            )));
        }
        let p = &self.params;
        let push = RecordPush {
            m: p.strata_m,
            n: p.strata_n,
            seed,
            level_subframe: level | (sub_frame << 16),
            min_px: p.min_spacing_px,
            max_px: p.max_spacing_px,
            v_scale: p.validity_scale(),
            r_eps_rel: R_EPS_REL,
            source: source as u32,
            fine_level: p.fine_level(),
            fine_m: p.fine_strata_m,
            fine_n: p.fine_strata_n,
            strata_falloff: u32::from(p.strata_falloff),
            // New records and refreshes alike (docs/temporal.md §3.8).
            grid_epoch: self.grid.as_ref().map_or(0, |g| g.next_epoch()),
        };
        let gbuffer = inputs.gbuffer;
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        let mut bindings = inputs.scene.bindings();
        bindings.extend(gbuffer.bindings());
        let grid = |f: fn(&PathGrid) -> &Buffer| self.grid.as_ref().map_or(&self.no_samples, f);
        bindings.extend([
            (b::REQUESTS, Resource::Buffer(inputs.requests)),
            (b::COUNTERS, Resource::Buffer(inputs.counters)),
            (b::RECORDS, Resource::Buffer(outputs.records)),
            (b::RAY_COUNT, Resource::Buffer(&self.rays)),
            (
                b::SAMPLES,
                Resource::Buffer(outputs.samples.unwrap_or(&self.no_samples)),
            ),
            (
                b::RADIANCE,
                Resource::Buffer(outputs.radiance.buffer().unwrap_or(&self.no_radiance)),
            ),
            (b::PATH_GRID, Resource::Buffer(grid(|g| &g.keys))),
            (b::PATH_GRID_SUMS, Resource::Buffer(grid(|g| &g.sums))),
        ]);
        rec.pass("records", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.dispatch_indirect(inputs.counters, DISPATCH_OFFSET);
        });
        Ok(())
    }

    /// Ray queries (gather rays, shadow rays and path continuations) of the last submitted
    /// dispatch; read after its fence.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}
