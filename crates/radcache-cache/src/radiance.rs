//! Radiance records (docs/radiance-caching.md §7): the SH coefficients of the incoming radiance
//! projected from a record's stratified gather, and their translational gradients in the
//! "moving walls" form of [KGBP05], so a record's coefficients extrapolate across its zone as
//! its irradiance does.
//!
//! **Projection.** Stratum `(j, k)` of the `M × N` cosine-stratified hemisphere has the exact
//! solid angle `Ω_j = (2π/N)(cosθ_j⁻ − cosθ_j⁺)` ([`stratum_solid_angle`]); its sample `L_jk`
//! counts at its (folded) gather direction `d_jk`: `c_i = Σ_jk Ω_j · L'_jk · Y_i(d_jk)`, where
//! `L'` is [`radiance_sample`]: the sample where its ray hit something, 0 where it escaped (the
//! light straight from the sky reaches glossy lobes through the direct pass's BSDF samples).
//!
//! **Gradient.** Moving the record point by `δx` moves every stratum wall across the scene
//! behind it; the solid angle swept across a wall changes hands between the two strata beside
//! it. For a solid-angle integral (no cosine, unlike the irradiance's projected solid angle of
//! `crate::record`) the swept solid angle per unit translation is:
//!
//! * polar wall between rows `j − 1` and `j` (at `θ_j⁻`, length `sinθ_j⁻·2π/N`, moving at
//!   `cosθ_j⁻/r` along `u(φ_k)`): `(2π/N)·sinθ_j⁻·cosθ_j⁻ · u(φ_k) / r`
//!   ([`radiance_polar_wall_coeff`]);
//! * azimuthal wall between columns `k − 1` and `k` (spanning `θ_j⁻..θ_j⁺`, swept solid angle
//!   `(cosθ_j⁻ − cosθ_j⁺)·δφ` with `δφ = δx/(r·sinθ_j)` along `v(φ_k⁻)`):
//!   `(cosθ_j⁻ − cosθ_j⁺)/sinθ_j · v(φ_k⁻) / r` ([`radiance_azimuthal_wall_coeff`]).
//!
//! The radiance that changes hands is `L'_cur − L'_prev` seen from the nearer side's distance
//! (`crate::record::wall_term`), and it arrives from the wall's direction, so
//!
//! ```text
//! ∇c_i = Σ_walls coeff_wall · Y_i(d_wall) · wall_term(L'_cur, L'_prev, r_cur, r_prev)
//! ```
//!
//! with `d_wall` the wall's midpoint: `stratum_direction_local(j, k, M, N, 0, ½)` for a polar wall
//! and `(j, k, M, N, ½, 0)` for an azimuthal one. The basis is fixed in world space, so a
//! translation changes no `Y_i`; only the walls move. First order in the stratum size, as the
//! irradiance gradient (tests/radiance_gradients.rs measures it against finite differences).

use core::f32::consts::TAU;
use glam::Vec3;
use radcache_material::sh::{sh_basis, ShRgb, SH_COEFFS};

use crate::record::wall_term;
use crate::sampling::{
    basis_from_normal, frame_to_world, horizontal_u, horizontal_v, normalize_or_z,
    stratum_direction_local, stratum_index, stratum_phi_centre, stratum_phi_start,
};
use crate::IC_FAR;

/// Solid angle of one stratum of row `j` of the `M × N` cosine-stratified hemisphere:
/// `(2π/N)(√(1 − j/M) − √(1 − (j+1)/M))` (`j` clamped to `M − 1`).
pub fn stratum_solid_angle(j: u32, m: u32, n: u32) -> f32 {
    let m = m.max(1);
    let j = j.min(m - 1) as f32;
    let mf = m as f32;
    let cos_lo = (1.0 - j / mf).max(0.0).sqrt();
    let cos_hi = (1.0 - (j + 1.0) / mf).max(0.0).sqrt();
    (TAU / n.max(1) as f32) * (cos_lo - cos_hi)
}

/// The value a stratum's sample contributes to the radiance projection: `l` where its ray hit
/// (`r < IC_FAR`), 0 where it escaped.
pub fn radiance_sample(l: Vec3, r: f32) -> Vec3 {
    if r < IC_FAR {
        l
    } else {
        Vec3::ZERO
    }
}

