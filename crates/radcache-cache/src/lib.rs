//! `radcache-cache`: the CPU reference ("Rust twin") of every irradiance-cache formula used by the
//! GPU passes, plus the parameter set of the cache.
//!
//! Algorithm: `docs/irradiance-cache.md` (cited in this crate as a bare §N; other files of `docs/`
//! by name, e.g. `docs/temporal.md §3.3`). Each formula lives in one module:
//!
//! | Module | What | Section |
//! |---|---|---|
//! | [`sampling`] | orthonormal basis, stratified cosine-weighted directions, per-stratum jitter | §2.1, §2.2, §2.3, §7.3 |
//! | [`record`] | irradiance, harmonic-mean / minimum distance, rotational and translational gradients | §2.5, §2.6, §3.1, §3.2 |
//! | [`radiance`] | radiance records: SH projection of the strata, translational gradients of the coefficients | `docs/radiance-caching.md` §7 |
//! | [`radius`] | gradient limit, pixel footprint, screen-space clamp, gradient attenuation, neighbour clamping, `finalize_radius` | §4.2–§4.7 |
//! | [`weight`] | Ward and Tabellion–Lamorlette weights with in-front and normal tests, weight cap, splat radius | §5.1–§5.4, §5.6, §7.2 |
//! | [`extrapolate`] | gradient extrapolation with the negative/exploding guards | §6.1, §6.2 |
//! | [`temporal`] | temporal gradient, lifespan, temporal extrapolation | `docs/temporal.md` §3.3 |
//! | [`hessian`] | Hessian-based error control: edge Hessians of the sample mesh, eigenvalues, radius | §10 |
//! | [`params`] | [`IcParams`] and its `draft`/`default`/`high` presets | §2.2, §8.1 |
//! | [`cache_file`] | the cache file: header, records, validation (no formula, no GLSL twin) | — |
//!
//! **GLSL twin.** `shaders/common/ircache_math.glsl` implements the same functions under the same
//! (snake_case) names, argument order and guards, in f32. Every public function here takes plain
//! `f32`, `u32`, `Vec3`, `[Vec3; 3]` or [`WeightKind`] (`uint` in GLSL) arguments so that a GPU
//! test can evaluate both sides over a table of inputs; functions returning several values return
//! a tuple or small struct here and use `out` parameters, in field order, in GLSL. RGB gradients
//! are three world-space vectors, one per colour channel (`[Vec3; 3]` here, three `vec3` arguments
//! in GLSL). Only [`compute_record`], [`compute_hessian`], [`radiance::compute_radiance`] (slices; the GPU pass reduces the per-stratum terms in shared
//! memory) and the test helper `sampling::stratum_contains` have no twin. `tests/glsl.rs` checks
//! names, arities and constants and compiles the GLSL when `glslangValidator` is installed.
//!
//! **Conventions.**
//! * Local frames are right-handed: `t × b = n` (§1.2); directions in the local frame are
//!   `(sinθ cosφ, sinθ sinφ, cosθ)`.
//! * Stratum `(j, k)` of an `M × N` grid is stored at index `j * N + k` ([`sampling::stratum_index`]).
//! * Hit distances: a miss is any distance `>= IC_FAR` (e.g. `f32::INFINITY`); a distance `<= r_eps`
//!   (or NaN) marks an invalid sample (self-intersection). Raw distances returned by this crate use
//!   [`IC_FAR`] for "no geometry", never `inf`, so that the GPU side never divides by infinity (Vulkan
//!   only guarantees division precision for divisors below 2^126).
//! * Guards never produce NaN or Inf from finite inputs, `+inf` distances, zero vectors, antiparallel
//!   normals or zero radii (checked by the randomized sweep in `tests/sweep.rs`). NaN *inputs* are not
//!   supported on the GPU side (Vulkan does not guarantee NaN semantics).

pub mod cache_file;
pub mod extrapolate;
pub mod hessian;
pub mod params;
pub mod radiance;
pub mod radius;
pub mod record;
pub mod sampling;
pub mod temporal;
pub mod weight;

pub use extrapolate::extrapolate_irradiance;
pub use hessian::compute_hessian;
pub use params::{falloff_strata, ErrorControl, IcParams, Preset};
pub use radius::{finalize_radius, FinalRadius};
pub use record::{compute_record, RecordEstimate};
pub use weight::{record_weight, splat_radius, WeightKind, WeightRecord};

use glam::Vec3;

// The constants shared with GLSL are declared once, in `radcache_shared::consts`.
pub use radcache_shared::consts::{
    ELEVATION_MIN_SIN2, EXTRAPOLATION_MAX_FACTOR, HESSIAN_ERROR, HESSIAN_SERIES_TAU, IC_FAR,
    KAPPA_MIN, R_FLOOR, TL_NORMAL_SCALE, WARD_MIN_ERROR,
};

/// `min(max(x, lo), hi)` in GLSL's order. Unlike `f32::clamp` it never panics (`lo > hi` gives `hi`)
/// and maps a NaN `x` to `lo`.
#[allow(clippy::manual_clamp)]
pub(crate) fn clamp_lo_hi(x: f32, lo: f32, hi: f32) -> f32 {
    x.max(lo).min(hi)
}

/// Rec. 709 luminance of an RGB triple (used by the temporal lifespan, docs/temporal.md §3.3).
pub fn luminance_rec709(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
