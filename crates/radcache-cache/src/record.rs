//! Record computation from one stratified sample set: irradiance, characteristic distances and the
//! rotational and translational gradients (docs/irradiance-cache.md §2.5, §2.6, §3.1, §3.2, §4.6,
//! §7.1).
//!
//! Inputs per stratum `(j, k)` (index `j * N + k`): RGB radiance `L_jk` and hit distance `r_jk`
//! (a miss is `r >= IC_FAR`, e.g. `+inf`; `r <= r_eps` or NaN is an invalid sample). The strata must
//! have been generated in the frame `basis_from_normal(normal)` (see [`crate::sampling`]).
//!
//! Formulas (all sums over strata, per colour channel):
//!
//! * Irradiance (§2.5): `E = π/(MN) · Σ_jk L_jk`. Every sample's `L` counts, valid or not.
//! * Harmonic-mean distance (§2.5): `R_harm = n_valid / Σ_valid 1/r_jk`, misses contributing
//!   `1/r = 0`; no finite hit gives `IC_FAR`. Minimum distance `R_min = min_valid r_jk`, and the
//!   elevation-restricted minimum over the rows lying entirely above 10° elevation
//!   (`cos²θ_j⁺ >= sin²10°`; Mitsuba tests each sample's own elevation, which this reduction does
//!   not see; the horizon row is always excluded). [`RecordEstimate::radius`] is
//!   `max(R_harm, R_min_restricted)` (§2.5: harmonic mean with the restricted minimum as a lower
//!   bound, which keeps a few short grazing hits from collapsing `R`, §4.6).
//! * Rotational gradient (§3.1): `∇_r E = Σ_k Σ_j (π/(MN)) · T_j · v(φ_k) · L_jk`, `φ_k` the column
//!   centre and `T_j` the **mean of `tan θ` over row `j`** under the cosine-weighted pdf,
//!   `T_j = M·[θ − sinθ cosθ]_{θ_j⁻}^{θ_j⁺}` ([`crate::sampling::stratum_tan_mean`]). §3.1 (and
//!   RADIANCE/Mitsuba) use `tan` at the row centre; both avoid the infinite `tan` of a jittered
//!   horizon sample, but the centre value underestimates the horizon row by `≈ 1/√2`, a bias that
//!   decays only like `1/√M`. The row mean is the exact expectation of the per-sample derivative
//!   `L tanθ cos(φ − ψ)` for radiance constant over the row. Measured against finite differences
//!   (the room scenes of tests/gradients.rs, 16×48, mean of 8 seeds): 2.5–12 % error with the
//!   centre value, 1.5–5 % with the row mean.
//! * Translational gradient (§3.2), **Křivánek et al. 2005 "improved" form [KGBP05]**:
//!   ```text
//!   ∇_t E = Σ_k [ u(φ_k)  Σ_{j=1}^{M−1} (2π/N) sinθ_j⁻ cos²θ_j⁻ (L_jk − L_{j−1,k}) / min(r_jk, r_{j−1,k})
//!               + v(φ_k⁻) Σ_{j=0}^{M−1} cosθ_j (cosθ_j⁻ − cosθ_j⁺)/sinθ_j (L_jk − L_{j,k−1}) / min(r_jk, r_{j,k−1}) ]
//!   ```
//!   with `sin²θ_j⁻ = j/M`, `sin²θ_j⁺ = (j+1)/M`, `sin²θ_j = (j+½)/M` (centre), `φ_k` the centre and
//!   `φ_k⁻ = 2πk/N` the start azimuth, `k − 1` wrapping to `N − 1`, the polar sum starting at `j = 1`
//!   (not Mitsuba's `j > 1`), and the `2π/N` approximation of `∫u dφ` over a column.
//!   A wall with an invalid side, or whose nearer side is a miss, contributes 0 (§3.2); the
//!   wall distance is floored at `R_FLOOR`.
//!   Accuracy: first order in the stratum size (an edge is moved to the nearest stratum wall and
//!   its distance read from the adjacent sample; grazing surfaces make that distance too short).
//!   At 16×48 the finite-difference error of tests/gradients.rs is 11–29 % (mean of 8 seeds),
//!   3–8 % at 64×192; the worst case is an edge crossing the pole row. The improved azimuthal
//!   coefficients also sum to `S = 0.939` instead of 1 at M = 16 (0.966 at M = 64), so a split
//!   sphere's gradient comes out 6 % low; the Ward–Heckbert coefficient `sinθ⁺ − sinθ⁻` sums to 1
//!   but was no better on the room scenes.
//!
//! The per-stratum coefficient functions below are what the GPU reduction evaluates per invocation;
//! [`compute_record`] is their sum.

