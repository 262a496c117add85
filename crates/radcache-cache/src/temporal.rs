//! Temporal radiance caching formulas (docs/temporal.md §3.3; docs/references.md §2 marks them as a
//! reconstruction of Gautron et al. 2007 [GBP07]). Pure formulas; record ageing and refresh
//! scheduling live in the renderer.
//!
//! For a record evaluated at frame `t_i` and again (same sample directions) at `t_i + 1`:
//! * temporal gradient (per channel, per frame): `∂E/∂t ≈ E(t_i+1) − E(t_i)`;
//! * change ratio on luminance: `τ = Y(E(t_i+1)) / Y(E(t_i))`;
//! * lifespan: the temporal weight `1/(|τ − 1|·(t − t_i))` stays above `1/a_t` for
//!   `Δt = a_t / |τ − 1|` frames, capped at `Δt_max`. Computed as `a_t·Y₀ / |Y₁ − Y₀|` so that no
//!   ratio is formed: `Y₀ = Y₁` (including both 0) gives `Δt_max`, `Y₀ = 0 < Y₁` gives 0;
//! * value within the lifespan: `E(t) = max(0, E(t_i) + (t − t_i)·∂E/∂t)`, then the spatial
//!   extrapolation of docs/irradiance-cache.md §6.1 ([`crate::extrapolate_irradiance`] with this
//!   value as `E_i`).
//!
//! [`moving_cover`] is this project's addition (docs/temporal.md §3.6; not from [GBP07]): the
//! lifespan comes from one frame's change and misses what comes later (an object that approaches a
//! record slowly at first), so a record also expires when the part of its hemisphere that moving
//! objects' bounding spheres cover has changed by more than `a_t` since its last evaluation.

use crate::luminance_rec709;
use glam::{Vec3, Vec4};

/// Temporal gradient per frame (docs/temporal.md §3.3): `E(t_i+1) − E(t_i)`.
pub fn temporal_gradient(e_t0: Vec3, e_t1: Vec3) -> Vec3 {
    e_t1 - e_t0
}

/// Lifespan in frames (docs/temporal.md §3.3): `min(a_t / |τ − 1|, Δt_max)` with `τ = Y(E₁)/Y(E₀)`,
/// in `[0, max(Δt_max, 0)]`. Negative luminances are treated as 0.
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

/// True while a record of age `age = t − t_i` frames is valid: `age <= lifespan`
/// (docs/temporal.md §3.5).
pub fn temporal_is_valid(age: f32, lifespan: f32) -> bool {
    age <= lifespan
}

/// Record value at age `age` frames (docs/temporal.md §3.4): `max(0, E(t_i) + age·∂E/∂t)` per
/// channel, `age` clamped to `>= 0`.
pub fn temporal_extrapolate(e_t0: Vec3, de_dt: Vec3, age: f32) -> Vec3 {
    (e_t0 + de_dt * age.max(0.0)).max(Vec3::ZERO)
}

/// The cosine-weighted fraction of the hemisphere over `(p, n)` (unit `n`) that the sphere
/// `(centre, radius)` covers: with `k = r/d = sin α` and `c = cos θ` of the direction to the
/// centre, exactly `k²·c` when the sphere is wholly above the horizon (`c ≥ k`: its projected
/// solid angle is `π·sin²α·cos θ`); across the horizon (`|c| < k`) the quadratic `k·(c + k)²/4`,
/// which meets `k²·c` with the same slope at `c = k` and falls to 0 at `c = −k`; 0 below; 1 with
/// `p` inside the sphere (0 for a sphere of radius 0); at most 1.
pub fn moving_cover(p: Vec3, n: Vec3, sphere: Vec4) -> f32 {
    let v = sphere.truncate() - p;
    let d = v.length();
    let r = sphere.w.max(0.0);
    if d <= r {
        return if r > 0.0 { 1.0 } else { 0.0 };
    }
    let k = r / d;
    let c = n.dot(v) / d;
    let f = if c >= k {
        k * k * c
    } else if c > -k {
        0.25 * k * (c + k) * (c + k)
    } else {
        0.0
    };
    f.min(1.0)
}
