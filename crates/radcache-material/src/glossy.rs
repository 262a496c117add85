//! The specular lobe against spherical-harmonic radiance (`docs/radiance-caching.md` §3): the
//! table of the lobe's projection onto bands 0–3 per roughness and view angle, its lookup, and the
//! reflected radiance of a radiance record at a pixel.
//!
//! The specular lobe of [`crate::brdf_eval_lobes`] is
//! `(metallic·F_m + (1 − metallic)·s·F_d) · D · V` with Schlick's `F = F0 + (1 − F0)·w`,
//! `w = (1 − v·h)^5`. It splits into two scalar lobes with colour weights:
//!
//! ```text
//! specular = K0 · D·V·(1 − w)  +  K1 · D·V·w
//! K0 = metallic·base + (1 − metallic)·s·F0_d        (RGB)
//! K1 = metallic + (1 − metallic)·s                   (F90 = 1 for both layers)
//! ```
//!
//! so a table of the projections `A_i = ∫ D·V·(1 − w)·(n·l)·Y_i(l) dl` and
//! `B_i = ∫ D·V·w·(n·l)·Y_i(l) dl` over roughness and `n·v` (in the local frame of
//! [`crate::sh::sh_view_frame`]) serves every material. The table stores them as frame weights
//! ([`crate::sh::sh_frame_weights`]): the composite reads the world-space coefficients at nine
//! directions of the pixel's frame and needs no rotation matrix.

use glam::Vec3;

use crate::fresnel::dielectric_f0;
use crate::ggx::{alpha_from_roughness, ggx_d, smith_v_correlated};
use crate::sampling::{ggx_reflection_pdf, reflect, sample_ggx_vndf};
use crate::sh::{
    sh_band, sh_basis, sh_frame_weights, sh_view_frame, ShRgb, SH_COEFFS, SH_FRAME_DIRS,
};
use crate::Material;
use radcache_shared::consts::{GLOSSY_NV_MIN, GLOSSY_TABLE_NV, GLOSSY_TABLE_ROUGHNESS};

/// Strata per axis of the table's sampling (`GLOSSY_TABLE_STRATA²` visible normals per entry).
/// Measured against 1024² strata over the nodes of roughness ≥ 0.2: largest error 1.3·10⁻² of
/// the entry's band-0 weight at 32, 6.8·10⁻³ at 64, 2.8·10⁻³ at 128, 2.3·10⁻³ at 256 (the cut
/// where reflected directions cross the horizon makes the convergence first-order).
pub const GLOSSY_TABLE_STRATA: usize = 128;

/// Floats per table entry: the 16 weights of `A` then the 16 of `B`.
pub const GLOSSY_ENTRY: usize = 2 * SH_COEFFS;

/// The table's roughness of row `j`: `j/(GLOSSY_TABLE_ROUGHNESS − 1)` over `[0, 1]`.
pub fn glossy_table_roughness(j: usize) -> f32 {
    j as f32 / (GLOSSY_TABLE_ROUGHNESS - 1) as f32
}

/// The table's `n·v` of column `i`: `GLOSSY_NV_MIN + (1 − GLOSSY_NV_MIN)·i/(GLOSSY_TABLE_NV − 1)`.
pub fn glossy_table_nv(i: usize) -> f32 {
    (GLOSSY_NV_MIN + (1.0 - GLOSSY_NV_MIN) * i as f32 / (GLOSSY_TABLE_NV - 1) as f32).min(1.0)
}

/// The lobe projections `(A, B)` (module docs) for one roughness and `n·v`, by stratified
/// sampling of the GGX visible normals (`strata²` samples; f64 sums): each sample's weight
/// `D·V·(n·l)/pdf` is the smooth `G2/G1`-like ratio, so few samples give a precise integral.
pub fn glossy_projection(
    roughness: f32,
    n_dot_v: f32,
    strata: usize,
) -> ([f64; SH_COEFFS], [f64; SH_COEFFS]) {
    let alpha = alpha_from_roughness(roughness);
    let nv = n_dot_v.clamp(GLOSSY_NV_MIN, 1.0);
    let v = Vec3::new((1.0 - nv * nv).max(0.0).sqrt(), 0.0, nv);
    let mut a = [0.0f64; SH_COEFFS];
    let mut b = [0.0f64; SH_COEFFS];
    let inv = 1.0 / (strata * strata) as f64;
    for s1 in 0..strata {
        for s2 in 0..strata {
            let u1 = (s1 as f32 + 0.5) / strata as f32;
            let u2 = (s2 as f32 + 0.5) / strata as f32;
            let m = sample_ggx_vndf(alpha, v, u1, u2);
            let l = reflect(v, m).normalize_or(Vec3::Z);
            if l.z <= 0.0 {
                continue;
            }
            let pdf = ggx_reflection_pdf(alpha, v, l);
            if pdf <= 0.0 {
                continue;
            }
            let h = (v + l).normalize_or(Vec3::Z);
            let dv = ggx_d(alpha, h) * smith_v_correlated(alpha, l.z, v.z);
            let weight = f64::from(dv * l.z / pdf) * inv;
            let w = f64::from((1.0 - v.dot(h).clamp(0.0, 1.0)).powi(5));
            let y = sh_basis(l);
            for k in 0..SH_COEFFS {
                a[k] += weight * (1.0 - w) * f64::from(y[k]);
                b[k] += weight * w * f64::from(y[k]);
            }
        }
    }
    (a, b)
}

