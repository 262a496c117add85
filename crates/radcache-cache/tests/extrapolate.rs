//! Tests of the extrapolation (docs/irradiance-cache.md §6.1, §6.2) and the temporal formulas
//! (docs/temporal.md §3.3).

mod common;

use common::{Rect, Scene};
use glam::{DVec3, Quat, Vec3, Vec4};
use radcache_cache::extrapolate::*;
use radcache_cache::temporal::*;
use radcache_cache::EXTRAPOLATION_MAX_FACTOR;

const ZERO3: [Vec3; 3] = [Vec3::ZERO; 3];

#[test]
fn extrapolation_is_linear_with_the_right_signs() {
    let e = Vec3::new(1.0, 2.0, 3.0);
    let gt = [Vec3::X * 0.5, Vec3::X, Vec3::Y];
    let gr = [Vec3::Y * 0.2, Vec3::ZERO, Vec3::ZERO];
    let (p_i, n_i) = (Vec3::ZERO, Vec3::Z);
    assert_eq!(
        extrapolate_irradiance(e, &ZERO3, &ZERO3, Vec3::ONE, Vec3::X, p_i, n_i),
        e,
        "no gradients"
    );
    let out = extrapolate_irradiance(e, &ZERO3, &gt, Vec3::new(0.2, 0.1, 0.0), n_i, p_i, n_i);
    assert!((out - Vec3::new(1.1, 2.2, 3.1)).length() < 1e-6);
    // Tilting n toward +x is a rotation about +y: n_i × n ≈ α ŷ, so the term is α·∇_r·ŷ.
    let a = 0.1f32;
    let n = Quat::from_rotation_y(a) * n_i;
    let out = extrapolate_irradiance(e, &gr, &ZERO3, p_i, n, p_i, n_i);
    assert!((out.x - (1.0 + 0.2 * a.sin())).abs() < 1e-6 && out.y == 2.0);
}

#[test]
fn extrapolation_clamps() {
    let e = Vec3::new(1.0, 0.0, 2.0);
    let big = [Vec3::X * 100.0, Vec3::X * 100.0, Vec3::X * 100.0];
    let up = extrapolate_irradiance(e, &ZERO3, &big, Vec3::X, Vec3::Z, Vec3::ZERO, Vec3::Z);
    assert_eq!(
        up,
        Vec3::new(
            EXTRAPOLATION_MAX_FACTOR,
            0.0,
            2.0 * EXTRAPOLATION_MAX_FACTOR
        ),
        "exploding → 4·E, black stays black"
    );
    let down = extrapolate_irradiance(e, &ZERO3, &big, -Vec3::X, Vec3::Z, Vec3::ZERO, Vec3::Z);
    assert_eq!(down, Vec3::ZERO, "negative → 0");
    let neg = extrapolate_irradiance(
        Vec3::splat(-1.0),
        &ZERO3,
        &ZERO3,
        Vec3::ZERO,
        Vec3::Z,
        Vec3::ZERO,
        Vec3::Z,
    );
    assert_eq!(neg, Vec3::ZERO);
    assert_eq!(
        clamp_extrapolation(Vec3::new(-1.0, 0.5, 9.0), Vec3::ONE),
        Vec3::new(0.0, 0.5, 4.0)
    );
}

#[test]
fn gradients_improve_the_estimate_in_an_analytic_scene() {
    // End-to-end sign check: a record near an emitting wall (x = 1) under a black sky; the
    // extrapolated value at nearby points / tilted normals must beat the record's plain value.
    let wall = Rect::new(
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::Y * 2.0,
        DVec3::Z * 1.5,
        DVec3::new(1.0, 0.7, 0.4),
    );
    let scene = Scene {
        rects: vec![wall],
        sky: DVec3::new(0.05, 0.05, 0.1),
    };
    let (p_i, n_i) = (Vec3::ZERO, Vec3::Z);
    let rec = scene.record(p_i, n_i, 32, 96, 11);
    let moves = [
        (Vec3::new(0.08, 0.0, 0.0), n_i),
        (Vec3::new(-0.06, 0.05, 0.0), n_i),
        (Vec3::ZERO, Quat::from_rotation_y(0.12) * n_i),
        (
            Vec3::ZERO,
            Quat::from_rotation_y(-0.1) * Quat::from_rotation_x(0.05) * n_i,
        ),
        (
            Vec3::new(0.04, -0.03, 0.0),
            Quat::from_rotation_y(-0.08) * n_i,
        ),
    ];
    for (p, n) in moves {
        let exact = scene.irradiance(p.as_dvec3(), n.as_dvec3()).as_vec3();
        let ext = extrapolate_irradiance(rec.e, &rec.grad_r, &rec.grad_t, p, n, p_i, n_i);
        let err0 = (rec.e - exact).length();
        let err1 = (ext - exact).length();
        assert!(
            err1 < 0.5 * err0,
            "p={p} n={n}: extrapolated error {err1} vs plain {err0}"
        );
    }
}

