//! Tests of the radius post-processing (docs/irradiance-cache.md §4.2–§4.7): gradient limit,
//! footprint, clamp order, gradient attenuation, neighbour clamping and corners.

use glam::Vec3;
use radcache_cache::radius::*;
use radcache_cache::weight::{splat_radius, validity_scale, WeightKind};
use radcache_cache::{IC_FAR, R_FLOOR};

const NO_GRAD: [Vec3; 3] = [Vec3::ZERO; 3];

#[test]
fn gradient_limit() {
    let e = Vec3::new(1.0, 2.0, 0.5);
    assert_eq!(
        gradient_limit_radius(10.0, e, &NO_GRAD),
        10.0,
        "zero gradients do not limit"
    );
    let g = [
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 0.05),
    ];
    // min(10, 1/0.1, 2/1, 0.5/0.05) = 2 (§4.2, per channel).
    assert!((gradient_limit_radius(10.0, e, &g) - 2.0).abs() < 1e-6);
    assert_eq!(gradient_limit_radius(1.0, e, &g), 1.0);
    assert_eq!(gradient_limit_radius(f32::INFINITY, e, &NO_GRAD), IC_FAR);
    assert_eq!(
        gradient_limit_radius(5.0, Vec3::new(-1.0, 2.0, 0.5), &g),
        0.0,
        "negative E clamps to 0"
    );
}

#[test]
fn pixel_footprint_forms() {
    assert!(
        (pixel_footprint_from_differentials(Vec3::X * 0.01, Vec3::Y * 0.01) - 0.01).abs() < 1e-7
    );
    assert!(
        (pixel_footprint_from_differentials(Vec3::X * 0.01, Vec3::Y * 0.04) - 0.02).abs() < 1e-7
    );
    // 60° fov, 1080 lines, depth 5, facing the camera: 2·5·tan30°/1080.
    let s = pixel_footprint(5.0, (30f32).to_radians().tan(), 1080.0, 1.0);
    assert!((s - 2.0 * 5.0 * 0.577_350_3 / 1080.0).abs() < 1e-7);
    assert!(
        (pixel_footprint(5.0, 0.577_350_3, 1080.0, 0.25) - 2.0 * s).abs() < 1e-6,
        "1/sqrt(cos)"
    );
    assert_eq!(
        pixel_footprint(5.0, 0.577_350_3, 1080.0, 0.0),
        pixel_footprint(5.0, 0.577_350_3, 1080.0, 0.1),
        "grazing clamp"
    );
}

#[test]
fn radius_bounds_are_validity_radii_in_pixels() {
    // §4.3: R⁻ = 2 px and R⁺ = 20 px are *validity* radii; the zone of a record clamped to R⁻
    // spans exactly 2 footprints for either weight.
    for (kind, param) in [
        (WeightKind::Ward, 0.15),
        (WeightKind::TabellionLamorlette, 1.0),
    ] {
        let s = 0.004;
        let (lo, hi) = radius_bounds(s, 2.0, 20.0, validity_scale(kind, param));
        assert!((splat_radius(kind, lo, param, 0.0) - 2.0 * s).abs() < 1e-6);
        assert!((splat_radius(kind, hi, param, 0.0) - 20.0 * s).abs() < 1e-5);
    }
    let (lo, hi) = radius_bounds(0.0, 2.0, 20.0, 0.15);
    assert_eq!((lo, hi), (R_FLOOR, R_FLOOR), "zero footprint keeps R⁻ > 0");
    let (lo, hi) = radius_bounds(1.0, 30.0, 10.0, 1.0);
    assert!(
        lo == 30.0 && hi == 30.0,
        "inverted pixel limits collapse to R⁻"
    );
}

#[test]
fn clamp_and_attenuation() {
    assert_eq!(clamp_radius(0.5, 1.0, 3.0), 1.0);
    assert_eq!(clamp_radius(5.0, 1.0, 3.0), 3.0);
    assert_eq!(clamp_radius(f32::INFINITY, 1.0, 3.0), 3.0);
    assert_eq!(
        clamp_radius(2.0, 4.0, 3.0),
        4.0,
        "r_hi < r_lo is raised to r_lo"
    );
    assert_eq!(gradient_attenuation(0.5, 2.0), 0.25);
    assert_eq!(gradient_attenuation(5.0, 2.0), 1.0);
    assert_eq!(gradient_attenuation(0.0, 2.0), 0.0);
}