/// The table of frame weights, `GLOSSY_TABLE_ROUGHNESS × GLOSSY_TABLE_NV` entries of
/// [`GLOSSY_ENTRY`] floats, row-major in roughness (entry `j·GLOSSY_TABLE_NV + i`): what the
/// renderer uploads for `shaders/common/glossy.glsl`. `strata` as in [`glossy_projection`].
pub fn glossy_table(strata: usize) -> Vec<f32> {
    let mut out =
        Vec::with_capacity((GLOSSY_TABLE_ROUGHNESS * GLOSSY_TABLE_NV) as usize * GLOSSY_ENTRY);
    for j in 0..GLOSSY_TABLE_ROUGHNESS as usize {
        for i in 0..GLOSSY_TABLE_NV as usize {
            let (a, b) = glossy_projection(glossy_table_roughness(j), glossy_table_nv(i), strata);
            out.extend(sh_frame_weights(&a).iter().map(|&x| x as f32));
            out.extend(sh_frame_weights(&b).iter().map(|&x| x as f32));
        }
    }
    out
}

/// The table entry for `roughness` and `n_dot_v`, bilinear between the four nearest entries
/// (both clamped to the table's range).
pub fn glossy_lookup(table: &[f32], roughness: f32, n_dot_v: f32) -> [f32; GLOSSY_ENTRY] {
    let nr = GLOSSY_TABLE_ROUGHNESS as usize;
    let nn = GLOSSY_TABLE_NV as usize;
    let x = ((roughness.clamp(0.0, 1.0)) * (nr - 1) as f32).clamp(0.0, (nr - 1) as f32);
    let y = ((n_dot_v.clamp(GLOSSY_NV_MIN, 1.0) - GLOSSY_NV_MIN) / (1.0 - GLOSSY_NV_MIN)
        * (nn - 1) as f32)
        .clamp(0.0, (nn - 1) as f32);
    let j0 = (x.floor() as usize).min(nr - 2);
    let i0 = (y.floor() as usize).min(nn - 2);
    let fx = x - j0 as f32;
    let fy = y - i0 as f32;
    let at = |j: usize, i: usize, k: usize| table[(j * nn + i) * GLOSSY_ENTRY + k];
    std::array::from_fn(|k| {
        let a = at(j0, i0, k) * (1.0 - fy) + at(j0, i0 + 1, k) * fy;
        let b = at(j0 + 1, i0, k) * (1.0 - fy) + at(j0 + 1, i0 + 1, k) * fy;
        a * (1.0 - fx) + b * fx
    })
}

/// The colour weights `(K0, K1)` of the two tabulated lobes for a material (module docs).
pub fn glossy_weights(m: &Material) -> (Vec3, f32) {
    let metallic = m.metallic.clamp(0.0, 1.0);
    let s = m.specular_factor.clamp(0.0, 1.0);
    let base = m.base_colour.clamp(Vec3::ZERO, Vec3::ONE);
    let f0_d = dielectric_f0(m.ior, m.specular_colour);
    (
        base * metallic + f0_d * ((1.0 - metallic) * s),
        metallic + (1.0 - metallic) * s,
    )
}

