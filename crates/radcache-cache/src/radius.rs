//! Post-processing of a record's radius `R` (docs/irradiance-cache.md §4.2–§4.7, §7.1).
//!
//! * Gradient limit (§4.2): `R ← min(R, min_c E_c / ‖∇_t E_c‖)` per colour channel (channels with a
//!   zero gradient do not limit).
//! * Pixel footprint (§4.3): `s = sqrt(‖∂p/∂x × ∂p/∂y‖)` from ray differentials, or the pinhole
//!   approximation `s ≈ (2 z tan(fov_y/2) / H) / sqrt(max(|n·v̂|, 0.1))`.
//! * Screen-space clamp (§4.3): `R ← clamp(R, R⁻, R⁺)` with `R⁻ = c_min·s / scale`,
//!   `R⁺ = c_max·s / scale`, where `c_min, c_max` are *validity radii in pixels* (§4.3; the
//!   default preset's are 4 and 20 px, §8.1) and `scale` maps `R` to the validity radius (`a` for
//!   Ward, `1/(2κ)` for Tabellion–Lamorlette; see [`crate::weight::validity_scale`]).
//! * Gradient attenuation (§4.4): `∇_t E ← ∇_t E · min(1, R_unclamped / R⁻)`. `R_unclamped` is the
//!   radius after the gradient limit and neighbour clamp (§4.4; Mitsuba uses the plain minimum hit
//!   distance instead, which also attenuates unclamped records — we only attenuate when the clamp
//!   actually raises `R`, as §4.4 states).
//! * Neighbour clamping (§4.5): `R_i ← min(R_i, R_j + ‖p_i − p_j‖)` on *unclamped* radii.
//! * Corners (§4.6): `R → 0` is harmless: every division uses `max(R, R_FLOOR)`, the clamp forces
//!   `R >= R⁻ > 0`, and the attenuation factor goes to 0 with `R` (large corner gradients are not
//!   extrapolated over the enlarged zone).
//! * [`finalize_radius`] runs §4.7 steps 1–5 in order.
//!
//! Raw radii may be `IC_FAR` ("no geometry"); inputs `>= IC_FAR` (including `+inf`) are treated as
//! `IC_FAR`.

use crate::{clamp_lo_hi, IC_FAR, R_FLOOR};
use glam::Vec3;

/// Radius sanitised to `[0, IC_FAR]` (negative → 0; `+inf` → `IC_FAR`).
pub fn sanitize_radius(r: f32) -> f32 {
    clamp_lo_hi(r, 0.0, IC_FAR)
}

/// Gradient limit (§4.2): `min(r, min_c max(E_c, 0) / ‖∇_t E_c‖)` over channels with a non-zero
/// gradient. Output in `[0, IC_FAR]`.
pub fn gradient_limit_radius(r: f32, e: Vec3, grad_t: &[Vec3; 3]) -> f32 {
    let mut out = sanitize_radius(r);
    for c in 0..3 {
        let g = grad_t[c].length();
        if g > 0.0 {
            out = out.min(e[c].max(0.0) / g);
        }
    }
    out
}

/// Neighbour clamp of one radius (§4.5): `min(r_i, r_j + d_ij)` on unclamped radii
/// (`d_ij = ‖p_i − p_j‖ >= 0`). Apply it both ways ([`neighbour_clamp_pair`]).
pub fn neighbour_clamp(r_i: f32, r_j: f32, d_ij: f32) -> f32 {
    sanitize_radius(r_i).min(sanitize_radius(r_j) + d_ij.max(0.0))
}

/// Symmetric neighbour clamp of two records (§4.5): returns the new `(R_i, R_j)`.
pub fn neighbour_clamp_pair(r_i: f32, p_i: Vec3, r_j: f32, p_j: Vec3) -> (f32, f32) {
    let d = (p_i - p_j).length();
    (neighbour_clamp(r_i, r_j, d), neighbour_clamp(r_j, r_i, d))
}

/// World-space size of one pixel at a point from its ray differentials (§4.3):
/// `sqrt(‖∂p/∂x × ∂p/∂y‖)`.
pub fn pixel_footprint_from_differentials(dpdx: Vec3, dpdy: Vec3) -> f32 {
    dpdx.cross(dpdy).length().sqrt()
}

