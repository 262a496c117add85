//! Tests of the weights and splat radius (docs/irradiance-cache.md §5.1–§5.4, §5.6, §7.2):
//! monotonicity, symmetry, cap, in-front and normal tests, zone shapes of Ward vs
//! Tabellion–Lamorlette.

use glam::{Quat, Vec3};
use radcache_cache::sampling::{ircache_hash, unit_float_from_bits};
use radcache_cache::weight::*;
use radcache_cache::{R_FLOOR, TL_NORMAL_SCALE, WARD_MIN_ERROR};

const KINDS: [(WeightKind, f32); 2] = [
    (WeightKind::Ward, 0.15),
    (WeightKind::TabellionLamorlette, 1.0),
];
const R: f32 = 2.0;
const TOL: f32 = 0.01;

fn w(kind: WeightKind, param: f32, p: Vec3, n: Vec3) -> f32 {
    let record = WeightRecord {
        p: Vec3::ZERO,
        n: Vec3::Z,
        r: R,
    };
    record_weight(kind, p, n, record, param, TOL)
}

fn tilt(angle: f32) -> Vec3 {
    Quat::from_rotation_y(angle) * Vec3::Z
}

#[test]
fn weights_decrease_with_distance_and_normal_deviation() {
    for (kind, param) in KINDS {
        let reach = splat_radius(kind, R, param, 0.0);
        let mut prev = f32::INFINITY;
        for i in 0..200 {
            let d = reach * 1.2 * i as f32 / 199.0;
            let wi = w(kind, param, Vec3::new(d, 0.0, 0.0), Vec3::Z);
            assert!(wi <= prev, "{kind:?}: not decreasing in distance at {d}");
            prev = wi;
        }
        assert_eq!(prev, 0.0);
        let mut prev = f32::INFINITY;
        for i in 0..200 {
            let a = 0.6 * i as f32 / 199.0;
            let wi = w(kind, param, Vec3::new(0.05 * reach, 0.0, 0.0), tilt(a));
            assert!(
                wi <= prev,
                "{kind:?}: not decreasing in normal deviation at {a}"
            );
            prev = wi;
        }
        assert_eq!(prev, 0.0);
    }
}

#[test]
fn weights_are_symmetric() {
    // Rotations about n_i and mirror images in the tangent plane leave the weight unchanged.
    for (kind, param) in KINDS {
        for i in 0..500 {
            let h = |k: u32| unit_float_from_bits(ircache_hash(i * 4 + k));
            let p = Vec3::new(h(0) - 0.5, h(1) - 0.5, 0.02 * (h(2) - 0.3));
            let n = tilt(0.2 * h(3));
            let w0 = w(kind, param, p, n);
            let q = Quat::from_rotation_z(1.234 * i as f32);
            let w1 = w(kind, param, q * p, q * n);
            let w2 = w(
                kind,
                param,
                Vec3::new(p.x, -p.y, p.z),
                Vec3::new(n.x, -n.y, n.z),
            );
            assert!(
                (w0 - w1).abs() <= 1e-4 * w0.max(1.0) && (w0 - w2).abs() <= 1e-4 * w0.max(1.0),
                "{kind:?}: {w0} {w1} {w2} p={p} n={n}"
            );
        }
    }
}

#[test]
fn weight_cap_and_maximum() {
    let ward = ward_weight(Vec3::ZERO, Vec3::Z, Vec3::ZERO, Vec3::Z, R, 0.15, TOL);
    assert_eq!(ward, 1.0 / WARD_MIN_ERROR, "1/ε capped at 1000 (§7.2)");
    let near = ward_weight(
        Vec3::new(1e-6, 0.0, 0.0),
        Vec3::Z,
        Vec3::ZERO,
        Vec3::Z,
        R,
        0.15,
        TOL,
    );
    assert_eq!(near, 1.0 / WARD_MIN_ERROR);
    assert_eq!(
        tl_weight(Vec3::ZERO, Vec3::Z, Vec3::ZERO, Vec3::Z, R, 1.0, TOL),
        1.0
    );
    // R = 0 (corner, §4.6): no Inf/NaN, the weight is the cap at p_i and 0 elsewhere.
    let corner = WeightRecord {
        p: Vec3::ZERO,
        n: Vec3::Z,
        r: 0.0,
    };
    for (kind, param) in KINDS {
        let at = record_weight(kind, Vec3::ZERO, Vec3::Z, corner, param, TOL);
        let off = record_weight(kind, Vec3::X * 1e-3, Vec3::Z, corner, param, TOL);
        assert!(at.is_finite() && at > 0.0 && off == 0.0);
        assert!(
            splat_radius(kind, 0.0, param, 0.0) >= 0.0
                && splat_radius(kind, 0.0, param, 0.0) <= R_FLOOR
        );
    }
}

