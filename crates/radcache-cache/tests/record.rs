//! Tests of the record sums (docs/irradiance-cache.md §2.5, §3): constant radiance, the harmonic
//! mean above a plane, the split sphere of §3.3 (exact gradients), invalid samples and the
//! elevation restriction.

mod common;

use common::{Rect, Scene};
use glam::{DVec3, Vec3};
use radcache_cache::record::*;
use radcache_cache::sampling::*;
use radcache_cache::IC_FAR;
use std::f32::consts::PI;

fn rel(a: f32, b: f32) -> f32 {
    (a - b).abs() / b.abs().max(1e-30)
}

#[test]
fn constant_radiance_gives_pi_l_and_zero_gradients() {
    let (m, n) = STRATA_DEFAULT;
    let l0 = Vec3::new(0.7, 1.3, 2.0);
    let l = vec![l0; (m * n) as usize];
    // Distances arbitrary (hits and misses): gradients must still vanish.
    let r: Vec<f32> = (0..m * n)
        .map(|i| {
            if i % 7 == 0 {
                f32::INFINITY
            } else {
                0.1 + unit_float_from_bits(ircache_hash(i)) * 5.0
            }
        })
        .collect();
    for normal in [Vec3::Z, -Vec3::Y, Vec3::new(0.3, -0.5, 0.8)] {
        let rec = compute_record(&l, &r, m, n, normal, 1e-4);
        assert!(
            (rec.e - l0 * PI).abs().max_element() < 1e-4 * PI * 2.0,
            "E = {}",
            rec.e
        );
        for c in 0..3 {
            assert!(rec.grad_r[c].length() < 1e-5, "grad_r = {}", rec.grad_r[c]);
            assert!(rec.grad_t[c].length() < 1e-5, "grad_t = {}", rec.grad_t[c]);
        }
        assert_eq!(rec.valid_samples, m * n);
    }
    let misses = vec![f32::INFINITY; (m * n) as usize];
    let rec = compute_record(&l, &misses, m, n, Vec3::Z, 1e-4);
    assert_eq!(
        (rec.r_harmonic, rec.r_min, rec.r_min_restricted),
        (IC_FAR, IC_FAR, IC_FAR)
    );
    assert_eq!(rec.radius(), IC_FAR);
}

#[test]
fn harmonic_mean_above_a_plane_is_three_halves_height() {
    // Record at height h facing an infinite plane: r = h/cosθ, and under the cosine pdf
    // E[1/r] = E[cosθ]/h = 2/(3h), so R_harm = 3h/2 (§2.5). r_min → h (pole stratum).
    let h = 0.8;
    let plane = Scene {
        rects: vec![Rect::new(
            DVec3::new(-1e5, -1e5, 0.0),
            DVec3::new(2e5, 0.0, 0.0),
            DVec3::new(0.0, 2e5, 0.0),
            DVec3::ONE,
        )],
        sky: DVec3::ZERO,
    };
    for (m, n, tol) in [(8, 24, 3e-3), (16, 48, 1e-3)] {
        let rec = plane.record(Vec3::new(0.3, -0.2, h), -Vec3::Z, m, n, 99);
        assert!(
            rel(rec.r_harmonic, 1.5 * h) < tol,
            "{m}x{n}: R_harm = {}",
            rec.r_harmonic
        );
        assert!(
            rec.r_min >= h && rec.r_min < h * (1.0 + 1.0 / m as f32),
            "r_min = {}",
            rec.r_min
        );
        assert_eq!(rec.r_min, rec.r_min_restricted);
        assert!(rel(rec.radius(), 1.5 * h) < tol);
        assert!(rel(rec.e.x, PI) < 1e-5, "whole hemisphere sees L = 1");
    }
}

/// Split sphere (§3.3): record at the centre of a sphere of radius `rs`, radiance `l` on the half
/// `x > 0`, black elsewhere. Exact: `E = πL/2`, `∇_t E = (2L/R) x̂`, `∇_r E = (πL/2) ŷ`, `R = rs`.
fn split_sphere(m: u32, n: u32, rs: f32, l: Vec3) -> RecordEstimate {
    let mut ls = Vec::new();
    let mut rs_v = Vec::new();
    for j in 0..m {
        for k in 0..n {
            let (xi, psi) = stratum_jitter(3, stratum_index(j, k, n));
            let w = stratum_direction_local(j, k, m, n, xi, psi); // frame of +Z is (x, y, z)
            ls.push(if w.x > 0.0 { l } else { Vec3::ZERO });
            rs_v.push(rs);
        }
    }
    compute_record(&ls, &rs_v, m, n, Vec3::Z, 1e-6)
}

