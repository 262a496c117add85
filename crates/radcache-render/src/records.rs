//! Irradiance records (`shaders/passes/record.comp`, IC reference §3, §4, §6, §7, §16): one
//! workgroup per requested pixel, dispatched indirectly from the counters (the host never learns
//! the request count), M×N stratified gather rays each, the record formed as
//! `radcache_cache::compute_record` + `finalize_radius` do (the shader's header has the details).
//!
//! Bindings, after the scene's and the G-buffer's (`PASS_BASE + 0..5`), from
//! [`RECORD_BINDINGS_BASE`] (`B_GBUFFER_END` in GLSL):
//!
//! - `+0` requests: `uint[]` pixel indices `y·width + x`;
//! - `+1` `IcCounters`: request `i < min(counts.y, limits.y)` creates record `counts.z + i`; the
//!   indirect dispatch is read at [`DISPATCH_OFFSET`]; `limits.z`/`limits.w` count dropped
//!   requests and rejected records;
//! - `+2` `GpuRecord[]`;
//! - `+3` the ray count (`uint`, host-readable, [`RecordPass::rays`]);
//! - `+4` the optional sample dump, `vec4[]` of `(L_jk, r_jk)`
//!   ([`RecordPass::record_with_samples`]).
//!
//! Push constants (48 bytes): `M`, `N`, seed, level | sub-frame << 16 (u32), then `min_px`,
//! `max_px` (R⁻/R⁺ as validity radii in pixel footprints), the validity scale
//! (`IcParams::validity_scale`) and `r_eps` relative to the scene scale (f32), then the source
//! (0: pixel requests; 1: record indices to refresh in place, [`RecordPass::record_refresh`]).

use bytemuck::{Pod, Zeroable};
use radcache_cache::sampling::ircache_hash;
use radcache_cache::IcParams;
use radcache_vk::{
    vk, Access, BindingKind, BindingLayout, Buffer, BufferDesc, Context, ImageUse, MemoryLocation,
    Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::{with_scene, PASS_BASE};
use crate::error::{Error, Result};
use crate::gbuffer::{GBuffer, GBUFFER_BINDINGS};
use crate::gpu_scene::GpuScene;

/// The shader, relative to `shaders/`.
pub const SHADER: &str = "passes/record.comp";
/// First binding of the pass's own resources (`B_GBUFFER_END` in GLSL).
pub const RECORD_BINDINGS_BASE: u32 = PASS_BASE + GBUFFER_BINDINGS;
/// Most strata a record may have (the shader's shared-memory arrays).
pub const MAX_STRATA: u32 = 1728;
/// Distances at or below this fraction of the scene's size are invalid samples (self-hits).
pub const R_EPS_REL: f32 = 1.0e-5;
/// Byte offset of the `VkDispatchIndirectCommand` in `IcCounters`.
pub const DISPATCH_OFFSET: u64 = 16;

/// `info.w`: the irradiance was not storable (`irradiance_is_valid`); the record is rejected.
pub const RECORD_FLAG_INVALID_IRRADIANCE: u32 = 1;
/// `info.w`: the requested pixel has no surface; the record is rejected.
pub const RECORD_FLAG_NO_SURFACE: u32 = 2;
/// `info.w`: `R_orig < R⁻` (the radius was raised; the gradient is attenuated).
pub const RECORD_FLAG_CLAMPED_UP: u32 = 4;
/// `info.w`: `R_orig > R⁺` (the radius was lowered).
pub const RECORD_FLAG_CLAMPED_DOWN: u32 = 8;
/// `info.w`: some gather directions fell below the geometric surface and were mirrored into it.
pub const RECORD_FLAG_FOLDED: u32 = 16;
/// `info.w`'s flag bits; the bits above hold 1 + the record's mesh instance
/// ([`RECORD_INSTANCE_SHIFT`]; 0 for a rejected record).
pub const RECORD_FLAGS_MASK: u32 = 0xff;
/// Shift of `1 + instance` in `info.w`.
pub const RECORD_INSTANCE_SHIFT: u32 = 8;

/// Push constants of `record.comp` (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Push {
    m: u32,
    n: u32,
    seed: u32,
    /// Level in the low 16 bits, sub-frame in the high 16 bits.
    level_subframe: u32,
    min_px: f32,
    max_px: f32,
    v_scale: f32,
    r_eps_rel: f32,
    /// 0: requests are pixels (new records); 1: requests are record indices (refresh in place).
    source: u32,
    pad: [u32; 3],
}

/// The pass seed of the records created for sub-frame `sub_frame` of a frame rendered with
/// `seed` (`IcRenderer`); `record.comp` recomputes it from a record's stored sub-frame when it
/// refreshes the record, so a refresh draws the record's own directions and paths again.
pub fn creation_seed(seed: u32, sub_frame: u32) -> u32 {
    seed.wrapping_mul(0x9e37_79b9) ^ sub_frame
}

/// Seed of the jitter of the record created at `pixel_index` with the pass seed `seed`: stratum
/// `i` of that record is jittered by `radcache_cache::sampling::stratum_jitter(record_seed, i)`,
/// so the same pixel and seed always reproduce the same gather directions (§11.4).
pub fn record_seed(pixel_index: u32, seed: u32) -> u32 {
    ircache_hash(pixel_index ^ ircache_hash(seed))
}

/// The record pipeline, its parameters and its ray counter.
pub struct RecordPass {
    pipeline: Pipeline,
    rays: Buffer,
    no_samples: Buffer,
    params: IcParams,
}

impl std::fmt::Debug for RecordPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordPass")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

/// The storage buffers a record dispatch reads and writes.
struct Io<'a> {
    requests: &'a Buffer,
    counters: &'a Buffer,
    records: &'a Buffer,
    samples: &'a Buffer,
}

