//! First-order extrapolation of a record's irradiance to a lookup point
//! (docs/irradiance-cache.md §6.1, §6.2).
//!
//! ```text
//! Ẽ_c = E_c + (n_i × n)·∇_r E_c + (p − p_i)·∇_t E_c            (per channel c)
//! Ẽ_c ← clamp(Ẽ_c, 0, EXTRAPOLATION_MAX_FACTOR · max(E_c, 0))
//! ```
//!
//! `n_i × n` is the small-angle rotation vector taking `n_i` to `n` (right-handed frames, §3.1).
//! Guards (§6.2): the lower clamp at 0 is Mitsuba's per-channel `max(Ẽ, 0)`; the upper clamp at
//! `4·E_c` bounds over-extrapolation (RADIANCE ≥ 4.2 caps its multiplicative factor at 20 for the
//! same reason). Inside a record's zone the gradient limit (§4.2) already keeps the translational
//! term below `E_c` times the validity scale (`a` or `1/(2κ)`), and the normal cone keeps
//! `‖n_i × n‖ <= sin 10°/κ` for T&L, so legitimate values stay within `[0, 2·E_c]`; the factor 4
//! only catches noisy or rotational overshoots. A black channel stays black.

use crate::EXTRAPOLATION_MAX_FACTOR;
use glam::Vec3;

/// Extrapolated irradiance `Ẽ_i(p, n)` of a record (§6.1) with the clamps of §6.2.
/// `grad_r`, `grad_t` hold one world-space gradient per channel (R, G, B).
pub fn extrapolate_irradiance(
    e_i: Vec3,
    grad_r: &[Vec3; 3],
    grad_t: &[Vec3; 3],
    p: Vec3,
    n: Vec3,
    p_i: Vec3,
    n_i: Vec3,
) -> Vec3 {
    let rot = n_i.cross(n);
    let dp = p - p_i;
    let raw = e_i
        + Vec3::new(
            rot.dot(grad_r[0]) + dp.dot(grad_t[0]),
            rot.dot(grad_r[1]) + dp.dot(grad_t[1]),
            rot.dot(grad_r[2]) + dp.dot(grad_t[2]),
        );
    clamp_extrapolation(raw, e_i)
}

/// The §6.2 guard alone: per channel `clamp(x_c, 0, EXTRAPOLATION_MAX_FACTOR · max(e_c, 0))`.
pub fn clamp_extrapolation(x: Vec3, e: Vec3) -> Vec3 {
    let hi = e.max(Vec3::ZERO) * EXTRAPOLATION_MAX_FACTOR;
    x.max(Vec3::ZERO).min(hi)
}