#[test]
fn split_sphere_matches_the_closed_form() {
    let (m, n) = STRATA_DEFAULT;
    let (rs, l) = (2.5, Vec3::new(1.0, 0.5, 0.0));
    let rec = split_sphere(m, n, rs, l);
    assert!((rec.e - l * PI / 2.0).abs().max_element() < 1e-5);
    assert!(rel(rec.r_harmonic, rs) < 1e-4 && rec.r_min == rs);
    // Rotational gradient: Σ_j mean(tanθ)/M = π/2 exactly, so only the midpoint sum over the
    // columns approximates ∫cosφ dφ: error O(1/N²).
    assert!(
        (rec.grad_r[0] - Vec3::Y * PI / 2.0).length() < 2e-3 * PI / 2.0,
        "grad_r = {}",
        rec.grad_r[0]
    );
    // Translational gradient: the split plane lies on column walls (N divisible by 4), so the
    // estimate is exactly 2·S·L/R with S = Σ_j of the improved azimuthal coefficients; the
    // improved form's S differs from the exact Σ_j(sinθ⁺ − sinθ⁻) = 1 by its pole/horizon rows.
    let s: f32 = (0..m)
        .map(|j| azimuthal_wall_coeff(j, 0, m, n).length())
        .sum();
    assert!(
        (rec.grad_t[0] - Vec3::X * 2.0 * s / rs).length() < 1e-4,
        "grad_t = {} vs S = {s}",
        rec.grad_t[0]
    );
    assert!((s - 1.0).abs() < 0.07, "S = {s}");
    assert!(
        rel(rec.grad_t[1].x, 0.5 * rec.grad_t[0].x) < 1e-5 && rec.grad_t[2].length() == 0.0,
        "per channel"
    );
    for c in 0..3 {
        assert!(
            rec.grad_t[c].z.abs() < 1e-6 && rec.grad_r[c].z.abs() < 1e-6,
            "tangent-plane vectors"
        );
    }
}

#[test]
fn invalid_samples_are_excluded_from_distances_and_walls() {
    let (m, n) = (4, 12);
    let l = vec![Vec3::ONE; 48];
    let mut r = vec![2.0f32; 48];
    r[5] = 0.0; // self-intersection
    r[6] = f32::NAN; // garbage
    r[7] = -1.0;
    r[8] = 1e-9; // below r_eps
    let rec = compute_record(&l, &r, m, n, Vec3::Z, 1e-6);
    assert_eq!(rec.valid_samples, 44);
    assert_eq!((rec.r_harmonic, rec.r_min), (2.0, 2.0));
    assert_eq!(wall_term(Vec3::ONE, Vec3::ZERO, 0.0, 1.0, 1e-6), Vec3::ZERO);
    assert_eq!(
        wall_term(Vec3::ONE, Vec3::ZERO, f32::INFINITY, f32::INFINITY, 1e-6),
        Vec3::ZERO,
        "two misses"
    );
    assert_eq!(
        wall_term(Vec3::ONE, Vec3::ZERO, f32::INFINITY, 0.5, 1e-6),
        Vec3::splat(2.0),
        "hit vs miss uses the hit"
    );
    assert_eq!(harmonic_mean_distance(f32::INFINITY, 3.0), 0.0);
    assert_eq!(inverse_distance(f32::INFINITY, 0.0), 0.0);
}

#[test]
fn restricted_minimum_ignores_grazing_hits() {
    // Hits at 4 everywhere but one very short grazing hit in the horizon row (elevation < 10°):
    // it collapses R_harm and R_min, not R_min_restricted, and radius() = max(R_harm,
    // R_min_restricted) keeps 4 (§2.5).
    let (m, n) = STRATA_DEFAULT;
    let mut r = vec![4.0f32; (m * n) as usize];
    r[stratum_index(m - 1, 3, n) as usize] = 1e-4;
    let rec = compute_record(&vec![Vec3::ONE; (m * n) as usize], &r, m, n, Vec3::Z, 1e-6);
    assert!(!stratum_elevation_ok(m - 1, m) && stratum_elevation_ok(m - 2, m));
    assert_eq!(rec.r_min, 1e-4);
    assert_eq!(rec.r_min_restricted, 4.0);
    assert!(rec.r_harmonic < 0.1, "R_harm = {}", rec.r_harmonic);
    assert_eq!(rec.radius(), 4.0);
    // With misses the harmonic mean counts them as 1/r = 0: one hit at 2 among M·N strata.
    let mut r = vec![f32::INFINITY; (m * n) as usize];
    r[0] = 2.0;
    let rec = compute_record(&vec![Vec3::ONE; (m * n) as usize], &r, m, n, Vec3::Z, 1e-6);
    assert!(rel(rec.r_harmonic, 2.0 * (m * n) as f32) < 1e-6);
}

#[test]
fn empty_and_degenerate_grids() {
    let rec = compute_record(&[], &[], 0, 0, Vec3::ZERO, 0.0);
    assert_eq!(rec.e, Vec3::ZERO);
    assert_eq!(rec.r_harmonic, IC_FAR);
    let rec = compute_record(&[Vec3::ONE], &[1.0], 1, 1, Vec3::ZERO, 0.0);
    assert!(rel(rec.e.x, PI) < 1e-6 && rec.grad_t[0].is_finite() && rec.grad_r[0].is_finite());
    assert!(irradiance_is_valid(rec.e));
    assert!(
        !irradiance_is_valid(Vec3::new(1.0, f32::NAN, 0.0))
            && !irradiance_is_valid(Vec3::new(-1.0, 0.0, 0.0))
    );
    assert!(!irradiance_is_valid(Vec3::splat(f32::INFINITY)));
}