impl RecordPass {
    /// Compiles the pass for `scene`'s plan with the cache parameters `params` (strata, spacing
    /// limits and weight kind, which sets the validity scale of `R⁻`/`R⁺`).
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        params: &IcParams,
    ) -> Result<RecordPass> {
        let (m, n) = (params.strata_m, params.strata_n);
        if m < 1 || n < 3 || m.saturating_mul(n) > MAX_STRATA {
            return Err(Error::Invalid(format!(
                "{m}×{n} strata: M ≥ 1, N ≥ 3 and at most {MAX_STRATA} in all"
            )));
        }
        let spirv = shaders.compile(SHADER, &scene.defines())?;
        let mut pass = GBuffer::layout().to_vec();
        for i in 0..5 {
            pass.push(BindingLayout::new(
                RECORD_BINDINGS_BASE + i,
                BindingKind::StorageBuffer,
            ));
        }
        let pipeline = Pipeline::compute(
            ctx,
            "records",
            &spirv,
            &with_scene(&pass),
            std::mem::size_of::<Push>() as u32,
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
            params: *params,
        })
    }

    /// The parameters the pass was built with.
    pub fn params(&self) -> &IcParams {
        &self.params
    }

    /// Records computing the pending batch in a pass named `records`: request `i` of `requests`
    /// (`i < min(counts.y, limits.y)` of `counters`) becomes record `counts.z + i` of `records`;
    /// one workgroup per request, dispatched from `counters`' indirect arguments (which must be
    /// visible to indirect reads). `level` and `sub_frame` are stored in the record's `info`;
    /// `seed` selects the jitter ([`record_seed`]).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        requests: &Buffer,
        counters: &Buffer,
        records: &Buffer,
        level: u32,
        sub_frame: u32,
        seed: u32,
    ) -> Result<()> {
        self.record_with_samples(
            rec,
            scene,
            gbuffer,
            requests,
            counters,
            records,
            level,
            sub_frame,
            seed,
            &self.no_samples,
        )
    }

    /// Records refreshing records in place (temporal caching, IC reference §11.2 step 6): request
    /// `i` of `requests` (`i < min(counts.y, limits.y)`, dispatched from `counters`) is a record
    /// index; that record is computed again at its own point, normal and footprint, with its own
    /// pixel, level and sub-frame, and the pass seed [`creation_seed`]`(frame_seed, sub-frame)`,
    /// so under unchanged lighting its irradiance and gradients come out bit for bit as they were
    /// (its radius comes back before neighbour clamping). Rejected records are left as they are.
    /// `gbuffer` is bound but not read.
    #[allow(clippy::too_many_arguments)]
    pub fn record_refresh(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        requests: &Buffer,
        counters: &Buffer,
        records: &Buffer,
        frame_seed: u32,
    ) -> Result<()> {
        let io = Io {
            requests,
            counters,
            records,
            samples: &self.no_samples,
        };
        self.record_io(rec, scene, gbuffer, &io, 0, 0, frame_seed, 1)
    }

    /// As [`RecordPass::record`], and request `i` also writes the samples of its strata,
    /// `(L_jk.rgb, r_jk)` as `[f32; 4]`, at `samples[i·M·N + j·N + k]`, when `samples` holds at
    /// least `(i + 1)·M·N` of them (for tests and diagnostics).
    #[allow(clippy::too_many_arguments)]
    pub fn record_with_samples(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        requests: &Buffer,
        counters: &Buffer,
        records: &Buffer,
        level: u32,
        sub_frame: u32,
        seed: u32,
        samples: &Buffer,
    ) -> Result<()> {
        let io = Io {
            requests,
            counters,
            records,
            samples,
        };
        self.record_io(rec, scene, gbuffer, &io, level, sub_frame, seed, 0)
    }

    #[allow(clippy::too_many_arguments)]
    fn record_io(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        io: &Io<'_>,
        level: u32,
        sub_frame: u32,
        seed: u32,
        source: u32,
    ) -> Result<()> {
        if level > 0xffff || sub_frame > 0xffff {
            return Err(Error::Invalid(format!(
                "record level {level} / sub-frame {sub_frame}: both must fit 16 bits"
            )));
        }
        let p = &self.params;
        let push = Push {
            m: p.strata_m,
            n: p.strata_n,
            seed,
            level_subframe: level | (sub_frame << 16),
            min_px: p.min_spacing_px,
            max_px: p.max_spacing_px,
            v_scale: p.validity_scale(),
            r_eps_rel: R_EPS_REL,
            source,
            pad: [0; 3],
        };
        for image in gbuffer.images() {
            rec.use_image(image, ImageUse::ComputeStorage);
        }
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        rec.barrier(Access::TRANSFER_WRITE, Access::COMPUTE_READ_WRITE);
        let base = RECORD_BINDINGS_BASE;
        let mut bindings = scene.bindings();
        bindings.extend(gbuffer.bindings());
        bindings.push((base, Resource::Buffer(io.requests)));
        bindings.push((base + 1, Resource::Buffer(io.counters)));
        bindings.push((base + 2, Resource::Buffer(io.records)));
        bindings.push((base + 3, Resource::Buffer(&self.rays)));
        bindings.push((base + 4, Resource::Buffer(io.samples)));
        rec.pass("records", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.dispatch_indirect(io.counters, DISPATCH_OFFSET);
        });
        rec.barrier(Access::COMPUTE_WRITE, Access::ALL.union(Access::HOST_READ));
        Ok(())
    }

    /// Ray queries (gather rays, shadow rays and path continuations) of the last submitted
    /// dispatch; read after its fence.
    pub fn rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }
}
