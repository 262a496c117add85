//! The GLSL twins of radcache-material's `sh` and `glossy` (`shaders/common/sh.glsl`,
//! `shaders/common/glossy.glsl`) evaluated ON LAVAPIPE against the Rust functions over tables of
//! inputs (`shaders/tests/sh_twin.comp`, one row per invocation): the basis and the projection of
//! a sample at random and axis-aligned directions; the view frame (with the view along the normal,
//! where it falls back), the frame values, the reconstruction and the glossy radiance for random
//! coefficient vectors, normals, views (grazing ones and ones below the horizon) and materials
//! over the table's roughness range. The glossy table is the one Rust builds
//! (`glossy_table(GLOSSY_TABLE_STRATA)`), uploaded as the harness's sample buffer.
//!
//! Tolerance: the harness's `|gpu − cpu| <= 1e-5 · max(|cpu|, scale) + 1e-6`, with `scale` the
//! sum of the magnitudes of the terms a result adds up (the sums cancel).

use glam::Vec3;
use radcache_material::glossy::{
    glossy_lookup, glossy_radiance, glossy_table, glossy_weights, glossy_world_weights,
    GLOSSY_TABLE_STRATA,
};
use radcache_material::sh::{
    sh_basis, sh_basis_one, sh_frame_values, sh_project_add, sh_reconstruct, sh_view_frame, ShRgb,
    SH_COEFFS,
};
use radcache_material::Material;
use radcache_tests::twin::{
    check_diffs, twin_pipeline, unit, v4, vec, Case, Expect, Row, ShTwinMode,
};
use radcache_tests::{context, finish, Rng};

fn pack(row: &mut Row, first: usize, c: &ShRgb) {
    for (i, ci) in c.iter().enumerate() {
        for k in 0..3 {
            let f = 3 * i + k;
            row[first + f / 4][f % 4] = ci[k];
        }
    }
}

/// The expected coefficients in the packed layout, each within `scale[i]`.
fn expect_packed(e: &mut Expect, first: usize, c: &ShRgb, scale: &[f32; SH_COEFFS]) {
    for (i, ci) in c.iter().enumerate() {
        for k in 0..3 {
            let f = 3 * i + k;
            e.f(first + f / 4, f % 4, ci[k], scale[i]);
        }
    }
}

fn coeffs(rng: &mut Rng, s: f32) -> ShRgb {
    std::array::from_fn(|_| vec(rng, s))
}

fn direction(rng: &mut Rng, i: u32) -> Vec3 {
    match i % 9 {
        0 => Vec3::X,
        1 => -Vec3::Y,
        2 => Vec3::Z,
        3 => Vec3::new(1.0, 1.0, 1.0).normalize(),
        _ => unit(rng),
    }
}

fn basis_cases(rng: &mut Rng) -> Vec<Case> {
    (0..400u32)
        .map(|i| {
            let d = direction(rng, i);
            let weight = rng.range(0.0, 3.0);
            let value = vec(rng, 2.0).abs();
            let c = coeffs(rng, 1.0);
            let mut row: Row = [[0.0; 4]; 16];
            row[0] = v4(d, weight);
            row[1] = v4(value, 0.0);
            pack(&mut row, 4, &c);
            let mut e = Expect::new();
            for (k, y) in sh_basis(d).iter().enumerate() {
                e.f(k / 4, k % 4, *y, 1.0);
            }
            let mut projected = c;
            sh_project_add(&mut projected, d, value, weight);
            let y = sh_basis(d);
            let scale: [f32; SH_COEFFS] = std::array::from_fn(|k| {
                c[k].abs().max_element() + (value * weight * y[k]).abs().max_element()
            });
            expect_packed(&mut e, 4, &projected, &scale);
            (row, e)
        })
        .collect()
}

/// The world weights for the glossy rows' inputs (mode `Weights`), each within the sum of the
/// magnitudes of its terms.
fn weight_cases(glossy: &[Case], table: &[f32]) -> Vec<Case> {
    glossy
        .iter()
        .map(|(row, _)| {
            let n = Vec3::from_slice(&row[0][..3]);
            let v = Vec3::from_slice(&row[1][..3]);
            let m = Material {
                base_colour: Vec3::from_slice(&row[2][..3]),
                metallic: row[1][3],
                roughness: row[0][3],
                ior: row[2][3],
                specular_factor: row[3][3],
                specular_colour: Vec3::from_slice(&row[3][..3]),
            };
            let w = glossy_world_weights(table, &m, n, v);
            let g = glossy_lookup(table, m.roughness, n.dot(v));
            let (k0, k1) = glossy_weights(&m);
            let total: f32 = (0..SH_COEFFS)
                .map(|k| k0.max_element() * g[k].abs() + k1 * g[SH_COEFFS + k].abs())
                .sum();
            let mut e = Expect::new();
            expect_packed(&mut e, 4, &w, &[total * 2.0; SH_COEFFS]);
            (*row, e)
        })
        .collect()
}

