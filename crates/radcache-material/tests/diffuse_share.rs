//! The diffuse share factor of the cached indirect light (docs/materials.md §6), against the
//! exact diffuse albedo under uniform incident light.

mod common;

use common::{diffuse_albedo, view_at};
use glam::Vec3;
use radcache_material::{diffuse_share, Material};

#[test]
fn diffuse_share_limits() {
    let metal = Material::metal_rough(Vec3::ONE, 1.0, 0.5);
    assert_eq!(
        diffuse_share(&metal, 0.7),
        0.0,
        "a metal has no diffuse lobe"
    );
    let no_spec = Material {
        specular_factor: 0.0,
        ..Material::metal_rough(Vec3::ONE, 0.0, 0.5)
    };
    assert_eq!(
        diffuse_share(&no_spec, 0.3),
        1.0,
        "no specular layer: all diffuse"
    );
    let d = Material::metal_rough(Vec3::ONE, 0.0, 0.5);
    assert!(
        (diffuse_share(&d, 1.0) - 0.96).abs() < 1e-4,
        "≈ 1 − F0 at normal view"
    );
    let half = Material::metal_rough(Vec3::ONE, 0.5, 0.5);
    assert!(
        (diffuse_share(&half, 1.0) - 0.48).abs() < 1e-4,
        "≈ (1 − metallic)(1 − F0)"
    );
}

/// Under uniform incident light the exact factor is the diffuse albedo of a white base,
/// `(1 − metallic) ∫ (1 − s·max F_d(v·h)) (n·l)/π dl` (quadrature, 512²), which the factor must
/// match within 2·10⁻⁴ at every view angle (measured figures printed with `--nocapture`).
#[test]
fn diffuse_share_is_exact_under_uniform_light() {
    for (name, m) in [
        ("ior 1.5", Material::metal_rough(Vec3::ONE, 0.0, 0.5)),
        (
            "ior 2.5",
            Material {
                ior: 2.5,
                ..Material::metal_rough(Vec3::ONE, 0.0, 0.5)
            },
        ),
        (
            "ior 1",
            Material {
                ior: 1.0,
                ..Material::metal_rough(Vec3::ONE, 0.0, 0.5)
            },
        ),
        (
            "coloured",
            Material {
                specular_factor: 0.5,
                specular_colour: Vec3::new(3.0, 1.0, 0.5),
                ..Material::metal_rough(Vec3::ONE, 0.3, 0.5)
            },
        ),
    ] {
        let mut row = String::new();
        let mut max_err = 0.0f64;
        for t in [0.0f32, 15.0, 30.0, 45.0, 60.0, 70.0, 80.0, 85.0, 88.0, 89.5] {
            let v = view_at(t);
            let exact = diffuse_albedo(&m, v, 512)[0];
            let share = diffuse_share(&m, v.z) as f64;
            row += &format!(" {t}°: {share:.5}/{exact:.5}");
            max_err = max_err.max((share - exact).abs());
            assert!(
                (share - exact).abs() <= 2e-4,
                "{name} θv {t}: share {share} vs exact {exact}"
            );
        }
        eprintln!("{name}: share/exact{row}; max error {max_err:.1e}");
    }
}

/// The fit of `W(n·v)` against its own quadrature (1-D check of the polynomial).
#[test]
fn schlick_hemispherical_mean_matches_quadrature() {
    let white_no_f0 = Material {
        ior: 1.0,
        ..Material::metal_rough(Vec3::ONE, 0.0, 0.5)
    };
    for i in 0..=20 {
        let nv = i as f32 / 20.0;
        let v = Vec3::new((1.0 - nv * nv).sqrt(), 0.0, nv);
        if v.z < 1e-3 {
            continue;
        }
        // ior 1, s = 1: diffuse albedo = 1 − W(n·v).
        let w = 1.0 - diffuse_albedo(&white_no_f0, v, 512)[0];
        let fit = radcache_material::brdf::schlick_hemispherical_mean(nv) as f64;
        assert!(
            (w - fit).abs() < 2e-5,
            "n·v {nv}: quadrature {w} vs fit {fit}"
        );
    }
}
