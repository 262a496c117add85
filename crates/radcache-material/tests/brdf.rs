//! The BRDF: reciprocity, the Lambertian limit, the white furnace (docs/materials.md §4).

mod common;

use common::{albedo, specular_albedo, view_at, Rng};
use glam::Vec3;
use radcache_material::fresnel::fresnel_schlick;
use radcache_material::{brdf_eval, Material};

fn random_material(rng: &mut Rng) -> Material {
    Material {
        base_colour: rng.vec3(),
        metallic: rng.f32(),
        roughness: rng.f32(),
        ior: 1.0 + 1.5 * rng.f32(),
        specular_factor: rng.f32(),
        specular_colour: rng.vec3() * 2.0,
    }
}

#[test]
fn brdf_is_reciprocal() {
    let mut rng = Rng::new(17);
    for _ in 0..20_000 {
        let m = random_material(&mut rng);
        let (v, l) = (rng.hemisphere(), rng.hemisphere());
        let (a, b) = (brdf_eval(&m, v, l), brdf_eval(&m, l, v));
        let scale = a.abs().max(b.abs()).max_element();
        assert!(
            (a - b).abs().max_element() <= 1e-4 * scale + 1e-7,
            "{m:?} v {v} l {l}: {a} vs {b}"
        );
        assert!(a.is_finite() && a.min_element() >= 0.0);
    }
}

/// Roughness 1, metallic 0 and no specular layer (ior 1 gives F0 = 0, and `KHR_materials_specular`
/// factor 0 removes the layer including its grazing `(1 − v·h)^5` term): exactly `base/π`.
#[test]
fn rough_dielectric_without_specular_is_lambertian() {
    let mut rng = Rng::new(3);
    let base = Vec3::new(0.8, 0.5, 0.2);
    let m = Material {
        ior: 1.0,
        specular_factor: 0.0,
        ..Material::metal_rough(base, 0.0, 1.0)
    };
    for _ in 0..10_000 {
        let (v, l) = (rng.hemisphere(), rng.hemisphere());
        if v.z < 1e-5 || l.z < 1e-5 {
            continue;
        }
        let f = brdf_eval(&m, v, l);
        assert!(
            (f - base * std::f32::consts::FRAC_1_PI).abs().max_element() < 1e-7,
            "{f}"
        );
    }
    // With ior 1 alone (F0 = 0, F90 = 1) only the Schlick grazing term remains: at normal
    // view and light v·h = 1, so F = 0 and the BRDF is base/π there too.
    let m1 = Material {
        ior: 1.0,
        ..Material::metal_rough(base, 0.0, 1.0)
    };
    let f = brdf_eval(&m1, Vec3::Z, Vec3::Z);
    assert!(
        (f - base * std::f32::consts::FRAC_1_PI).abs().max_element() < 1e-7,
        "{f}"
    );
}

const ROUGHNESS: [f32; 8] = [0.0, 0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0];
const THETA_V: [f32; 7] = [0.0, 20.0, 40.0, 60.0, 75.0, 85.0, 89.0];

/// White furnace: base colour 1, the directional albedo `∫ f (n·l) dl` (printed with
/// `--nocapture`; `1 − albedo` of the metal is its single-scattering energy loss).
///
/// * A metal, and a dielectric without specular layer, never exceed 1 (plus the quadrature
///   tolerance 2·10⁻³), at every roughness and angle.
/// * A dielectric follows the specification's `fresnel_mix`, which weights the diffuse base by
///   `1 − F(v·h)` per light direction while the specular layer reflects about `F(n·v)`: it is
///   conservative up to θv = 40° (asserted ≤ 1.002) but gains energy at oblique views, most for
///   smooth surfaces (measured 1.025 at θv 60°, 1.20 at 75°, 1.85 at 89°, roughness 0, ior 1.5;
///   docs/materials.md §4.4). Beyond 40° the measured figures are pinned (≤ `grazing`) so that
///   a change that makes the model less conservative fails.
#[test]
fn white_furnace_albedo() {
    let materials = [
        ("metal", Material::metal_rough(Vec3::ONE, 1.0, 0.0), 1.002),
        (
            "dielectric",
            Material::metal_rough(Vec3::ONE, 0.0, 0.0),
            1.86,
        ),
        ("half", Material::metal_rough(Vec3::ONE, 0.5, 0.0), 1.43),
        (
            "ior 2.5",
            Material {
                ior: 2.5,
                ..Material::metal_rough(Vec3::ONE, 0.0, 0.0)
            },
            1.73,
        ),
        (
            "no spec",
            Material {
                specular_factor: 0.0,
                ..Material::metal_rough(Vec3::ONE, 0.0, 0.0)
            },
            1.002,
        ),
    ];
    for (name, base, grazing) in materials {
        let mut max = 0.0f64;
        for r in ROUGHNESS {
            let m = Material {
                roughness: r,
                ..base
            };
            let mut row = String::new();
            for t in THETA_V {
                let a = albedo(&m, view_at(t));
                let bound = if t <= 40.0 { 1.002 } else { grazing };
                assert!(
                    a.iter().all(|&x| x <= bound && x >= 0.0),
                    "{name} roughness {r} θv {t}: albedo {a:?} > {bound}"
                );
                max = max.max(a[0]);
                row += &format!(" {:.4}", a[0]);
            }
            eprintln!("{name:>10} roughness {r:.2}: albedo at θv {THETA_V:?} ={row}");
        }
        eprintln!("{name:>10}: maximum albedo {max:.4}");
    }
}

/// A metal with roughness → 0 becomes a mirror: its albedo approaches `F(n·v)` (within 1%, up to
/// θv = 60°; the shadowing of a near-mirror removes more at grazing angles).
#[test]
fn smooth_metal_albedo_approaches_fresnel() {
    let base = Vec3::new(0.9, 0.6, 0.3);
    for r in [0.0f32, 0.05] {
        let m = Material::metal_rough(base, 1.0, r);
        for t in [0.0f32, 30.0, 60.0] {
            let v = view_at(t);
            let a = specular_albedo(&m, v, 2048, 256);
            let f = fresnel_schlick(base, 1.0, v.z);
            for c in 0..3 {
                assert!(
                    (a[c] - f[c] as f64).abs() < 0.01 * f[c] as f64,
                    "roughness {r} θv {t} channel {c}: {} vs {}",
                    a[c],
                    f[c]
                );
            }
        }
    }
}
