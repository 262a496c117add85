//! BRDF sampling: pdf normalisation, χ² of the sampler against its pdf, and the Monte Carlo
//! estimator against the quadrature of the albedo (docs/materials.md §5).

mod common;

use common::{albedo, chi2_statistic, chi2_survival, view_at, Rng};
use glam::Vec3;
use radcache_material::ggx::alpha_from_roughness;
use radcache_material::sampling::{ggx_reflection_pdf, ggx_vndf_pdf, reflect, sample_ggx_vndf};
use radcache_material::{brdf_pdf, brdf_sample, Material};

fn sphere_dir(z: f64, phi: f64) -> Vec3 {
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
}

/// `∫ pdf(l) dl = 1` over the sphere (midpoint rule in (z, φ), dl = dz dφ), for the GGX
/// reflection pdf alone and for the lobe mixture.
#[test]
fn pdfs_integrate_to_one_over_the_sphere() {
    let (nz, np) = (4000, 512);
    for r in [0.45f32, 0.7, 1.0] {
        let alpha = alpha_from_roughness(r);
        for t in [0.0f32, 45.0, 80.0] {
            let v = view_at(t);
            let m = Material::metal_rough(Vec3::new(0.7, 0.5, 0.3), 0.3, r);
            let (mut a_spec, mut a_mix) = (0.0f64, 0.0f64);
            for i in 0..nz {
                let z = -1.0 + 2.0 * (i as f64 + 0.5) / nz as f64;
                for j in 0..np {
                    let l =
                        sphere_dir(z, 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64);
                    a_spec += ggx_reflection_pdf(alpha, v, l) as f64;
                    a_mix += brdf_pdf(&m, v, l) as f64;
                }
            }
            let w = 2.0 * 2.0 * std::f64::consts::PI / (nz * np) as f64;
            let (a_spec, a_mix) = (a_spec * w, a_mix * w);
            assert!(
                (a_spec - 1.0).abs() < 3e-3,
                "roughness {r} θv {t}: ∫ GGX pdf = {a_spec}"
            );
            assert!(
                (a_mix - 1.0).abs() < 3e-3,
                "roughness {r} θv {t}: ∫ mixture pdf = {a_mix}"
            );
        }
    }
}

/// The visible-normal sampler's own density: `E[g(m)/D_v(m)]` over its samples equals the area of
/// the region `g` selects where `D_v > 0`; with `g = 1` on the cone of half-angle 25° around n (all
/// of it visible, `v·m > 0`, for θv ≤ 60°), the estimate of its solid angle `2π(1 − cos 25°)` must
/// come out within 4 standard errors.
#[test]
fn vndf_sampler_matches_its_density() {
    let mut rng = Rng::new(7);
    let n = 200_000;
    let cos_cone = 25.0f32.to_radians().cos();
    // α ≥ 0.2: for smaller α the density on the cone's rim is so small that 1/D_v is heavy-tailed
    // and the sample variance is not a usable error bound (the χ² test covers small α).
    for alpha in [0.2f32, 0.5, 1.0] {
        for t in [0.0f32, 30.0, 60.0] {
            let v = view_at(t);
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let m = sample_ggx_vndf(alpha, v, rng.f32(), rng.f32());
                assert!(v.dot(m) >= -1e-6 && m.z >= 0.0);
                let x = if m.z >= cos_cone {
                    1.0 / ggx_vndf_pdf(alpha, v, m) as f64
                } else {
                    0.0
                };
                s += x;
                s2 += x * x;
            }
            let mean = s / n as f64;
            let se = ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            let exact = 2.0 * std::f64::consts::PI * (1.0 - cos_cone as f64);
            assert!(
                (mean - exact).abs() <= 4.0 * se + 1e-3,
                "α {alpha} θv {t}: {mean} ± {se} vs {exact}"
            );
        }
    }
}