#[test]
fn in_front_and_normal_tests() {
    for (kind, param) in KINDS {
        let reach = splat_radius(kind, R, param, 0.0);
        let x = Vec3::X * 0.1 * reach;
        assert!(
            w(kind, param, x - Vec3::Z * (2.0 * TOL), Vec3::Z) == 0.0,
            "{kind:?}: behind the record's tangent plane"
        );
        assert!(
            w(kind, param, x - Vec3::Z * (0.5 * TOL), Vec3::Z) > 0.0,
            "{kind:?}: within the tolerance"
        );
        assert!(
            w(kind, param, x + Vec3::Z * (0.5 * TOL), Vec3::Z) > 0.0,
            "{kind:?}: in front is fine"
        );
        assert_eq!(
            w(kind, param, x, -Vec3::Z),
            0.0,
            "{kind:?}: antiparallel normal"
        );
        assert_eq!(
            w(kind, param, x, Vec3::X),
            0.0,
            "{kind:?}: perpendicular normal"
        );
        assert_eq!(w(kind, param, x, Vec3::ZERO), 0.0, "{kind:?}: zero normal");
    }
    assert!(in_front_test(
        Vec3::new(0.0, 0.0, -0.5),
        Vec3::ZERO,
        Vec3::Z,
        0.5
    ));
    assert!(
        !in_front_test(Vec3::new(0.0, 0.0, -0.5), Vec3::ZERO, Vec3::Z, -1.0),
        "negative tol = 0"
    );
    assert_eq!(normal_error(Vec3::Z, Vec3::Z), 0.0);
    assert!((normal_error(Vec3::Z, -Vec3::Z) - 2f32.sqrt()).abs() < 1e-6);
    let small = tilt(1e-3); // sqrt(1 − cos 1e-3) = 7.0711e-4; the f32 dot-product form is percent-level off here
    assert!((normal_error(small, Vec3::Z) - 7.071_067e-4).abs() < 1e-8);
    assert!(
        (normal_error(Vec3::Z * 1.01, Vec3::Z) - 0.01 / 2f32.sqrt()).abs() < 1e-6,
        "non-unit: no NaN (§7.3)"
    );
    // The out-of-plane term lowers the weight of a point above the record's plane.
    for (kind, param) in KINDS {
        let d = 0.1 * splat_radius(kind, R, param, 0.0);
        assert!(
            w(kind, param, Vec3::new(0.0, 0.0, d), Vec3::Z)
                < w(kind, param, Vec3::new(d, 0.0, 0.0), Vec3::Z)
        );
    }
}