#[test]
fn finalize_radius_follows_the_recommended_order() {
    let e = Vec3::splat(1.0);
    let g = [Vec3::X * 0.5, Vec3::ZERO, Vec3::ZERO]; // gradient limit: R <= 2
                                                     // 3. limit (8 → 2), 4. neighbour bound 1.5, 5. bounds [1, 4], 6. attenuation 1, 7. clamp.
    let f = finalize_radius(8.0, e, &g, 1.5, 1.0, 4.0);
    assert_eq!((f.r_orig, f.r_used, f.grad_t_scale), (1.5, 1.5, 1.0));
    // Clamped up: the unclamped radius after limit/neighbour (0.5) sets the attenuation.
    let f = finalize_radius(8.0, e, &g, 0.5, 1.0, 4.0);
    assert_eq!((f.r_orig, f.r_used, f.grad_t_scale), (0.5, 1.0, 0.5));
    // Clamped down: no attenuation, R_orig keeps the unclamped value for later neighbour clamps.
    let f = finalize_radius(100.0, e, &NO_GRAD, f32::INFINITY, 1.0, 4.0);
    assert_eq!((f.r_orig, f.r_used, f.grad_t_scale), (100.0, 4.0, 1.0));
    // The gradient limit acts before the clamp: a limited radius below R⁻ is raised and attenuated.
    let f = finalize_radius(
        8.0,
        e,
        &[Vec3::X * 4.0, Vec3::ZERO, Vec3::ZERO],
        IC_FAR,
        1.0,
        4.0,
    );
    assert_eq!((f.r_orig, f.r_used, f.grad_t_scale), (0.25, 1.0, 0.25));
    assert_eq!((f.r_lo, f.r_hi), (1.0, 4.0));
}

#[test]
fn neighbour_clamping() {
    // §4.5: R_i <= R_j + d_ij both ways; records far apart are unaffected.
    let (a, b) = neighbour_clamp_pair(10.0, Vec3::ZERO, 1.0, Vec3::X * 2.0);
    assert_eq!((a, b), (3.0, 1.0));
    let (a, b) = neighbour_clamp_pair(10.0, Vec3::ZERO, 1.0, Vec3::X * 20.0);
    assert_eq!((a, b), (10.0, 1.0));
    let (a, b) = neighbour_clamp_pair(f32::INFINITY, Vec3::ZERO, f32::INFINITY, Vec3::ONE);
    assert_eq!((a, b), (IC_FAR, IC_FAR));
    // Triangle inequality holds after one symmetric pass, and a second pass changes nothing.
    let pts = [
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.3, 2.0, 0.0),
        Vec3::new(-4.0, 0.0, 1.0),
    ];
    let mut r = [50.0f32, 0.2, 7.0, f32::INFINITY];
    for _ in 0..2 {
        let before = r;
        for i in 0..4 {
            for j in 0..4 {
                if i != j {
                    r[i] = neighbour_clamp(r[i], r[j], (pts[i] - pts[j]).length());
                }
            }
        }
        if before == r {
            break;
        }
    }
    for i in 0..4 {
        for j in 0..4 {
            assert!(r[i] <= r[j] + (pts[i] - pts[j]).length() + 1e-5);
        }
    }
    let again: Vec<f32> = (0..4)
        .map(|i| {
            (0..4).fold(r[i], |acc, j| {
                neighbour_clamp(acc, r[j], (pts[i] - pts[j]).length())
            })
        })
        .collect();
    assert_eq!(again, r.to_vec());
}

#[test]
fn corners_with_vanishing_radius() {
    // §4.6: R → 0 (record in a corner) must give a positive used radius, a zero attenuation
    // factor (huge corner gradients are not extrapolated) and no Inf/NaN.
    for r in [0.0f32, 1e-30, -1.0] {
        let g = [Vec3::X * 1e30, Vec3::Y * 1e30, Vec3::Z];
        let f = finalize_radius(r, Vec3::ONE, &g, 0.0, 0.01, 0.2);
        assert_eq!(f.r_used, 0.01);
        assert!(f.r_orig >= 0.0 && f.r_orig <= 1e-29 && f.grad_t_scale <= 1e-27);
        let f = finalize_radius(r, Vec3::ONE, &g, 0.0, 0.0, 0.0);
        assert_eq!(f.r_used, R_FLOOR);
        assert!(f.grad_t_scale.is_finite() && f.r_orig.is_finite());
    }
}
