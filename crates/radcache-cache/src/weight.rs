//! Record weights, validity tests and splat radius (docs/irradiance-cache.md §5.1–§5.4,
//! §5.6, §7.2).
//!
//! Common tests (a weight is 0 when any fails):
//! * normal test (§5.4): `n·n_i > 0`; the normal error `sqrt(1 − n·n_i)` is evaluated as
//!   `‖n − n_i‖/√2` (equal for unit normals, no cancellation, never NaN — §5.1);
//! * in-front test (§5.4, RADIANCE ≥ 4.2 form): reject when `(p − p_i)·n_i < −tol`, with `tol` in
//!   world units (by default `0.5 · s(p)`, half a pixel footprint);
//! * out-of-plane error (§5.1): `|(p − p_i)·n_i| / R_i` is added to the positional error, so
//!   points far above/below the record's tangent plane (thin walls, table over floor) lose weight.
//!
//! Weights (`Δ = p − p_i`, `e_pos = (‖Δ‖ + |Δ·n_i|) / R_i`, `e_nrm = sqrt(1 − n·n_i)`):
//! * **Ward** (§5.2): `ε = e_pos + e_nrm`, valid iff `ε < a`, `w = 1 / max(ε, 10⁻³)` (cap 1000,
//!   §7.2: RADIANCE's cap; with at most a few tens of records per pixel `Σ w·E` stays far from the
//!   f32 range, and below the f16 range for `E < ~2`).
//! * **Tabellion–Lamorlette** (§5.3): `w = 1 − κ · max(2·e_pos, e_nrm / sqrt(1 − cos 10°))`, valid iff
//!   `w > 0`. Bounded by 1, so sums cannot overflow.
//!
//! **Default: Tabellion–Lamorlette** ([`WeightKind::default`]). Reasons: (1) the weight falls
//! continuously to 0 at the zone boundary, so a record entering or leaving a pixel's set does not pop
//! (Ward jumps from `1/a` to 0) — this matters for splat seams and for temporal stability
//! (docs/temporal.md §3.7); (2) it is bounded, so additive splat blending needs no cap and
//! half-float targets are safe; (3) its zone of influence is a hard ball `‖Δ‖ < R/(2κ)` with an
//! explicit normal cone (10°/κ), which sizes splats exactly (§5.6); (4) it is Mitsuba's choice
//! together with gradients and neighbour clamping, the combination this project follows (§5.5).
//! Ward stays selectable (its `a` is the classic accuracy knob; interpolation reproduces each
//! record exactly).
//!
//! Validity shapes (both kinds, `n = n_i`, point in the record's plane): Ward's zone is the disk
//! `‖Δ‖ < a·R`, T&L's the disk `‖Δ‖ < R/(2κ)`; both shrink with normal deviation, Ward additively
//! (`‖Δ‖/R < a − e_nrm`), T&L as a max (`‖Δ‖` unaffected until the cone `e_nrm < 0.1233/κ` is left).

use crate::{clamp_lo_hi, IC_FAR, KAPPA_MIN, R_FLOOR, TL_NORMAL_SCALE, WARD_MIN_ERROR};
use glam::Vec3;

/// GLSL values of [`WeightKind`] (declared once in `radcache_shared::consts`).
pub use radcache_shared::consts::{WEIGHT_TL, WEIGHT_WARD};

/// Which weighting function interpolates the cache (`as u32` gives the GLSL constant).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum WeightKind {
    /// Ward's split-sphere weight `1/ε` (§5.2); parameter `a` (accuracy).
    Ward = WEIGHT_WARD,
    /// Tabellion–Lamorlette's bounded weight `1 − κ·max(ε_p, ε_n)` (§5.3); parameter `κ`.
    #[default]
    TabellionLamorlette = WEIGHT_TL,
}

impl WeightKind {
    /// Kind from its GLSL constant (unknown values map to the default).
    pub fn from_u32(v: u32) -> Self {
        if v == WEIGHT_WARD {
            Self::Ward
        } else {
            Self::TabellionLamorlette
        }
    }
}

/// Normal test (§5.4): the record faces the same side, `n·n_i > 0`.
pub fn normal_test(n: Vec3, n_i: Vec3) -> bool {
    n.dot(n_i) > 0.0
}

/// In-front test (§5.4): true (record usable) unless `(p − p_i)·n_i < −max(tol, 0)`.
pub fn in_front_test(p: Vec3, p_i: Vec3, n_i: Vec3, tol: f32) -> bool {
    (p - p_i).dot(n_i) >= -tol.max(0.0)
}

/// Normal error `sqrt(1 − n·n_i)` (§5.1), evaluated as `‖n − n_i‖/√2` — the same value for unit
/// normals (`‖n − n_i‖² = 2 − 2 n·n_i`), but without the cancellation of `1 − n·n_i` in f32 (a
/// percent-level error below 0.1° of deviation) and never negative under the root (§5.1).
pub fn normal_error(n: Vec3, n_i: Vec3) -> f32 {
    (n - n_i).length() * core::f32::consts::FRAC_1_SQRT_2
}