fn glossy_cases(rng: &mut Rng, table: &[f32]) -> Vec<Case> {
    (0..600u32)
        .map(|i| {
            let n = direction(rng, i);
            let v = match i % 7 {
                // Along the normal: the frame's fallback tangent.
                0 => n,
                // Grazing, and below the horizon.
                1 => (n.any_orthonormal_vector() + n * 0.01).normalize(),
                2 => (n.any_orthonormal_vector() - n * 0.3).normalize(),
                _ => (unit(rng) + n * 1.2).normalize(),
            };
            let roughness = rng.range(0.55, 1.0);
            let m = Material {
                base_colour: vec(rng, 1.0).abs(),
                metallic: [0.0, 1.0, 0.5][i as usize % 3],
                roughness,
                ior: rng.range(1.0, 2.0),
                specular_factor: rng.range(0.0, 1.0),
                specular_colour: vec(rng, 1.0).abs(),
            };
            let c = coeffs(rng, 1.0);
            let mut row: Row = [[0.0; 4]; 16];
            row[0] = v4(n, m.roughness);
            row[1] = v4(v, m.metallic);
            row[2] = v4(m.base_colour, m.ior);
            row[3] = v4(m.specular_colour, m.specular_factor);
            pack(&mut row, 4, &c);

            let mut e = Expect::new();
            let (t, b, nn) = sh_view_frame(n, v);
            e.v(1, t, 1.0);
            e.v(2, b, 1.0);
            let y = sh_basis(n);
            let rec_scale: f32 = (0..SH_COEFFS)
                .map(|k| (c[k] * y[k]).abs().max_element())
                .sum();
            e.v(3, sh_reconstruct(&c, n), rec_scale);
            let values = sh_frame_values(&c, t, b, nn);
            let value_scale =
                [c.iter().map(|x| x.abs().max_element()).sum::<f32>() * 3.0; SH_COEFFS];
            expect_packed(&mut e, 4, &values, &value_scale);
            let radiance = glossy_radiance(table, &m, n, v, &c);
            let g = glossy_lookup(table, m.roughness, n.dot(v));
            let (k0, k1) = glossy_weights(&m);
            let scale: f32 = (0..SH_COEFFS)
                .map(|k| {
                    values[k].abs().max_element()
                        * (k0.max_element() * g[k].abs() + k1 * g[SH_COEFFS + k].abs())
                })
                .sum::<f32>()
                * 2.0;
            e.v(0, radiance, scale);
            (row, e)
        })
        .collect()
}

#[test]
fn the_glsl_spherical_harmonics_match_the_rust_twin() {
    let ctx = context();
    let pl = twin_pipeline(&ctx, "sh_twin.comp", "sh_twin");
    let table = glossy_table(GLOSSY_TABLE_STRATA);
    let samples: Vec<[f32; 4]> = table
        .chunks(4)
        .map(|c| std::array::from_fn(|k| c.get(k).copied().unwrap_or(0.0)))
        .collect();
    let mut rng = Rng::new(29);
    let basis = basis_cases(&mut rng);
    let d = check_diffs(&ctx, &pl, ShTwinMode::Basis, &basis, &samples);
    let worst = |slots: std::ops::Range<usize>| {
        slots
            .flat_map(|s| d[s].iter().map(|x| x.of_tolerance).collect::<Vec<_>>())
            .fold(0.0f32, f32::max)
    };
    eprintln!(
        "sh_basis: {:.3} of the tolerance; sh_project_add {:.3}",
        worst(0..4),
        worst(4..16)
    );
    let one: Vec<Case> = basis
        .iter()
        .map(|(row, _)| {
            let d = Vec3::from_slice(&row[0][..3]);
            let mut e = Expect::new();
            for k in 0..=SH_COEFFS {
                e.f(k / 4, k % 4, sh_basis_one(k, d), 1.0);
            }
            (*row, e)
        })
        .collect();
    check_diffs(&ctx, &pl, ShTwinMode::BasisOne, &one, &samples);
    let glossy = glossy_cases(&mut rng, &table);
    let d = check_diffs(&ctx, &pl, ShTwinMode::Glossy, &glossy, &samples);
    let worst = |slots: std::ops::Range<usize>| {
        slots
            .flat_map(|s| d[s].iter().map(|x| x.of_tolerance).collect::<Vec<_>>())
            .fold(0.0f32, f32::max)
    };
    eprintln!(
        "glossy_radiance {:.3}, sh_view_frame {:.3}, sh_reconstruct {:.3}, sh_frame_values {:.3} of the tolerance",
        worst(0..1),
        worst(1..3),
        worst(3..4),
        worst(4..16)
    );
    let weights = weight_cases(&glossy, &table);
    let d = check_diffs(&ctx, &pl, ShTwinMode::Weights, &weights, &samples);
    let w = (4..16)
        .flat_map(|s| d[s].iter().map(|x| x.of_tolerance).collect::<Vec<_>>())
        .fold(0.0f32, f32::max);
    eprintln!("glossy_world_weights {w:.3} of the tolerance");
    // Some glossy rows reflect light: the comparison is not of zeros only.
    let lit = glossy
        .iter()
        .filter(|(_, e)| e.v[0][0].abs() + e.v[0][1].abs() + e.v[0][2].abs() > 1e-3)
        .count();
    assert!(lit > 300, "{lit} rows reflect light");
    finish(ctx);
}
