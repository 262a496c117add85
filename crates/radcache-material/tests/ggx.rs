//! The GGX distribution and Smith terms (docs/materials.md §3).

mod common;

use glam::Vec3;
use radcache_material::ggx::{
    alpha_from_roughness, ggx_d, smith_g1, smith_lambda, smith_v_correlated, ALPHA_MIN,
};

fn d_at(alpha: f32, theta: f64) -> f64 {
    ggx_d(
        alpha,
        Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32),
    ) as f64
}

/// `∫ D(m)(n·m) dm = 2π ∫ D(θ) cosθ sinθ dθ = 1`, midpoint rule with 400 000 steps in θ.
#[test]
fn d_is_normalised_over_projected_area() {
    let n = 400_000;
    for alpha in [0.01f32, 0.05, 0.1, 0.3, 0.6, 1.0] {
        let h = std::f64::consts::FRAC_PI_2 / n as f64;
        let mut acc = 0.0;
        for i in 0..n {
            let t = (i as f64 + 0.5) * h;
            acc += d_at(alpha, t) * t.cos() * t.sin();
        }
        let integral = 2.0 * std::f64::consts::PI * acc * h;
        assert!(
            (integral - 1.0).abs() < 1e-3,
            "α = {alpha}: ∫ D cos = {integral}"
        );
    }
}

/// The projected-area identity `∫ D(m) max(v·m, 0) dm = (n·v)/G1(v)` (Heitz 2014, §2),
/// which ties Λ to D; 2-D midpoint rule in (θ, φ).
#[test]
fn g1_satisfies_the_projected_area_identity() {
    let (nt, np) = (4000, 256);
    for alpha in [0.1f32, 0.4, 1.0] {
        for theta_v in [0.0f32, 30.0, 60.0, 85.0] {
            let v = common::view_at(theta_v);
            let mut acc = 0.0;
            for i in 0..nt {
                let t = (i as f64 + 0.5) * std::f64::consts::FRAC_PI_2 / nt as f64;
                for j in 0..np {
                    let p = (j as f64 + 0.5) * 2.0 * std::f64::consts::PI / np as f64;
                    let m = Vec3::new(
                        (t.sin() * p.cos()) as f32,
                        (t.sin() * p.sin()) as f32,
                        t.cos() as f32,
                    );
                    acc += ggx_d(alpha, m) as f64 * (v.dot(m).max(0.0) as f64) * t.sin();
                }
            }
            let integral = acc
                * (std::f64::consts::FRAC_PI_2 / nt as f64)
                * (2.0 * std::f64::consts::PI / np as f64);
            let expected = v.z as f64 / smith_g1(alpha, v.z) as f64;
            assert!(
                (integral - expected).abs() < 2e-3 * expected.max(0.1),
                "α = {alpha}, θv = {theta_v}: {integral} vs {expected}"
            );
        }
    }
}

/// The glTF form of V equals `G2/(4 n·l n·v)` with `G2 = 1/(1 + Λ(v) + Λ(l))`, and the
/// height-correlated G2 lies between the separable `G1(l)G1(v)` and `min(G1(l), G1(v))`.
#[test]
fn v_is_the_height_correlated_smith_term() {
    for alpha in [ALPHA_MIN, 0.01, 0.2, 0.7, 1.0] {
        for &nl in &[1e-4f32, 0.05, 0.3, 0.7, 1.0] {
            for &nv in &[1e-4f32, 0.1, 0.5, 0.9, 1.0] {
                let g2 =
                    1.0 / (1.0 + smith_lambda(alpha, nl) as f64 + smith_lambda(alpha, nv) as f64);
                let v = smith_v_correlated(alpha, nl, nv) as f64;
                let from_g2 = g2 / (4.0 * nl as f64 * nv as f64);
                assert!(
                    (v - from_g2).abs() <= 1e-4 * from_g2,
                    "α {alpha} nl {nl} nv {nv}: {v} vs {from_g2}"
                );
                let (g1l, g1v) = (smith_g1(alpha, nl) as f64, smith_g1(alpha, nv) as f64);
                assert!(g2 >= g1l * g1v * (1.0 - 1e-5) && g2 <= g1l.min(g1v) * (1.0 + 1e-5));
            }
        }
    }
    assert_eq!(smith_v_correlated(0.5, 0.0, 0.5), 0.0);
    assert_eq!(smith_v_correlated(0.5, 0.5, -0.1), 0.0);
    assert_eq!(smith_g1(0.5, 1.0), 1.0);
}

#[test]
fn alpha_is_roughness_squared_with_a_floor() {
    assert_eq!(alpha_from_roughness(0.5), 0.25);
    assert_eq!(alpha_from_roughness(1.0), 1.0);
    assert_eq!(alpha_from_roughness(0.0), ALPHA_MIN);
    assert_eq!(alpha_from_roughness(2.0), 1.0);
    assert_eq!(alpha_from_roughness(-1.0), ALPHA_MIN);
    // α = 1: D is uniform over the hemisphere, 1/π.
    for t in [0.0f64, 0.5, 1.2] {
        assert!((d_at(1.0, t) - std::f64::consts::FRAC_1_PI).abs() < 1e-6);
    }
}