use crate::sampling::{
    basis_from_normal, frame_to_world, horizontal_u, horizontal_v, normalize_or_z, stratum_index,
    stratum_phi_centre, stratum_phi_start, stratum_projected_solid_angle, stratum_tan_mean,
};
use crate::{ELEVATION_MIN_SIN2, IC_FAR, R_FLOOR};
use core::f32::consts::TAU;
use glam::Vec3;

/// True when `r` is a usable sample distance: `r > max(r_eps, 0)` (NaN is invalid, a miss is valid).
pub fn is_valid_sample(r: f32, r_eps: f32) -> bool {
    r > r_eps.max(0.0)
}

/// `1/r` for a valid hit, 0 for a miss (`r >= IC_FAR`) or an invalid sample (§2.5).
pub fn inverse_distance(r: f32, r_eps: f32) -> f32 {
    if is_valid_sample(r, r_eps) && r < IC_FAR {
        1.0 / r
    } else {
        0.0
    }
}

/// Harmonic mean `count / Σ(1/r)` from its two sums (§2.5). `IC_FAR` when nothing was hit; 0 when
/// the sum overflowed (hits at distance ≈ 0, handled later by the clamps of §4.3/§4.6).
pub fn harmonic_mean_distance(sum_inv_r: f32, valid_count: f32) -> f32 {
    if sum_inv_r > 0.0 && valid_count > 0.0 {
        if sum_inv_r < IC_FAR {
            (valid_count / sum_inv_r).min(IC_FAR)
        } else {
            0.0
        }
    } else {
        IC_FAR
    }
}

/// True when all of row `j` lies above 10° elevation (`cos²θ_j⁺ = 1 − (j+1)/M >= sin²10°`, §2.5).
/// The horizon row never qualifies; with a centre-based test no row would be excluded at `M <= 16`.
pub fn stratum_elevation_ok(j: u32, m: u32) -> bool {
    1.0 - (j as f32 + 1.0) / m.max(1) as f32 >= ELEVATION_MIN_SIN2
}

/// Local-frame coefficient of `L_jk` in the rotational gradient: `π/(MN) · mean_j(tanθ) · v(φ_k)`
/// (§3.1 with the row mean of `tan θ`, see the module docs).
pub fn rotational_gradient_coeff(j: u32, k: u32, m: u32, n: u32) -> Vec3 {
    horizontal_v(stratum_phi_centre(k, n))
        * (stratum_projected_solid_angle(m, n) * stratum_tan_mean(j, m))
}

/// Local-frame coefficient of the polar wall between rows `j − 1` and `j` in column `k`:
/// `(2π/N) · sinθ_j⁻ · cos²θ_j⁻ · u(φ_k)`; zero for `j = 0` or `j >= M` (§3.2).
pub fn polar_wall_coeff(j: u32, k: u32, m: u32, n: u32) -> Vec3 {
    let m = m.max(1);
    if j == 0 || j >= m {
        return Vec3::ZERO;
    }
    let s2 = j as f32 / m as f32;
    let c = (TAU / n.max(1) as f32) * s2.sqrt() * (1.0 - s2);
    horizontal_u(stratum_phi_centre(k, n)) * c
}

/// Local-frame coefficient of the azimuthal wall between columns `k − 1` and `k` in row `j`
/// (Křivánek's improved form): `cosθ_j (cosθ_j⁻ − cosθ_j⁺) / sinθ_j · v(φ_k⁻)` (§3.2).
/// `j` is clamped to `M − 1`; `sinθ_j >= sqrt(1/(2M)) > 0`.
pub fn azimuthal_wall_coeff(j: u32, k: u32, m: u32, n: u32) -> Vec3 {
    let m = m.max(1);
    let j = j.min(m - 1) as f32;
    let mf = m as f32;
    let s2c = (j + 0.5) / mf;
    let cos_lo = (1.0 - j / mf).max(0.0).sqrt();
    let cos_hi = (1.0 - (j + 1.0) / mf).max(0.0).sqrt();
    let c = (1.0 - s2c).sqrt() * (cos_lo - cos_hi) / s2c.sqrt();
    horizontal_v(stratum_phi_start(k, n)) * c
}

/// Radiance difference across one wall divided by the wall's distance:
/// `(L_cur − L_prev) / max(min(r_cur, r_prev), R_FLOOR)` per channel; 0 when either side is
/// invalid or the nearer side is a miss (two misses: an infinitely distant wall moves by 0) (§3.2).
pub fn wall_term(l_cur: Vec3, l_prev: Vec3, r_cur: f32, r_prev: f32, r_eps: f32) -> Vec3 {
    if !is_valid_sample(r_cur, r_eps) || !is_valid_sample(r_prev, r_eps) {
        return Vec3::ZERO;
    }
    let r = r_cur.min(r_prev).max(R_FLOOR);
    if r < IC_FAR {
        (l_cur - l_prev) / r
    } else {
        Vec3::ZERO
    }
}

