//! Schlick Fresnel and the F0 terms (docs/materials.md §2).

use glam::Vec3;
use radcache_material::fresnel::{dielectric_f0, f0_from_ior, fresnel_schlick, schlick_weight};

#[test]
fn schlick_endpoints_are_f0_and_f90() {
    for f0 in [
        Vec3::splat(0.04),
        Vec3::new(0.9, 0.6, 0.3),
        Vec3::ZERO,
        Vec3::ONE,
    ] {
        for f90 in [1.0, 0.5, 0.0] {
            assert_eq!(fresnel_schlick(f0, f90, 1.0), f0, "F(1) = F0");
            assert!(
                (fresnel_schlick(f0, f90, 0.0) - Vec3::splat(f90))
                    .abs()
                    .max_element()
                    < 1e-7,
                "F(0) = F90"
            );
        }
    }
}

#[test]
fn schlick_is_monotone_and_bounded() {
    let f0 = Vec3::new(0.04, 0.5, 0.95);
    let mut prev = fresnel_schlick(f0, 1.0, 0.0);
    for i in 1..=1000 {
        let c = i as f32 / 1000.0;
        let f = fresnel_schlick(f0, 1.0, c);
        assert!(
            f.cmple(prev + Vec3::splat(1e-7)).all(),
            "F decreasing in cos at {c}"
        );
        assert!(f.cmpge(f0 - Vec3::splat(1e-7)).all() && f.cmple(Vec3::ONE).all());
        prev = f;
    }
    // Clamped outside [0, 1].
    assert_eq!(schlick_weight(-0.5), 1.0);
    assert_eq!(schlick_weight(1.5), 0.0);
    assert!((schlick_weight(0.5) - 0.03125).abs() < 1e-7);
}

#[test]
fn f0_from_ior_matches_the_specification() {
    assert!(
        (f0_from_ior(1.5) - 0.04).abs() < 1e-7,
        "glTF default ior 1.5 → 0.04"
    );
    assert_eq!(f0_from_ior(1.0), 0.0);
    assert_eq!(f0_from_ior(0.5), 0.0, "ior below 1 clamped");
    assert!((f0_from_ior(2.0) - 1.0 / 9.0).abs() < 1e-7);
    // KHR_materials_specular: coloured F0, clamped to 1.
    let f0 = dielectric_f0(1.5, Vec3::new(1.0, 0.5, 100.0));
    assert!((f0 - Vec3::new(0.04, 0.02, 1.0)).abs().max_element() < 1e-7);
}