/// Local-frame coefficient of the polar wall between rows `j − 1` and `j` in column `k` for a
/// solid-angle integral: `(2π/N)·sinθ_j⁻·cosθ_j⁻ · u(φ_k)`; zero for `j = 0` or `j >= M`.
pub fn radiance_polar_wall_coeff(j: u32, k: u32, m: u32, n: u32) -> Vec3 {
    let m = m.max(1);
    if j == 0 || j >= m {
        return Vec3::ZERO;
    }
    let s2 = j as f32 / m as f32;
    let c = (TAU / n.max(1) as f32) * s2.sqrt() * (1.0 - s2).max(0.0).sqrt();
    horizontal_u(stratum_phi_centre(k, n)) * c
}

/// Local-frame coefficient of the azimuthal wall between columns `k − 1` and `k` in row `j` for
/// a solid-angle integral: `(cosθ_j⁻ − cosθ_j⁺)/sinθ_j · v(φ_k⁻)`, `sin²θ_j = (j + ½)/M`; `j` is
/// clamped to `M − 1`.
pub fn radiance_azimuthal_wall_coeff(j: u32, k: u32, m: u32, n: u32) -> Vec3 {
    let m = m.max(1);
    let j = j.min(m - 1) as f32;
    let mf = m as f32;
    let s2c = (j + 0.5) / mf;
    let cos_lo = (1.0 - j / mf).max(0.0).sqrt();
    let cos_hi = (1.0 - (j + 1.0) / mf).max(0.0).sqrt();
    horizontal_v(stratum_phi_start(k, n)) * ((cos_lo - cos_hi) / s2c.sqrt())
}

/// A record's radiance coefficients and their translational gradients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadianceEstimate {
    /// `c_i` (RGB) in world space.
    pub coeffs: ShRgb,
    /// `∂c_i/∂x`, `∂c_i/∂y`, `∂c_i/∂z` (world axes), RGB each.
    pub grad: [ShRgb; 3],
}

/// Projects `M × N` strata (`l[j*N + k]`, `r[j*N + k]`, gathered in the frame
/// `basis_from_normal(normal)` along the world directions `dirs[j*N + k]`) onto the SH basis,
/// with the translational gradients of the coefficients (see the module docs).
///
/// # Panics
/// If a slice does not hold exactly `m * n` entries (a programming error).
pub fn compute_radiance(
    l: &[Vec3],
    r: &[f32],
    dirs: &[Vec3],
    m: u32,
    n: u32,
    normal: Vec3,
    r_eps: f32,
) -> RadianceEstimate {
    let count = m as usize * n as usize;
    assert_eq!(l.len(), count, "radiance slice must hold M*N strata");
    assert_eq!(r.len(), count, "distance slice must hold M*N strata");
    assert_eq!(dirs.len(), count, "direction slice must hold M*N strata");
    let nn = normalize_or_z(normal);
    let (t, b) = basis_from_normal(nn);
    let mut out = RadianceEstimate {
        coeffs: [Vec3::ZERO; SH_COEFFS],
        grad: [[Vec3::ZERO; SH_COEFFS]; 3],
    };
    let sample = |i: usize| radiance_sample(l[i], r[i]);
    let mut add_wall = |coeff: Vec3, dir_local: Vec3, d: Vec3| {
        let cw = frame_to_world(coeff, t, b, nn);
        let y = sh_basis(frame_to_world(dir_local, t, b, nn));
        for (i, yi) in y.iter().enumerate() {
            for (axis, g) in out.grad.iter_mut().enumerate() {
                g[i] += d * (cw[axis] * yi);
            }
        }
    };
    for j in 0..m {
        for k in 0..n {
            let i = stratum_index(j, k, n) as usize;
            if j > 0 {
                let ip = stratum_index(j - 1, k, n) as usize;
                let d = wall_term(sample(i), sample(ip), r[i], r[ip], r_eps);
                let dir = stratum_direction_local(j, k, m, n, 0.0, 0.5);
                add_wall(radiance_polar_wall_coeff(j, k, m, n), dir, d);
            }
            let ip = stratum_index(j, if k == 0 { n - 1 } else { k - 1 }, n) as usize;
            let d = wall_term(sample(i), sample(ip), r[i], r[ip], r_eps);
            let dir = stratum_direction_local(j, k, m, n, 0.5, 0.0);
            add_wall(radiance_azimuthal_wall_coeff(j, k, m, n), dir, d);
        }
    }
    for j in 0..m {
        let omega = stratum_solid_angle(j, m, n);
        for k in 0..n {
            let i = stratum_index(j, k, n) as usize;
            let y = sh_basis(dirs[i]);
            let v = sample(i) * omega;
            for (c, yi) in out.coeffs.iter_mut().zip(y) {
                *c += v * yi;
            }
        }
    }
    out
}