#[test]
fn zone_boundaries_and_splat_radius() {
    // In-plane, n = n_i: Ward is valid iff ‖Δ‖ < a·R, T&L iff ‖Δ‖ < R/(2κ); splat_radius bounds
    // every point with a positive weight (or above w_min) for any normal.
    let a = 0.15;
    assert!(w(WeightKind::Ward, a, Vec3::X * (a * R * 0.999), Vec3::Z) > 0.0);
    assert_eq!(
        w(WeightKind::Ward, a, Vec3::X * (a * R * 1.001), Vec3::Z),
        0.0
    );
    assert!(
        w(WeightKind::Ward, a, Vec3::X * (a * R * 0.999), Vec3::Z) >= 1.0 / a,
        "Ward jumps from 1/a to 0"
    );
    let k = 1.0;
    assert!(
        w(
            WeightKind::TabellionLamorlette,
            k,
            Vec3::X * (R / (2.0 * k) * 0.999),
            Vec3::Z
        ) > 0.0
    );
    assert_eq!(
        w(
            WeightKind::TabellionLamorlette,
            k,
            Vec3::X * (R / (2.0 * k) * 1.001),
            Vec3::Z
        ),
        0.0
    );
    assert!(
        w(
            WeightKind::TabellionLamorlette,
            k,
            Vec3::X * (R / (2.0 * k) * 0.999),
            Vec3::Z
        ) < 0.01,
        "T&L fades to 0"
    );
    for (kind, param) in KINDS {
        assert!((splat_radius(kind, R, param, 0.0) - validity_scale(kind, param) * R).abs() < 1e-6);
        for w_min in [0.0, 0.3, 10.0] {
            let reach = splat_radius(kind, R, param, w_min);
            for i in 0..5000 {
                let h = |j: u32| unit_float_from_bits(ircache_hash(i * 5 + j)) - 0.5;
                let p = Vec3::new(h(0), h(1), 0.1 * h(2)) * 2.0 * R;
                let n = (Vec3::Z + Vec3::new(h(3), h(4), 0.0) * 0.3).normalize();
                if w(kind, param, p, n) > w_min.max(0.0) {
                    assert!(
                        p.length() <= reach * 1.0001,
                        "{kind:?} w_min={w_min}: |p| = {} > {reach}",
                        p.length()
                    );
                }
            }
        }
    }
}

#[test]
fn ward_and_tl_zone_shapes() {
    // With κ = 1/(2a) both zones are the same disk in the record's plane (for n = n_i) — the
    // documented equivalence. Under normal deviation, Ward's zone shrinks additively
    // (‖Δ‖/R < a − e_nrm) while T&L's keeps its radius until the 10°/κ cone is left.
    let a = 0.25;
    let k = 1.0 / (2.0 * a);
    for i in 0..2000 {
        let h = |j: u32| unit_float_from_bits(ircache_hash(77 + i * 2 + j));
        let p = Quat::from_rotation_z(6.3 * h(0)) * Vec3::X * (a * R * (0.9 + 0.2 * h(1)));
        let (ww, wt) = (
            w(WeightKind::Ward, a, p, Vec3::Z),
            w(WeightKind::TabellionLamorlette, k, p, Vec3::Z),
        );
        if (p.length() - a * R).abs() > 1e-4 {
            assert_eq!(ww > 0.0, wt > 0.0, "same disk at |p| = {}", p.length());
        }
    }
    let dev = 0.05f32; // radians, e_nrm ≈ 0.035 < T&L cone 0.1233/κ = 0.062
    let e_nrm = (1.0 - dev.cos()).sqrt();
    assert!(e_nrm < TL_NORMAL_SCALE / k);
    let ward_r = (a - e_nrm) * R;
    let tl_r = R / (2.0 * k);
    let n = tilt(dev);
    let yaxis = Vec3::Y; // orthogonal to the tilt: only the normal term changes
    assert!(
        w(WeightKind::Ward, a, yaxis * ward_r * 0.99, n) > 0.0
            && w(WeightKind::Ward, a, yaxis * ward_r * 1.01, n) == 0.0
    );
    assert!(w(WeightKind::TabellionLamorlette, k, yaxis * tl_r * 0.99, n) > 0.0);
    assert_eq!(
        w(WeightKind::TabellionLamorlette, k, yaxis * tl_r * 1.01, n),
        0.0
    );
}

#[test]
fn coverage_threshold_units() {
    assert_eq!(weight_unit(WeightKind::Ward, 0.2), 5.0);
    assert_eq!(weight_unit(WeightKind::TabellionLamorlette, 3.0), 1.0);
    assert_eq!(coverage_threshold(WeightKind::Ward, 0.2, 0.5), 2.5);
    assert_eq!(
        coverage_threshold(WeightKind::TabellionLamorlette, 1.0, 0.5),
        0.5
    );
    assert_eq!(
        WeightKind::from_u32(WeightKind::Ward as u32),
        WeightKind::Ward
    );
    assert_eq!(WeightKind::from_u32(7), WeightKind::default());
    assert_eq!(WeightKind::default(), WeightKind::TabellionLamorlette);
}