/// χ² test of `brdf_sample` against `brdf_pdf` over the sphere (24 × 48 equal-area cells in
/// (z, φ), expected counts by 10 × 10 sub-cell quadrature, cells with expected < 5 pooled),
/// 27 configurations × 300 000 samples, fixed seeds; each p-value must exceed the Šidák-corrected
/// 1% level `1 − 0.99^(1/27)`.
#[test]
fn brdf_sampling_passes_chi2() {
    let (nz, np, sub, n) = (24usize, 48usize, 10usize, 300_000usize);
    let materials = [
        Material::metal_rough(Vec3::new(0.9, 0.6, 0.3), 1.0, 0.0),
        Material::metal_rough(Vec3::new(0.8, 0.8, 0.8), 0.0, 0.0),
        Material {
            ior: 2.0,
            specular_colour: Vec3::new(1.0, 0.5, 0.5),
            ..Material::metal_rough(Vec3::new(0.2, 0.5, 0.7), 0.4, 0.0)
        },
    ];
    let configs = 27.0;
    let level = 1.0 - 0.99f64.powf(1.0 / configs);
    let mut seed = 100;
    for base in materials {
        for r in [0.4f32, 0.7, 1.0] {
            for t in [10.0f32, 50.0, 80.0] {
                let m = Material {
                    roughness: r,
                    ..base
                };
                let v = view_at(t);
                let mut expected = vec![0.0f64; nz * np];
                let cell = (2.0 / nz as f64) * (2.0 * std::f64::consts::PI / np as f64);
                for iz in 0..nz {
                    for ip in 0..np {
                        let mut acc = 0.0;
                        for a in 0..sub {
                            let z = -1.0
                                + (iz as f64 + (a as f64 + 0.5) / sub as f64) * 2.0 / nz as f64;
                            for b in 0..sub {
                                let phi = (ip as f64 + (b as f64 + 0.5) / sub as f64)
                                    * 2.0
                                    * std::f64::consts::PI
                                    / np as f64;
                                acc += brdf_pdf(&m, v, sphere_dir(z, phi)) as f64;
                            }
                        }
                        expected[iz * np + ip] = acc / (sub * sub) as f64 * cell * n as f64;
                    }
                }
                let mut observed = vec![0.0f64; nz * np];
                seed += 1;
                let mut rng = Rng::new(seed);
                for _ in 0..n {
                    let s = brdf_sample(&m, v, rng.vec3());
                    let l = s.l;
                    let iz = (((l.z as f64 + 1.0) * 0.5 * nz as f64) as usize).min(nz - 1);
                    let phi = (l.y as f64)
                        .atan2(l.x as f64)
                        .rem_euclid(2.0 * std::f64::consts::PI);
                    let ip =
                        ((phi / (2.0 * std::f64::consts::PI) * np as f64) as usize).min(np - 1);
                    observed[iz * np + ip] += 1.0;
                }
                let (chi2, dof) = chi2_statistic(&observed, &expected);
                let p = chi2_survival(chi2, dof as f64);
                eprintln!("chi2 {m:?} θv {t}: χ² {chi2:.1}, dof {dof}, p {p:.3}");
                assert!(dof > 30, "too few cells");
                assert!(p > level, "roughness {r} θv {t} {m:?}: χ² {chi2:.1} with {dof} dof, p = {p:.2e} < {level:.2e}");
            }
        }
    }
}

/// The estimator `f·cos/pdf` averaged over 200 000 samples equals the quadrature of the albedo
/// within `5·σ/√N + 3·10⁻³` (σ the sample standard deviation; 3·10⁻³ the quadrature tolerance).
#[test]
fn sampling_estimator_matches_quadrature_albedo() {
    let n = 200_000;
    let materials = [
        Material::metal_rough(Vec3::new(0.9, 0.6, 0.3), 1.0, 0.0),
        Material::metal_rough(Vec3::new(0.8, 0.3, 0.1), 0.0, 0.0),
        Material {
            specular_factor: 0.5,
            ..Material::metal_rough(Vec3::new(0.5, 0.7, 0.9), 0.5, 0.0)
        },
    ];
    let mut seed = 1000;
    for base in materials {
        for r in [0.0f32, 0.1, 0.3, 0.6, 1.0] {
            for t in [0.0f32, 45.0, 75.0] {
                let m = Material {
                    roughness: r,
                    ..base
                };
                let v = view_at(t);
                let quad = albedo(&m, v);
                seed += 1;
                let mut rng = Rng::new(seed);
                let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
                for _ in 0..n {
                    let w = brdf_sample(&m, v, rng.vec3()).weight;
                    for c in 0..3 {
                        s[c] += w[c] as f64;
                        s2[c] += (w[c] as f64).powi(2);
                    }
                }
                for c in 0..3 {
                    let mean = s[c] / n as f64;
                    let sd = (s2[c] / n as f64 - mean * mean).max(0.0).sqrt();
                    let bound = 5.0 * sd / (n as f64).sqrt() + 3e-3;
                    assert!((mean - quad[c]).abs() <= bound, "roughness {r} θv {t} channel {c} {m:?}: MC {mean} vs quadrature {} (bound {bound})", quad[c]);
                }
            }
        }
    }
}

/// The reflected direction of a visible normal is consistent with the reflection pdf:
/// `ggx_reflection_pdf(l) = D_v(h)/(4 v·h)`.
#[test]
fn reflection_pdf_is_the_vndf_jacobian() {
    let mut rng = Rng::new(5);
    for _ in 0..10_000 {
        let alpha = alpha_from_roughness(rng.f32());
        let v = rng.hemisphere();
        if v.z < 1e-3 {
            continue;
        }
        let m = sample_ggx_vndf(alpha, v, rng.f32(), rng.f32());
        let l = reflect(v, m);
        let vh = v.dot(m);
        if vh < 1e-3 {
            continue;
        }
        let a = ggx_reflection_pdf(alpha, v, l) as f64;
        let b = ggx_vndf_pdf(alpha, v, (v + l).normalize()) as f64 / (4.0 * vh as f64);
        assert!(
            (a - b).abs() <= 2e-3 * a.max(b),
            "α {alpha} v {v}: {a} vs {b}"
        );
    }
}
