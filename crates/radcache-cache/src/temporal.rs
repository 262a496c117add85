//! Temporal radiance caching formulas (spec §11.2; the spec marks them as a reconstruction of
//! Gautron et al. 2007, tagged "recall"). Pure formulas; record ageing and refresh scheduling live
//! in the renderer.
//!
//! For a record evaluated at frame `t_i` and again (same sample directions) at `t_i + 1`:
//! * temporal gradient (per channel, per frame): `∂E/∂t ≈ E(t_i+1) − E(t_i)`;
//! * change ratio on luminance: `τ = Y(E(t_i+1)) / Y(E(t_i))`;
//! * lifespan: the temporal weight `1/(|τ − 1|·(t − t_i))` stays above `1/a_t` for
//!   `Δt = a_t / |τ − 1|` frames, capped at `Δt_max`. Computed as `a_t·Y₀ / |Y₁ − Y₀|` so that no
//!   ratio is formed: `Y₀ = Y₁` (including both 0) gives `Δt_max`, `Y₀ = 0 < Y₁` gives 0;
//! * value within the lifespan: `E(t) = max(0, E(t_i) + (t − t_i)·∂E/∂t)`, then the spatial
//!   extrapolation of §5.6 ([`crate::extrapolate_irradiance`] with this value as `E_i`).

use crate::luminance_rec709;
use glam::Vec3;

/// Temporal gradient per frame (§11.2 step 3): `E(t_i+1) − E(t_i)`.
pub fn temporal_gradient(e_t0: Vec3, e_t1: Vec3) -> Vec3 {
    e_t1 - e_t0
}

/// Lifespan in frames (§11.2 step 4): `min(a_t / |τ − 1|, Δt_max)` with `τ = Y(E₁)/Y(E₀)`, in
/// `[0, max(Δt_max, 0)]`. Negative luminances are treated as 0.
pub fn temporal_lifespan(e_t0: Vec3, e_t1: Vec3, a_t: f32, max_age: f32) -> f32 {
    let max_age = max_age.max(0.0);
    let y0 = luminance_rec709(e_t0).max(0.0);
    let y1 = luminance_rec709(e_t1).max(0.0);
    let dy = (y1 - y0).abs();
    let num = a_t.max(0.0) * y0;
    // num / dy >= max_age  <=>  num >= max_age * dy (also covers dy = 0).
    if num >= max_age * dy {
        max_age
    } else {
        num / dy
    }
}

/// True while a record of age `age = t − t_i` frames is valid: `age <= lifespan` (§11.2 step 6).
pub fn temporal_is_valid(age: f32, lifespan: f32) -> bool {
    age <= lifespan
}

/// Record value at age `age` frames (§11.2 step 5): `max(0, E(t_i) + age·∂E/∂t)` per channel,
/// `age` clamped to `>= 0`.
pub fn temporal_extrapolate(e_t0: Vec3, de_dt: Vec3, age: f32) -> Vec3 {
    (e_t0 + de_dt * age.max(0.0)).max(Vec3::ZERO)
}