/// Pinhole approximation of the pixel footprint (§4.3):
/// `(2 · depth · tan(fov_y/2) / height) / sqrt(max(|cos_view|, 0.1))`, where `cos_view = n·v̂`.
pub fn pixel_footprint(depth: f32, tan_half_fov_y: f32, image_height: f32, cos_view: f32) -> f32 {
    let s = 2.0 * depth.abs() * tan_half_fov_y.abs() / image_height.max(1.0);
    s / cos_view.abs().max(0.1).sqrt()
}

/// Clamp interval `(R⁻, R⁺)` of `R` from the footprint `s` and the validity-radius limits in pixels
/// (§4.3, §8.1): `R⁻ = min_px·s/scale`, `R⁺ = max_px·s/scale`, `scale` = validity radius / `R`.
/// Guarantees `R_FLOOR <= R⁻ <= R⁺ <= IC_FAR`.
pub fn radius_bounds(footprint: f32, min_px: f32, max_px: f32, validity_scale: f32) -> (f32, f32) {
    let scale = validity_scale.max(1.0e-6);
    let s = footprint.max(0.0);
    let lo = clamp_lo_hi(min_px.max(0.0) * s / scale, R_FLOOR, IC_FAR);
    let hi = clamp_lo_hi(max_px.max(0.0) * s / scale, lo, IC_FAR);
    (lo, hi)
}

/// `clamp(r, r_lo, r_hi)` with the guards of §7.1: `r_lo >= R_FLOOR`, `r_hi >= r_lo`, `<= IC_FAR`.
pub fn clamp_radius(r: f32, r_lo: f32, r_hi: f32) -> f32 {
    let lo = clamp_lo_hi(r_lo, R_FLOOR, IC_FAR);
    let hi = clamp_lo_hi(r_hi, lo, IC_FAR);
    clamp_lo_hi(sanitize_radius(r), lo, hi)
}

/// Translational-gradient attenuation factor (§4.4): `min(1, r_unclamped / r_lo)`, in `[0, 1]`.
pub fn gradient_attenuation(r_unclamped: f32, r_lo: f32) -> f32 {
    (sanitize_radius(r_unclamped) / clamp_lo_hi(r_lo, R_FLOOR, IC_FAR)).min(1.0)
}

/// Result of [`finalize_radius`] (the radius fields of §2.6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinalRadius {
    /// Unclamped radius after the gradient limit and neighbour clamp (`R_orig`, kept for later
    /// neighbour clamps), in `[0, IC_FAR]`.
    pub r_orig: f32,
    /// Radius used by the weight: `clamp(R_orig, R⁻, R⁺)`, in `[R_FLOOR, IC_FAR]`.
    pub r_used: f32,
    /// Sanitised `R⁻` (store it with the record to re-clamp after a neighbour shrinks it).
    pub r_lo: f32,
    /// Sanitised `R⁺`.
    pub r_hi: f32,
    /// Factor for the translational gradient (§4.4), in `[0, 1]`.
    pub grad_t_scale: f32,
}

/// §4.7 steps 1–5 for a new record, in order:
/// 1. gradient limit `R ← min(R, min_c E_c/‖∇_t E_c‖)`;
/// 2. neighbour clamp `R ← min(R, r_neighbour)` where `r_neighbour = min_j (R_j^orig + ‖p_i − p_j‖)`
///    over existing neighbours (`IC_FAR` or `+inf` when none; shrink the neighbours with
///    [`neighbour_clamp`] and re-clamp them with [`clamp_radius`] and their own stored bounds);
/// 3. bounds `R⁻, R⁺` (from [`radius_bounds`]), sanitised;
/// 4. gradient attenuation factor `min(1, R / R⁻)`;
/// 5. `R_orig = R`, `R_used = clamp(R, R⁻, R⁺)`.
///
/// `r` is the raw radius from the samples ([`crate::RecordEstimate::radius`]).
pub fn finalize_radius(
    r: f32,
    e: Vec3,
    grad_t: &[Vec3; 3],
    r_neighbour: f32,
    r_lo: f32,
    r_hi: f32,
) -> FinalRadius {
    let limited = gradient_limit_radius(r, e, grad_t);
    let r_orig = limited.min(sanitize_radius(r_neighbour));
    let lo = clamp_lo_hi(r_lo, R_FLOOR, IC_FAR);
    let hi = clamp_lo_hi(r_hi, lo, IC_FAR);
    FinalRadius {
        r_orig,
        r_used: clamp_radius(r_orig, lo, hi),
        r_lo: lo,
        r_hi: hi,
        grad_t_scale: gradient_attenuation(r_orig, lo),
    }
}
