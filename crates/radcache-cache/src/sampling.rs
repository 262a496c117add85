//! Hemisphere sampling for one record: orthonormal basis, stratified cosine-weighted directions and a
//! deterministic per-stratum jitter (docs/irradiance-cache.md §2.1, §2.2, §2.3, §7.3).
//!
//! Stratum `(j, k)` of an `M × N` grid covers `sin²θ ∈ [j/M, (j+1)/M)` and `φ ∈ [2πk/N, 2π(k+1)/N)`;
//! every stratum has projected solid angle `π/(MN)`, so one jittered direction per stratum is a
//! stratified sample of the pdf `cos θ / π` (§2.1):
//!
//! ```text
//! sin θ_j = sqrt((j + ξ)/M),  cos θ_j = sqrt(1 − (j + ξ)/M),  φ_k = 2π(k + ψ)/N
//! ω_jk = sin θ cos φ · t + sin θ sin φ · b + cos θ · n
//! ```
//!
//! Angles are wrapped to `[−π, π]` before `sin`/`cos` so that the GLSL twin stays inside the range
//! where Vulkan bounds the error of `sin`/`cos` (absolute 2^-11 on `[−π, π]`).

use core::f32::consts::{PI, TAU};
use glam::Vec3;

/// The course's strata for offline quality, `M × N = 16 × 48` (§2.2, §8.1; the default preset
/// takes 12 × 36, measured: params.rs).
pub const STRATA_DEFAULT: (u32, u32) = (16, 48);

/// Index of stratum `(j, k)` in the `M × N` sample arrays: `j * N + k` (wrapping, like GLSL `uint`).
pub fn stratum_index(j: u32, k: u32, n: u32) -> u32 {
    j.wrapping_mul(n).wrapping_add(k)
}

/// Unit normal, or `+Z` when `n` is zero, tiny, huge or not finite (§2.1 degenerate-frame guard).
pub fn normalize_or_z(n: Vec3) -> Vec3 {
    let len2 = n.dot(n);
    if len2 > 1.0e-30 && len2 < 1.0e30 {
        n / len2.sqrt()
    } else {
        Vec3::Z
    }
}

