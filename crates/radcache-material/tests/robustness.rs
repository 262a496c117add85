//! No NaN or Inf anywhere, zero weights below the horizon, and a pdf that covers the BRDF
//! (docs/materials.md §4.3, §5).

mod common;

use common::Rng;
use glam::Vec3;
use radcache_material::ggx::ALPHA_MIN;
use radcache_material::{brdf_eval, brdf_pdf, brdf_sample, diffuse_share, Material};

fn edge_material(rng: &mut Rng) -> Material {
    let pick = |rng: &mut Rng, xs: &[f32]| xs[(rng.next_u64() % xs.len() as u64) as usize];
    let (r1, r2, r3, r4, r5) = (rng.f32(), rng.f32(), rng.f32(), rng.f32(), rng.f32());
    Material {
        base_colour: Vec3::new(pick(rng, &[0.0, 1.0, 0.5]), r1, pick(rng, &[0.0, 1.0])),
        metallic: pick(rng, &[0.0, 1.0, 0.5, r2]),
        roughness: pick(rng, &[0.0, 1.0, 0.01, 0.03, r3]),
        ior: pick(rng, &[1.0, 1.5, 3.0, 0.8]),
        specular_factor: pick(rng, &[0.0, 1.0, r4]),
        specular_colour: Vec3::new(pick(rng, &[0.0, 1.0, 30.0]), 1.0, r5),
    }
}

fn edge_direction(rng: &mut Rng) -> Vec3 {
    let z = match rng.next_u64() % 8 {
        0 => 0.0,
        1 => 1e-7,
        2 => 1e-5,
        3 => -0.2,
        4 => 1.0,
        _ => rng.f32(),
    };
    let phi = 2.0 * std::f32::consts::PI * rng.f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn every_output_is_finite_and_non_negative() {
    let mut rng = Rng::new(99);
    let u_edges = [0.0f32, 1.0 - f32::EPSILON / 2.0, 0.5];
    for i in 0..200_000 {
        let m = edge_material(&mut rng);
        let (v, l) = (edge_direction(&mut rng), edge_direction(&mut rng));
        let f = brdf_eval(&m, v, l);
        let pdf = brdf_pdf(&m, v, l);
        assert!(
            f.is_finite() && f.min_element() >= 0.0,
            "{m:?} v {v} l {l}: f {f}"
        );
        assert!(
            pdf.is_finite() && pdf >= 0.0,
            "{m:?} v {v} l {l}: pdf {pdf}"
        );
        // Coverage: wherever the BRDF is non-zero (above the horizon), the pdf is positive.
        if f.max_element() > 0.0 {
            assert!(pdf > 0.0, "{m:?} v {v} l {l}: f {f} but pdf 0");
        }
        let u = if i % 4 == 0 {
            Vec3::new(u_edges[i % 3], u_edges[(i / 3) % 3], u_edges[(i / 9) % 3])
        } else {
            rng.vec3()
        };
        let s = brdf_sample(&m, v, u);
        assert!(
            s.l.is_finite() && (s.l.length() - 1.0).abs() < 1e-3,
            "{m:?} v {v} u {u}: l {}",
            s.l
        );
        assert!(
            s.pdf.is_finite() && s.pdf >= 0.0,
            "{m:?} v {v} u {u}: pdf {}",
            s.pdf
        );
        assert!(
            s.weight.is_finite() && s.weight.min_element() >= 0.0,
            "{m:?} v {v} u {u}: weight {}",
            s.weight
        );
        if s.l.z <= 0.0 || v.z <= 0.0 {
            assert_eq!(s.weight, Vec3::ZERO, "below the horizon");
        }
        let share = diffuse_share(&m, v.z);
        assert!(share.is_finite() && (0.0..=1.0).contains(&share));
    }
}

/// At the horizon (`n·v = 0`) and below, everything is zero; roughness 0 is α = ALPHA_MIN.
#[test]
fn horizon_and_mirror_limits() {
    let m = Material::metal_rough(Vec3::ONE, 0.0, 0.0);
    let grazing = Vec3::X;
    let l = Vec3::new(0.0, 0.6, 0.8);
    assert_eq!(brdf_eval(&m, grazing, l), Vec3::ZERO);
    assert_eq!(brdf_eval(&m, l, grazing), Vec3::ZERO);
    assert_eq!(brdf_pdf(&m, grazing, l), 0.0);
    let s = brdf_sample(&m, grazing, Vec3::splat(0.3));
    assert_eq!((s.pdf, s.weight), (0.0, Vec3::ZERO));
    assert_eq!(diffuse_share(&m, 0.0), 0.0);
    // The mirror peak of roughness 0 is the one of α = ALPHA_MIN: D(n) = 1/(π α²).
    let peak = radcache_material::ggx::ggx_d(ALPHA_MIN, Vec3::Z);
    assert!((peak - 1.0 / (std::f32::consts::PI * ALPHA_MIN * ALPHA_MIN)).abs() < 1.0);
    let f = brdf_eval(
        &Material::metal_rough(Vec3::ONE, 1.0, 0.0),
        Vec3::Z,
        Vec3::Z,
    );
    assert!(
        f.is_finite() && f.x > 1e4,
        "a near-mirror's peak is large and finite: {f}"
    );
}