/// Positional error `(‖Δ‖ + |Δ·n_i|) / max(R_i, R_FLOOR)`, `Δ = p − p_i` (§5.1, with its
/// out-of-plane term).
pub fn position_error(p: Vec3, p_i: Vec3, n_i: Vec3, r_i: f32) -> f32 {
    let d = p - p_i;
    (d.length() + d.dot(n_i).abs()) / clamp_lo_hi(r_i, R_FLOOR, IC_FAR)
}

/// Ward's weight (§5.2) with the normal and in-front tests: `1/max(ε, 10⁻³)` if `ε < a`, else 0.
pub fn ward_weight(
    p: Vec3,
    n: Vec3,
    p_i: Vec3,
    n_i: Vec3,
    r_i: f32,
    a: f32,
    front_tol: f32,
) -> f32 {
    if !normal_test(n, n_i) || !in_front_test(p, p_i, n_i, front_tol) {
        return 0.0;
    }
    let eps = position_error(p, p_i, n_i, r_i) + normal_error(n, n_i);
    if eps < a {
        1.0 / eps.max(WARD_MIN_ERROR)
    } else {
        0.0
    }
}

/// Tabellion–Lamorlette's weight (§5.3) with the normal and in-front tests:
/// `max(0, 1 − κ·max(2·e_pos, e_nrm/sqrt(1 − cos 10°)))`, `κ >= KAPPA_MIN`.
pub fn tl_weight(
    p: Vec3,
    n: Vec3,
    p_i: Vec3,
    n_i: Vec3,
    r_i: f32,
    kappa: f32,
    front_tol: f32,
) -> f32 {
    if !normal_test(n, n_i) || !in_front_test(p, p_i, n_i, front_tol) {
        return 0.0;
    }
    let e_p = 2.0 * position_error(p, p_i, n_i, r_i);
    let e_n = normal_error(n, n_i) / TL_NORMAL_SCALE;
    let w = 1.0 - kappa.max(KAPPA_MIN) * e_p.max(e_n);
    if w > 0.0 {
        w
    } else {
        0.0
    }
}

/// A record as its weight sees it: its point `p_i`, normal `n_i` and harmonic-mean distance
/// `R_i` (the GLSL twin's `p_i, n_i, r_i`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightRecord {
    /// The record's point `p_i`.
    pub p: Vec3,
    /// Its normal `n_i`.
    pub n: Vec3,
    /// Its harmonic-mean distance `R_i`.
    pub r: f32,
}

/// Weight of `record` at `(p, n)` for `kind`; `param` is `a` (Ward) or `κ` (T&L).
pub fn record_weight(
    kind: WeightKind,
    p: Vec3,
    n: Vec3,
    record: WeightRecord,
    param: f32,
    front_tol: f32,
) -> f32 {
    let WeightRecord {
        p: p_i,
        n: n_i,
        r: r_i,
    } = record;
    match kind {
        WeightKind::Ward => ward_weight(p, n, p_i, n_i, r_i, param, front_tol),
        WeightKind::TabellionLamorlette => tl_weight(p, n, p_i, n_i, r_i, param, front_tol),
    }
}

/// Ratio of the validity radius to `R` (§5.6): `a` (Ward) or `1/(2κ)` (T&L).
pub fn validity_scale(kind: WeightKind, param: f32) -> f32 {
    match kind {
        WeightKind::Ward => param.max(0.0),
        WeightKind::TabellionLamorlette => 0.5 / param.max(KAPPA_MIN),
    }
}

/// World-space radius around `p_i` beyond which the weight is 0 or below `w_min` (§5.6): the
/// radius of the sphere a splat quad must cover.
/// * Ward: `w > max(1/a, w_min)` needs `‖Δ‖ < R / max(1/a, w_min)` (since `ε >= ‖Δ‖/R`).
/// * T&L: `w > w_min` needs `‖Δ‖ < (1 − w_min) · R / (2κ)` (`w_min` clamped to `[0, 1]`).
pub fn splat_radius(kind: WeightKind, r_i: f32, param: f32, w_min: f32) -> f32 {
    let r = clamp_lo_hi(r_i, R_FLOOR, IC_FAR);
    match kind {
        WeightKind::Ward => (r / (1.0 / param.max(1.0e-6)).max(w_min)).min(IC_FAR),
        WeightKind::TabellionLamorlette => {
            (1.0 - w_min.clamp(0.0, 1.0)) * r * (0.5 / param.max(KAPPA_MIN))
        }
    }
}

/// Weight of "one full record" for hole detection: `1/a` for Ward (every valid Ward weight exceeds
/// it), 1 for T&L (the weight at the record's own position).
pub fn weight_unit(kind: WeightKind, param: f32) -> f32 {
    match kind {
        WeightKind::Ward => 1.0 / param.max(1.0e-6),
        WeightKind::TabellionLamorlette => 1.0,
    }
}

/// Σw below which a pixel is a hole: `hole_threshold · weight_unit` (§5.6;
/// docs/cache-frame.md §3.3).
pub fn coverage_threshold(kind: WeightKind, param: f32, hole_threshold: f32) -> f32 {
    hole_threshold.max(0.0) * weight_unit(kind, param)
}