/// The radiance the specular lobe of material `m` reflects towards `v` (world, unit) at a
/// point with shading normal `n` (world, unit) under the incident radiance `c` (world-space
/// coefficients): `Σ_i c_i ⊙ W_i` with the weights of [`glossy_world_weights`] (equal to
/// `Σ_k (K0·gA_k + K1·gB_k) · value_k` with the values of [`crate::sh::sh_frame_values`]),
/// clamped at 0
/// (a truncated product can dip below it). 0 where `n·v ≤ 0`; between 0 and the table's first
/// column, [`GLOSSY_NV_MIN`], the lookup is clamped there, not extrapolated.
pub fn glossy_radiance(table: &[f32], m: &Material, n: Vec3, v: Vec3, c: &ShRgb) -> Vec3 {
    let w = glossy_world_weights(table, m, n, v);
    c.iter()
        .zip(&w)
        .fold(Vec3::ZERO, |acc, (ci, wi)| acc + *ci * *wi)
        .max(Vec3::ZERO)
}

/// The world-space weights `W` of the glossy lobe for one pixel: `Σ_i c_i ⊙ W_i` is
/// [`glossy_radiance`] before its clamp at 0, for every coefficient vector `c`. The frame change
/// is linear in `c`: `value_k = Σ_{i ∈ band(k)} c_i·Y_i(M·d_k)`, so
/// `W_i = Σ_{k: band(k) = band(i)} Y_i(M·d_k) · (K0·gA_k + K1·gB_k)`. The splat weighs each
/// record's coefficients by them (one dot product per record and pixel, docs/radiance-caching.md
/// §6.2); zero where `n·v ≤ 0`.
pub fn glossy_world_weights(table: &[f32], m: &Material, n: Vec3, v: Vec3) -> ShRgb {
    let mut w = [Vec3::ZERO; SH_COEFFS];
    let nv = n.dot(v);
    if nv <= 0.0 {
        return w;
    }
    let (t, b, n) = sh_view_frame(n, v);
    let g = glossy_lookup(table, m.roughness, nv);
    let (k0, k1) = glossy_weights(m);
    for k in 0..SH_COEFFS {
        let d = SH_FRAME_DIRS[k];
        let y = sh_basis(t * d.x + b * d.y + n * d.z);
        let gk = k0 * g[k] + Vec3::splat(k1 * g[SH_COEFFS + k]);
        let band = sh_band(k);
        for (i, wi) in w
            .iter_mut()
            .enumerate()
            .take((band + 1) * (band + 1))
            .skip(band * band)
        {
            *wi += gk * y[i];
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf_eval_lobes;
    use crate::sh::{sh_frame_values, sh_reconstruct, sh_sphere_linear};

    /// `∫ L(l)·specular(v, l)·(n·l) dl` by brute-force quadrature in the local frame
    /// (midpoint in cos θ and φ, refined near the mirror direction by sheer count).
    fn reference(m: &Material, v_local: Vec3, radiance: impl Fn(Vec3) -> Vec3) -> Vec3 {
        let (nz, np) = (1200, 1200);
        let mut s = glam::DVec3::ZERO;
        for iz in 0..nz {
            let z = (iz as f32 + 0.5) / nz as f32;
            let r = (1.0 - z * z).sqrt();
            for ip in 0..np {
                let p = std::f32::consts::TAU * (ip as f32 + 0.5) / np as f32;
                let l = Vec3::new(r * p.cos(), r * p.sin(), z);
                let f = brdf_eval_lobes(m, v_local, l).specular;
                s += (f * radiance(l) * l.z).as_dvec3();
            }
        }
        (s * (std::f64::consts::TAU / (nz * np) as f64)).as_vec3()
    }

    #[test]
    fn world_weights_reproduce_the_glossy_radiance() {
        let table = glossy_table(16);
        for i in 0..50u32 {
            let f = |k: u32| ((i * 31 + k * 17) % 97) as f32 / 97.0;
            let n = Vec3::new(f(1) - 0.5, f(2) - 0.5, f(3) - 0.3).normalize();
            let v = (Vec3::new(f(4) - 0.5, f(5) - 0.5, f(6) - 0.5) + n).normalize();
            let c: ShRgb = std::array::from_fn(|k| {
                Vec3::new(f(k as u32 + 7), f(k as u32 + 8), f(k as u32 + 9)) - 0.3
            });
            let m = Material::metal_rough(Vec3::new(f(10), f(11), f(12)), f(13), 0.5 + f(14) / 2.0);
            let w = glossy_world_weights(&table, &m, n, v);
            let by_weights: Vec3 = (0..SH_COEFFS).map(|k| c[k] * w[k]).sum();
            let (t, b, nn) = sh_view_frame(n, v);
            let values = sh_frame_values(&c, t, b, nn);
            let g = glossy_lookup(&table, m.roughness, n.dot(v));
            let (k0, k1) = glossy_weights(&m);
            let direct: Vec3 = (0..SH_COEFFS)
                .map(|k| values[k] * (k0 * g[k] + Vec3::splat(k1 * g[SH_COEFFS + k])))
                .sum();
            assert!(
                (by_weights - direct).abs().max_element()
                    < 1e-4 * (1.0 + direct.abs().max_element())
            );
            assert_eq!(
                by_weights.max(Vec3::ZERO),
                glossy_radiance(&table, &m, n, v, &c)
            );
        }
        let m = Material::default();
        assert_eq!(
            glossy_world_weights(&table, &m, Vec3::Z, -Vec3::Z),
            [Vec3::ZERO; SH_COEFFS]
        );
    }

    #[test]
    fn table_convolution_matches_numerical_integration_at_the_nodes() {
        let table = glossy_table(GLOSSY_TABLE_STRATA);
        // Linear fields (exactly band-limited): the SH product is exact up to the table's
        // sampling error.
        let c = sh_sphere_linear(
            Vec3::new(1.0, 0.8, 0.5),
            Vec3::new(0.3, 0.0, -0.2),
            Vec3::new(-0.1, 0.4, 0.0),
            Vec3::new(0.5, 0.2, 0.6),
        );
        for &(j, i) in &[(4usize, 3usize), (8, 10), (15, 15), (6, 0), (10, 7)] {
            let roughness = glossy_table_roughness(j);
            let nv = glossy_table_nv(i);
            let m = Material::metal_rough(Vec3::new(0.9, 0.6, 0.3), 0.7, roughness);
            let v = Vec3::new((1.0 - nv * nv).sqrt(), 0.0, nv);
            let expected = reference(&m, v, |l| sh_reconstruct(&c, l));
            let got = glossy_radiance(&table, &m, Vec3::Z, v, &c);

            let err = (got - expected).abs().max_element() / expected.max_element();
            assert!(
                err < 5e-3,
                "r {roughness} nv {nv}: {got} vs {expected} ({err})"
            );
        }
    }
}

#[cfg(test)]
mod band_limit {
    //! The measurement behind `SH_BANDS` and `GLOSSY_ROUGHNESS_MIN` (docs/radiance-caching.md
    //! §4): the truncation error of the reflected radiance in a room, per order and roughness.
    use super::*;
    use crate::brdf_eval_lobes;
    use crate::sh::{sh_eval, sh_project_add, SH_BANDS};
    use glam::DVec3;
    use radcache_shared::consts::GLOSSY_ROUGHNESS_MIN;

    /// The indirect radiance seen from the centre of a room's floor (local frame: the floor's
    /// normal is +z; walls at x = ±1 and y = ±1, ceiling at z = 2): a red wall (−x), a green one
    /// (+x), white ones, and a ceiling three times as bright (lit from below).
    fn room(d: DVec3) -> DVec3 {
        if d.z <= 0.0 {
            return DVec3::ZERO;
        }
        let tx = 1.0 / d.x.abs().max(1e-12);
        let ty = 1.0 / d.y.abs().max(1e-12);
        let tz = 2.0 / d.z;
        if tz <= tx && tz <= ty {
            DVec3::splat(1.5)
        } else if tx <= ty && d.x < 0.0 {
            DVec3::new(0.6, 0.08, 0.06)
        } else if tx <= ty {
            DVec3::new(0.1, 0.5, 0.1)
        } else {
            DVec3::splat(0.55)
        }
    }

    /// Midpoint quadrature directions over the upper hemisphere (cos θ, φ) and their weight.
    fn hemisphere(n: usize) -> (Vec<DVec3>, f64) {
        let mut dirs = Vec::with_capacity(n * n);
        for iz in 0..n {
            for ip in 0..n {
                let z = (iz as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let p = std::f64::consts::TAU * (ip as f64 + 0.5) / n as f64;
                dirs.push(DVec3::new(r * p.cos(), r * p.sin(), z));
            }
        }
        (dirs, std::f64::consts::TAU / (n * n) as f64)
    }

    /// Views: `n·v` 1, 0.7, 0.4, 0.2 at three azimuths (towards the red wall, a corner, the
    /// green wall's side).
    fn views() -> Vec<Vec3> {
        let mut out = Vec::new();
        for nv in [1.0f32, 0.7, 0.4, 0.2] {
            for az in [0.0f32, 1.2, 2.5] {
                let s = (1.0 - nv * nv).sqrt();
                out.push(Vec3::new(s * az.cos(), s * az.sin(), nv));
            }
        }
        out
    }

    /// The largest relative error of any channel over [`views`] of the `bands`-band product
    /// `Σ L_i f_i` (both projected by quadrature, `sh_eval`) for the scalar lobe `D·V·(n·l)`.
    fn truncation_error(roughness: f32, bands: usize, dirs: &[DVec3], dw: f64) -> f64 {
        let count = bands * bands;
        let ys: Vec<Vec<f64>> = dirs
            .iter()
            .map(|&d| {
                (0..bands)
                    .flat_map(|l| (-(l as i32)..=l as i32).map(move |m| sh_eval(l, m, d)))
                    .collect()
            })
            .collect();
        let radiance: Vec<DVec3> = dirs.iter().map(|&d| room(d)).collect();
        let mut lc = vec![DVec3::ZERO; count];
        for (y, l) in ys.iter().zip(&radiance) {
            for i in 0..count {
                lc[i] += *l * (y[i] * dw);
            }
        }
        let alpha = alpha_from_roughness(roughness);
        let mut worst: f64 = 0.0;
        for v in views() {
            let mut exact = DVec3::ZERO;
            let mut fc = vec![0.0f64; count];
            for ((d, y), l) in dirs.iter().zip(&ys).zip(&radiance) {
                let dl = d.as_vec3();
                let h = (v + dl).normalize();
                let f = f64::from(ggx_d(alpha, h) * smith_v_correlated(alpha, dl.z, v.z) * dl.z);
                exact += *l * (f * dw);
                for i in 0..count {
                    fc[i] += f * y[i] * dw;
                }
            }
            let approx: DVec3 = (0..count).map(|i| lc[i] * fc[i]).sum();
            worst = worst.max(((approx - exact).abs() / exact).max_element());
        }
        worst
    }

    #[test]
    fn the_order_and_the_roughness_threshold_hold_in_a_room() {
        let (dirs, dw) = hemisphere(384);
        let limit = 0.1;
        // The chosen order is within 10 % from the threshold up; one band fewer is not.
        for r in [GLOSSY_ROUGHNESS_MIN, 0.8, 1.0] {
            let e = truncation_error(r, SH_BANDS, &dirs, dw);
            eprintln!("roughness {r}: {SH_BANDS} bands {e:.3}");
            assert!(e <= limit, "roughness {r}: {e}");
        }
        let e = truncation_error(GLOSSY_ROUGHNESS_MIN, SH_BANDS - 1, &dirs, dw);
        eprintln!(
            "roughness {GLOSSY_ROUGHNESS_MIN}: {} bands {e:.3}",
            SH_BANDS - 1
        );
        assert!(e > limit, "{} bands would do: {e}", SH_BANDS - 1);
        // Below the threshold the chosen order is not enough: those lobes stay path traced.
        let e = truncation_error(GLOSSY_ROUGHNESS_MIN - 0.1, SH_BANDS, &dirs, dw);
        eprintln!(
            "roughness {}: {SH_BANDS} bands {e:.3}",
            GLOSSY_ROUGHNESS_MIN - 0.1
        );
        assert!(e > limit);
    }

    #[test]
    fn the_table_reproduces_the_room_through_the_renderer_path() {
        // The renderer's path: the radiance projected onto 16 coefficients (sh_project_add),
        // the table, the frame change; a white metal (K0 = 1, K1 = 1: the whole Schlick lobe).
        let table = glossy_table(GLOSSY_TABLE_STRATA);
        let (dirs, dw) = hemisphere(384);
        let mut c = [Vec3::ZERO; SH_COEFFS];
        for d in &dirs {
            sh_project_add(&mut c, d.as_vec3(), room(*d).as_vec3(), dw as f32);
        }
        for r in [GLOSSY_ROUGHNESS_MIN, 0.8, 1.0] {
            let m = Material::metal_rough(Vec3::ONE, 1.0, r);
            let mut worst: f32 = 0.0;
            for v in views() {
                let mut exact = DVec3::ZERO;
                for d in &dirs {
                    let l = d.as_vec3();
                    let f = brdf_eval_lobes(&m, v, l).specular;
                    exact += room(*d) * (f.as_dvec3() * f64::from(l.z) * dw);
                }
                let exact = exact.as_vec3();
                let got = glossy_radiance(&table, &m, Vec3::Z, v, &c);
                worst = worst.max(((got - exact).abs() / exact).max_element());
            }
            eprintln!("roughness {r}: table and frame change {worst:.3}");
            assert!(worst <= 0.1, "roughness {r}: {worst}");
        }
    }
}