#[test]
fn temporal_gradient_lifespan_and_value() {
    let e0 = Vec3::new(1.0, 1.0, 1.0);
    let e1 = Vec3::new(1.02, 1.01, 0.99);
    let g = temporal_gradient(e0, e1);
    assert!((g - Vec3::new(0.02, 0.01, -0.01)).length() < 1e-6);
    // τ − 1 = ΔY/Y: lifespan = a_t/|τ − 1|.
    let dy = 0.2126 * 0.02 + 0.7152 * 0.01 - 0.0722 * 0.01;
    let life = temporal_lifespan(e0, e1, 0.05, 1000.0);
    assert!((life - 0.05 / dy).abs() < 1e-3 * life, "{life}");
    assert_eq!(
        temporal_lifespan(e0, e1, 0.05, 3.0),
        3.0,
        "capped by Δt_max"
    );
    assert_eq!(
        temporal_lifespan(e0, e0, 0.05, 30.0),
        30.0,
        "static lighting lives Δt_max"
    );
    assert_eq!(
        temporal_lifespan(Vec3::ZERO, Vec3::ZERO, 0.05, 30.0),
        30.0,
        "black stays valid"
    );
    assert_eq!(
        temporal_lifespan(Vec3::ZERO, e1, 0.05, 30.0),
        0.0,
        "light appearing: refresh now"
    );
    assert_eq!(
        temporal_lifespan(e0, Vec3::ZERO, 0.05, 30.0),
        0.05,
        "light vanishing: |τ−1| = 1"
    );
    assert!(temporal_is_valid(life, life) && !temporal_is_valid(life + 0.5, life));
    assert!((temporal_extrapolate(e0, g, 3.0) - (e0 + 3.0 * g)).length() < 1e-6);
    assert_eq!(
        temporal_extrapolate(e0, g, -5.0),
        e0,
        "negative age clamps to 0"
    );
    assert_eq!(
        temporal_extrapolate(e0, -e0, 4.0),
        Vec3::ZERO,
        "never negative"
    );
    // Within the lifespan the luminance change stays within a_t (the validity criterion).
    let at = 0.05;
    let life = temporal_lifespan(e0, e1, at, 1e6);
    let y = |v: Vec3| radcache_cache::luminance_rec709(v);
    let drift = (y(temporal_extrapolate(e0, g, life)) - y(e0)).abs() / y(e0);
    assert!((drift - at).abs() < 1e-4);
}

/// The cosine-weighted fraction of the hemisphere over (0, +Z) that a sphere covers, by
/// stratified cosine-weighted directions (the exact answer to `moving_cover`'s question).
fn covered_fraction(centre: DVec3, r: f64) -> f64 {
    let side = 400;
    let mut hit = 0u32;
    for a in 0..side {
        for b in 0..side {
            let (u, v) = (
                (a as f64 + 0.5) / side as f64,
                (b as f64 + 0.5) / side as f64,
            );
            let (sin_t, phi) = (u.sqrt(), std::f64::consts::TAU * v);
            let w = DVec3::new(sin_t * phi.cos(), sin_t * phi.sin(), (1.0 - u).sqrt());
            let t = centre.dot(w);
            if t > 0.0 && (centre - w * t).length_squared() <= r * r {
                hit += 1;
            }
        }
    }
    f64::from(hit) / f64::from(side * side)
}

#[test]
fn moving_cover_is_the_covered_share_of_the_cosine_weighted_hemisphere() {
    let (p, n) = (Vec3::ZERO, Vec3::Z);
    // Wholly above the horizon: exact (k²·cos θ), checked against the integral.
    for (dir, d, r) in [
        (Vec3::Z, 2.0f32, 0.3f32),
        (Vec3::new(0.6, 0.0, 0.8), 1.0, 0.25),
        (Vec3::new(0.0, -0.8, 0.6), 3.0, 0.9),
    ] {
        let c = dir.normalize() * d;
        let got = moving_cover(p, n, c.extend(r));
        let k = r / d;
        assert!((got - k * k * dir.normalize().z).abs() < 1e-6);
        let exact = covered_fraction(c.as_dvec3(), f64::from(r));
        assert!(
            (f64::from(got) - exact).abs() < 0.02 * exact + 1e-4,
            "above: {got} against {exact}"
        );
    }
    // Across the horizon: the quadratic is within a third of the integral and continuous.
    for cos_t in [-0.2f32, 0.0, 0.15, 0.29] {
        let dir = Vec3::new((1.0 - cos_t * cos_t).sqrt(), 0.0, cos_t);
        let got = moving_cover(p, n, (dir * 1.0).extend(0.3));
        let exact = covered_fraction(dir.as_dvec3(), 0.3);
        assert!(
            (f64::from(got) - exact).abs() < 0.35 * exact + 2e-3,
            "across the horizon, cos θ = {cos_t}: {got} against {exact}"
        );
    }
    let at = |c: f32| moving_cover(p, n, Vec3::new((1.0 - c * c).sqrt(), 0.0, c).extend(0.3));
    assert!(
        (at(0.3 + 1e-4) - at(0.3 - 1e-4)).abs() < 1e-4,
        "continuous at c = k"
    );
    assert_eq!(at(-0.31), 0.0, "below the horizon");
    assert_eq!(
        moving_cover(p, n, Vec4::new(0.1, 0.0, 0.1, 0.5)),
        1.0,
        "inside"
    );
    assert_eq!(
        moving_cover(p, n, Vec4::new(0.0, 0.0, 1.0, 0.0)),
        0.0,
        "no sphere"
    );
    assert_eq!(
        moving_cover(p, n, Vec4::new(0.0, 0.0, 0.0, 0.0)),
        0.0,
        "a point at p"
    );
    // Approaching: the cover grows as 1/d².
    let near = moving_cover(p, n, Vec4::new(0.0, 0.0, 1.0, 0.1));
    let far = moving_cover(p, n, Vec4::new(0.0, 0.0, 2.0, 0.1));
    assert!((near / far - 4.0).abs() < 1e-4);
}