/// Right-handed orthonormal tangent frame `(t, b)` with `t × b = n̂`, `n̂ = normalize_or_z(n)`.
///
/// Branchless construction of Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin,
/// *Building an Orthonormal Basis, Revisited*, JCGT 6(1), 2017:
/// `s = sign(n_z)`, `a = −1/(s + n_z)`, `c = n_x n_y a`,
/// `t = (1 + s n_x² a, s c, −s n_x)`, `b = (c, s + n_y² a, −n_y)`.
/// `sign(0) = +1` (the GLSL twin cannot see the sign of −0), which is valid on both sides of `n_z = 0`.
pub fn basis_from_normal(n: Vec3) -> (Vec3, Vec3) {
    let n = normalize_or_z(n);
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let c = n.x * n.y * a;
    let t = Vec3::new(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    let b = Vec3::new(c, s + n.y * n.y * a, -n.y);
    (t, b)
}

/// Local direction `v` (components along `t`, `b`, `n`) to world space: `v.x t + v.y b + v.z n`.
pub fn frame_to_world(v: Vec3, t: Vec3, b: Vec3, n: Vec3) -> Vec3 {
    t * v.x + b * v.y + n * v.z
}

/// World direction to the local frame `(t, b, n)`: `(w·t, w·b, w·n)`.
pub fn world_to_frame(w: Vec3, t: Vec3, b: Vec3, n: Vec3) -> Vec3 {
    Vec3::new(w.dot(t), w.dot(b), w.dot(n))
}

/// Azimuth `2π·u` wrapped to `[−π, π]` (u in `[0, 1]`).
pub fn azimuth_from_unit(u: f32) -> f32 {
    if u > 0.5 {
        TAU * (u - 1.0)
    } else {
        TAU * u
    }
}

/// Centre azimuth of stratum column `k`: `φ_k = 2π(k + ½)/N`, wrapped to `[−π, π]` (§1.2).
pub fn stratum_phi_centre(k: u32, n: u32) -> f32 {
    azimuth_from_unit((k as f32 + 0.5) / n.max(1) as f32)
}

/// Start azimuth of stratum column `k`: `φ_k⁻ = 2πk/N`, wrapped to `[−π, π]` (§1.2).
pub fn stratum_phi_start(k: u32, n: u32) -> f32 {
    azimuth_from_unit(k as f32 / n.max(1) as f32)
}

/// Horizontal unit vector `u(φ) = (cos φ, sin φ, 0)` in the local frame (§1.2).
pub fn horizontal_u(phi: f32) -> Vec3 {
    Vec3::new(phi.cos(), phi.sin(), 0.0)
}

/// Horizontal unit vector `v(φ) = u(φ + π/2) = (−sin φ, cos φ, 0)` in the local frame (§1.2).
pub fn horizontal_v(phi: f32) -> Vec3 {
    Vec3::new(-phi.sin(), phi.cos(), 0.0)
}

/// `tan θ_j` at the polar centre of row `j` (`sin²θ_j = (j + ½)/M`), i.e. `1/sqrt(M/(j+½) − 1)`:
/// §3.1's (RADIANCE's, Mitsuba's) rotational-gradient weight, kept for comparison; the crate uses
/// [`stratum_tan_mean`]. `j` is clamped to `M − 1`, so the result is always finite (§3.1).
pub fn stratum_tan_centre(j: u32, m: u32) -> f32 {
    let m = m.max(1);
    let s2 = (j.min(m - 1) as f32 + 0.5) / m as f32;
    // 1 − s2 >= 0.5/M exactly; the max keeps it there when f32 rounds s2 to 1 (huge M).
    (s2 / (1.0 - s2).max(0.5 / m as f32)).sqrt()
}

/// Mean of `tan θ` over row `j` under the cosine-weighted pdf (`u = sin²θ` uniform in
/// `[j/M, (j+1)/M]`, `j` clamped to `M − 1`):
/// `M · ∫ sqrt(u/(1−u)) du = M · [θ − sinθ cosθ]_{θ_j⁻}^{θ_j⁺}`.
/// Finite everywhere (the horizon row gives `M·(π/2 − θ⁻ + sinθ⁻ cosθ⁻)`). The angle difference is
/// taken with `atan2` of the difference formulas to avoid cancelling two `asin`s.
/// Used by the rotational gradient instead of the centre value (see [`crate::record`]).
/// GPU note: Vulkan allows `atan` an error of up to 4096 ULP, and the pole row loses ~1.4 digits to
/// cancellation, so a pass wanting bit-for-bit agreement can upload these `M` values computed here.
pub fn stratum_tan_mean(j: u32, m: u32) -> f32 {
    let m = m.max(1);
    let j = j.min(m - 1);
    let mf = m as f32;
    let ua = j as f32 / mf;
    let ub = (j + 1) as f32 / mf;
    let (sa, ca) = (ua.sqrt(), (1.0 - ua).max(0.0).sqrt());
    let (sb, cb) = (ub.min(1.0).sqrt(), (1.0 - ub).max(0.0).sqrt());
    let dtheta = (sb * ca - sa * cb).atan2(cb * ca + sb * sa);
    (mf * (dtheta - (sb * cb - sa * ca))).max(0.0)
}

/// Local direction of stratum `(j, k)` with jitter `(ξ, ψ) ∈ [0, 1]²` (§2.1):
/// `(sinθ cosφ, sinθ sinφ, cosθ)`, `sin²θ = (j+ξ)/M`, `φ = 2π(k+ψ)/N`.
/// Jitters are clamped to `[0, 1]`, `M, N` to `>= 1`, and `sin²θ` to `[0, 1]`.
pub fn stratum_direction_local(j: u32, k: u32, m: u32, n: u32, xi: f32, psi: f32) -> Vec3 {
    let xi = xi.clamp(0.0, 1.0);
    let psi = psi.clamp(0.0, 1.0);
    let s2 = ((j as f32 + xi) / m.max(1) as f32).clamp(0.0, 1.0);
    let sin_t = s2.sqrt();
    let cos_t = (1.0 - s2).max(0.0).sqrt();
    let phi = azimuth_from_unit((k as f32 + psi) / n.max(1) as f32);
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// True when local direction `w` lies in stratum `(j, k)` of `M × N`, with an absolute tolerance
/// `tol` on `sin²θ` and on the azimuth fraction (test helper, also usable by the GPU test).
pub fn stratum_contains(w: Vec3, j: u32, k: u32, m: u32, n: u32, tol: f32) -> bool {
    let m = m.max(1) as f32;
    let n = n.max(1) as f32;
    let s2 = (w.x * w.x + w.y * w.y).min(1.0);
    let mut u = w.y.atan2(w.x) / TAU;
    if u < 0.0 {
        u += 1.0;
    }
    let in_theta = s2 >= j as f32 / m - tol && s2 <= (j as f32 + 1.0) / m + tol;
    let lo = k as f32 / n - tol;
    let hi = (k as f32 + 1.0) / n + tol;
    // The azimuth fraction may wrap around 0/1 within the tolerance; at the pole it is undefined.
    let in_phi = s2 <= tol
        || (u >= lo && u <= hi)
        || (u - 1.0 >= lo && u - 1.0 <= hi)
        || (u + 1.0 >= lo && u + 1.0 <= hi);
    w.z >= -tol && in_theta && in_phi
}

/// Integer hash for the deterministic per-record jitter (§2.3). PCG-style output permutation of
/// one LCG step (Jarzynski & Olano, *Hash Functions for GPU Rendering*, JCGT 9(3), 2020); identical
/// bit-for-bit in GLSL (`uint` arithmetic wraps).
pub fn ircache_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Top 24 bits of `h` as a float in `[0, 1 − 2^-24]` (exact on CPU and GPU).
pub fn unit_float_from_bits(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Jitter `(ξ, ψ)` of stratum `index` of the record with seed `seed` (e.g. the record id): the same
/// record always reproduces the same directions, so a refreshed record with unchanged lighting gives
/// the same value (§2.3; flicker control, docs/temporal.md §3.7).
pub fn stratum_jitter(seed: u32, index: u32) -> (f32, f32) {
    let h1 = ircache_hash(index.wrapping_add(ircache_hash(seed)));
    let h2 = ircache_hash(h1);
    (unit_float_from_bits(h1), unit_float_from_bits(h2))
}

/// Solid-angle helper for tests and docs: the projected solid angle of one stratum, `π/(MN)`
/// (§2.1).
pub fn stratum_projected_solid_angle(m: u32, n: u32) -> f32 {
    PI / (m.max(1) as f32 * n.max(1) as f32)
}