/// The glossy gradient limit from the sums it needs (docs/radiance-caching.md §9):
/// `min_c √(Σ_i c_ic² / Σ_{a,i} (∂c_ic/∂x_a)²)` over the channels whose gradients are not all
/// zero, [`IC_FAR`] when none is; `coeff_sq` and `grad_sq` hold those two sums per channel.
/// `glossy_gradient_limit_from_sums` in `shaders/common/ircache_math.glsl` is its GLSL twin.
pub fn glossy_gradient_limit_from_sums(coeff_sq: Vec3, grad_sq: Vec3) -> f32 {
    let mut out = IC_FAR;
    for c in 0..3 {
        if grad_sq[c] > 0.0 && grad_sq[c].is_finite() {
            out = out.min((coeff_sq[c].max(0.0) / grad_sq[c]).sqrt());
        }
    }
    out
}

/// The radius over which a record's radiance field, as its coefficients see it, changes to first
/// order by its own size: per channel the L² norm of the coefficients over the L² (Frobenius)
/// norm of their translational gradients, the smallest over the channels. By Parseval both
/// norms are those of the band-limited functions on the sphere, so this is the glossy lobe's
/// analogue of the irradiance's gradient limit `E/‖∇E‖` ([`crate::radius::gradient_limit_radius`]):
/// a lobe that weighs the directions evenly changes at most as fast as the field (Cauchy–Schwarz
/// bounds `|Σ ∇c_i·δx W_i|` by `‖∇c‖·|δx|·‖W‖`).
pub fn glossy_gradient_limit(estimate: &RadianceEstimate) -> f32 {
    let (mut coeff_sq, mut grad_sq) = (Vec3::ZERO, Vec3::ZERO);
    for i in 0..SH_COEFFS {
        coeff_sq += estimate.coeffs[i] * estimate.coeffs[i];
        for axis in &estimate.grad {
            grad_sq += axis[i] * axis[i];
        }
    }
    glossy_gradient_limit_from_sums(coeff_sq, grad_sq)
}

#[cfg(test)]
mod glossy_limit_tests {
    use super::*;

    fn estimate(c0: Vec3, g: Vec3) -> RadianceEstimate {
        let mut e = RadianceEstimate {
            coeffs: [Vec3::ZERO; SH_COEFFS],
            grad: [[Vec3::ZERO; SH_COEFFS]; 3],
        };
        e.coeffs[0] = c0;
        e.coeffs[3] = 0.5 * c0;
        e.grad[0][0] = g;
        e.grad[2][3] = 2.0 * g;
        e
    }

    #[test]
    fn the_limit_is_the_distance_at_which_the_linear_field_doubles() {
        // ‖c‖ = √1.25·|c0|, ‖∇c‖ = √5·|g| per channel.
        let e = estimate(Vec3::new(2.0, 4.0, 1.0), Vec3::new(1.0, 1.0, 1.0));
        let expect = (1.25f32).sqrt() * 1.0 / 5f32.sqrt();
        assert!((glossy_gradient_limit(&e) - expect).abs() <= 1e-6 * expect);
        // The smallest channel wins: a steeper red gradient limits all three.
        let mut steep = e;
        steep.grad[0][0].x = 10.0;
        let red = ((1.25f32 * 4.0) / (100.0 + 4.0)).sqrt();
        assert!((glossy_gradient_limit(&steep) - red).abs() <= 1e-6 * red);
    }

    #[test]
    fn no_gradient_means_no_limit_and_a_dark_channel_limits_nothing_it_lacks() {
        let flat = estimate(Vec3::ONE, Vec3::ZERO);
        assert_eq!(glossy_gradient_limit(&flat), IC_FAR);
        // A channel without light but with a gradient limits to 0 (its first-order change is
        // infinitely larger than its value), as the irradiance's limit does.
        let dark_red = estimate(Vec3::new(0.0, 1.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(glossy_gradient_limit(&dark_red), 0.0);
        let sums = glossy_gradient_limit_from_sums(Vec3::splat(4.0), Vec3::new(1.0, f32::NAN, 0.0));
        assert_eq!(sums, 2.0);
    }
}