/// Everything a record needs from its sample set (§2.6), before the radius post-processing of §4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordEstimate {
    /// Irradiance `E` (RGB), §2.5.
    pub e: Vec3,
    /// Rotational gradient, one world-space tangent vector per channel (R, G, B), §3.1.
    pub grad_r: [Vec3; 3],
    /// Translational gradient (Křivánek improved form), per channel, world space, §3.2.
    pub grad_t: [Vec3; 3],
    /// Harmonic-mean hit distance over valid samples (`IC_FAR` if nothing was hit), §2.5.
    pub r_harmonic: f32,
    /// Minimum valid hit distance (`IC_FAR` if none), §2.5.
    pub r_min: f32,
    /// Minimum valid hit distance over rows entirely above 10° elevation (`IC_FAR` if none), §2.5.
    pub r_min_restricted: f32,
    /// Number of valid samples (`r > r_eps`).
    pub valid_samples: u32,
}

impl RecordEstimate {
    /// Characteristic distance before §4 post-processing: `max(R_harm, R_min_restricted)` (§2.5).
    pub fn radius(&self) -> f32 {
        self.r_harmonic.max(self.r_min_restricted)
    }
}

/// Computes `E`, `∇_r E`, `∇_t E`, `R_harm`, `R_min` and `R_min_restricted` from `M × N` strata
/// (`l[j*N + k]`, `r[j*N + k]`) sampled around `normal` in the frame `basis_from_normal(normal)`.
/// `m == 0 || n == 0` gives an empty record (`E = 0`, distances `IC_FAR`).
///
/// # Panics
/// If `l` or `r` does not hold exactly `m * n` entries (a programming error).
pub fn compute_record(
    l: &[Vec3],
    r: &[f32],
    m: u32,
    n: u32,
    normal: Vec3,
    r_eps: f32,
) -> RecordEstimate {
    let count = m as usize * n as usize;
    assert_eq!(l.len(), count, "radiance slice must hold M*N strata");
    assert_eq!(r.len(), count, "distance slice must hold M*N strata");
    let nn = normalize_or_z(normal);
    let (t, b) = basis_from_normal(nn);
    let mut sum_l = Vec3::ZERO;
    let mut grad_r = [Vec3::ZERO; 3];
    let mut grad_t = [Vec3::ZERO; 3];
    let mut sum_inv = 0.0f32;
    let mut valid = 0u32;
    let mut r_min = IC_FAR;
    let mut r_min_restricted = IC_FAR;
    for j in 0..m {
        let elevation_ok = stratum_elevation_ok(j, m);
        for k in 0..n {
            let i = stratum_index(j, k, n) as usize;
            let (lc, rc) = (l[i], r[i]);
            sum_l += lc;
            if is_valid_sample(rc, r_eps) {
                valid += 1;
                sum_inv += inverse_distance(rc, r_eps);
                r_min = r_min.min(rc);
                if elevation_ok {
                    r_min_restricted = r_min_restricted.min(rc);
                }
            }
            let cr = frame_to_world(rotational_gradient_coeff(j, k, m, n), t, b, nn);
            let mut trans = [Vec3::ZERO; 3];
            if j > 0 {
                let ip = stratum_index(j - 1, k, n) as usize;
                let d = wall_term(lc, l[ip], rc, r[ip], r_eps);
                let cw = frame_to_world(polar_wall_coeff(j, k, m, n), t, b, nn);
                trans = [cw * d.x, cw * d.y, cw * d.z];
            }
            let kp = if k == 0 { n - 1 } else { k - 1 };
            let ip = stratum_index(j, kp, n) as usize;
            let d = wall_term(lc, l[ip], rc, r[ip], r_eps);
            let ca = frame_to_world(azimuthal_wall_coeff(j, k, m, n), t, b, nn);
            for c in 0..3 {
                grad_r[c] += cr * lc[c];
                grad_t[c] += trans[c] + ca * d[c];
            }
        }
    }
    RecordEstimate {
        e: sum_l * stratum_projected_solid_angle(m, n),
        grad_r,
        grad_t,
        r_harmonic: harmonic_mean_distance(sum_inv, valid as f32),
        r_min: r_min.min(IC_FAR),
        r_min_restricted: r_min_restricted.min(IC_FAR),
        valid_samples: valid,
    }
}

/// True when a computed irradiance is storable: every channel in `[0, 3·10³⁸)` (finite, not NaN,
/// not negative) (§2.7: validate before insertion and count rejections).
pub fn irradiance_is_valid(e: Vec3) -> bool {
    e.cmpge(Vec3::ZERO).all() && e.cmplt(Vec3::splat(3.0e38)).all()
}
