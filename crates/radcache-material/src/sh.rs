//! Real spherical harmonics for radiance records (`docs/radiance-caching.md` §2): the basis of
//! bands 0–3 (16 functions) in closed form, an arbitrary band by recurrence (for measurements),
//! projection of samples, the analytic coefficients of simple radiance fields, and the change of
//! frame "by evaluation" that lets the composite apply a BRDF tabulated in the local shading frame
//! to coefficients kept in world space (§3).
//!
//! **Convention.** `Y_l^m`, index `i = l² + l + m`, real, orthonormal over the sphere, without the
//! Condon–Shortley phase (as in Sloan, *Stupid Spherical Harmonics Tricks*, GDC 2008, and
//! Ramamoorthi & Hanrahan 2001): `Y_1^{-1} = K₁·y`, `Y_1^0 = K₁·z`, `Y_1^1 = K₁·x`;
//! `m > 0` ↔ `cos(mφ)`, `m < 0` ↔ `sin(|m|φ)`.

use glam::{DVec3, Vec3};

/// Bands kept by a radiance record (0 to 3), `SH_BANDS`, and coefficients per channel,
/// `SH_COEFFS = SH_BANDS²`: the order chosen in `docs/radiance-caching.md` §4 by measuring the
/// truncation error of the GGX lobes against a room's radiance (band 3 cuts the error about
/// fourfold; bands 4 and 5 add little). The constants are declared in `radcache_shared::consts`
/// (generated for GLSL).
pub const SH_BANDS: usize = radcache_shared::consts::SH_BANDS as usize;
/// See [`SH_BANDS`].
pub const SH_COEFFS: usize = radcache_shared::consts::SH_COEFFS as usize;
pub use radcache_shared::consts::{
    SH_K00, SH_K1, SH_K2, SH_K20, SH_K22, SH_K30, SH_K31, SH_K32, SH_K32B, SH_K33,
};

/// The 16 basis functions of bands 0–3 at the unit direction `d`:
/// `[K00, K1·y, K1·z, K1·x, K2·xy, K2·yz, K20·(3z² − 1), K2·xz, K22·(x² − y²),
/// K33·y(3x² − y²), K32·xyz, K31·y(5z² − 1), K30·z(5z² − 3), K31·x(5z² − 1), K32b·z(x² − y²),
/// K33·x(x² − 3y²)]`.
pub fn sh_basis(d: Vec3) -> [f32; SH_COEFFS] {
    let (x, y, z) = (d.x, d.y, d.z);
    let z2 = z * z;
    [
        SH_K00,
        SH_K1 * y,
        SH_K1 * z,
        SH_K1 * x,
        SH_K2 * x * y,
        SH_K2 * y * z,
        SH_K20 * (3.0 * z * z - 1.0),
        SH_K2 * x * z,
        SH_K22 * (x * x - y * y),
        SH_K33 * y * (3.0 * x * x - y * y),
        SH_K32 * x * y * z,
        SH_K31 * y * (5.0 * z2 - 1.0),
        SH_K30 * z * (5.0 * z2 - 3.0),
        SH_K31 * x * (5.0 * z2 - 1.0),
        SH_K32B * z * (x * x - y * y),
        SH_K33 * x * (x * x - 3.0 * y * y),
    ]
}

/// Basis function `i` alone (`sh_basis(d)[i]`; 0 past the last): what one shader invocation
/// evaluates when it projects one coefficient.
pub fn sh_basis_one(i: usize, d: Vec3) -> f32 {
    sh_basis(d).get(i).copied().unwrap_or(0.0)
}

/// The band of coefficient `i`: `⌊√i⌋`.
pub fn sh_band(i: usize) -> usize {
    let mut l = 0;
    while (l + 1) * (l + 1) <= i {
        l += 1;
    }
    l
}

/// `Y_l^m(d)` for any band (f64, by the associated-Legendre recurrence; for measurements of the
/// band limit, §4, and as the check of [`sh_basis`]). `|m| > l` gives 0.
pub fn sh_eval(l: usize, m: i32, d: DVec3) -> f64 {
    let am = m.unsigned_abs() as usize;
    if am > l {
        return 0.0;
    }
    let d = d.normalize_or(DVec3::Z);
    let z = d.z.clamp(-1.0, 1.0);
    let s = (1.0 - z * z).max(0.0).sqrt();
    // P_am^am = (2am − 1)!! s^am (no Condon–Shortley phase).
    let mut p_mm = 1.0;
    for k in 0..am {
        p_mm *= (2 * k + 1) as f64 * s;
    }
    let p = if l == am {
        p_mm
    } else {
        let mut p_prev = p_mm;
        let mut p_cur = z * (2 * am + 1) as f64 * p_mm;
        for ll in (am + 2)..=l {
            let next = (z * (2 * ll - 1) as f64 * p_cur - (ll + am - 1) as f64 * p_prev)
                / (ll - am) as f64;
            p_prev = p_cur;
            p_cur = next;
        }
        p_cur
    };
    let mut ratio = 1.0; // (l − am)! / (l + am)!
    for k in (l - am + 1)..=(l + am) {
        ratio /= k as f64;
    }
    let k = ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI) * ratio).sqrt();
    let phi = d.y.atan2(d.x);
    match m.cmp(&0) {
        std::cmp::Ordering::Equal => k * p,
        std::cmp::Ordering::Greater => std::f64::consts::SQRT_2 * k * p * (am as f64 * phi).cos(),
        std::cmp::Ordering::Less => std::f64::consts::SQRT_2 * k * p * (am as f64 * phi).sin(),
    }
}

/// RGB coefficient vectors, one `Vec3` per basis function.
pub type ShRgb = [Vec3; SH_COEFFS];

/// Adds the sample `value` seen in direction `d` with quadrature weight `weight` (for a Monte
/// Carlo estimate, `1/(N·pdf(d))`) to the projection `c`: `c_i += weight · value · Y_i(d)`.
pub fn sh_project_add(c: &mut ShRgb, d: Vec3, value: Vec3, weight: f32) {
    let y = sh_basis(d);
    for (ci, yi) in c.iter_mut().zip(y) {
        *ci += value * (weight * yi);
    }
}

/// The function the coefficients `c` stand for, at direction `d`: `Σ c_i Y_i(d)`.
pub fn sh_reconstruct(c: &ShRgb, d: Vec3) -> Vec3 {
    sh_basis(d)
        .iter()
        .zip(c)
        .fold(Vec3::ZERO, |acc, (&y, &ci)| acc + ci * y)
}

/// The coefficients of a constant radiance `L` over the hemisphere `d·n > 0` (zero below), `n`
/// unit. The field is zonal about `n`, so `c_{l,m} = c_{l,0}^{(z)} · Y_l^m(n) / Y_l^0(+z)` (the
/// addition theorem) with `c_{l,0}^{(z)} = 2π L ∫_0^1 Y_l^0(z) dz`: band 0 `2π·K00·L`; band 1
/// `π·L·Y_1^m(n)`; band 2 `0` (`∫_0^1 (3z² − 1) dz = 0`); band 3 `−(π/4)·L·Y_3^m(n)`
/// (`∫_0^1 z(5z² − 3) dz = −1/4`, `Y_3^0(+z) = 2·K30`).
pub fn sh_hemisphere_constant(n: Vec3, radiance: Vec3) -> ShRgb {
    let pi = std::f32::consts::PI;
    let y = sh_basis(n);
    let mut c = [Vec3::ZERO; SH_COEFFS];
    c[0] = radiance * (2.0 * pi * SH_K00);
    for i in 1..4 {
        c[i] = radiance * (pi * y[i]);
    }
    for i in 9..16 {
        c[i] = radiance * (-pi / 4.0 * y[i]);
    }
    c
}

/// The coefficients of a radiance field `L(d) = a + g·d` over the whole sphere (a constant plus a
/// linear gradient, per channel: `a`, and `g` as three RGB vectors `gx, gy, gz`): band 0
/// `4π·K00·a`, band 1 `(4π/3)·K1·g`, bands 2 and 3 `0`.
pub fn sh_sphere_linear(a: Vec3, gx: Vec3, gy: Vec3, gz: Vec3) -> ShRgb {
    let pi = std::f32::consts::PI;
    let k = 4.0 * pi / 3.0 * SH_K1;
    let mut c = [Vec3::ZERO; SH_COEFFS];
    c[0] = a * (4.0 * pi * SH_K00);
    c[1] = gy * k;
    c[2] = gz * k;
    c[3] = gx * k;
    c
}

/// The coefficients of a single bright direction `d` carrying power (radiance × solid angle)
/// `phi`: `Φ · Y_i(d)` (the projection of a Dirac delta).
pub fn sh_delta(d: Vec3, phi: Vec3) -> ShRgb {
    let mut c = [Vec3::ZERO; SH_COEFFS];
    sh_project_add(&mut c, d, phi, 1.0);
    c
}

/// `√½`.
const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// `1/√3`.
const T: f32 = 0.577_350_26;

/// The fixed local directions of the change of frame by evaluation (§3), one per coefficient:
/// slot 0 (band 0) any direction; slots 1–3 (band 1) the axes `y, z, x`, so that band 1's matrix
/// `A_km = Y_1^m(d_k)` is `K1·I`; slots 4–8 (band 2) and 9–15 (band 3) directions whose matrices
/// `A_km = Y_l^m(d_k)` are invertible, chosen among axes, face and body diagonals for the
/// smallest `‖A⁻ᵀ‖₁` (3.66 and 3.87: a value's rounding error grows at most that much).
pub const SH_FRAME_DIRS: [Vec3; SH_COEFFS] = [
    Vec3::Z,
    Vec3::Y,
    Vec3::Z,
    Vec3::X,
    Vec3::new(H, H, 0.0),
    Vec3::new(0.0, H, H),
    Vec3::Z,
    Vec3::new(H, 0.0, H),
    Vec3::X,
    Vec3::X,
    Vec3::Y,
    Vec3::Z,
    Vec3::new(H, H, 0.0),
    Vec3::new(H, 0.0, H),
    Vec3::new(0.0, H, -H),
    Vec3::new(T, T, T),
];

/// The band-`band` part of the function `c` at direction `d`: `Σ_m c_{l,m} Y_l^m(d)`.
pub fn sh_band_value(c: &ShRgb, band: usize, d: Vec3) -> Vec3 {
    let y = sh_basis(d);
    let lo = band * band;
    let hi = (band + 1) * (band + 1);
    (lo..hi).fold(Vec3::ZERO, |acc, i| acc + c[i] * y[i])
}

/// The values the frame change reads: for slot `k` of band `l`, the band-`l` part of the world
/// function `c` at `frame · SH_FRAME_DIRS[k]`, where `frame = [t, b, n]` maps local to world
/// (columns). With weights `g` from [`sh_frame_weights`], `Σ_k g_k · value_k = Σ_i f_i c'_i`:
/// the inner product of a function tabulated in the local frame (coefficients `f`) with `c`
/// expressed in that frame, exact for bands 0–3 because each band rotates within itself.
pub fn sh_frame_values(c: &ShRgb, t: Vec3, b: Vec3, n: Vec3) -> ShRgb {
    let mut out = [Vec3::ZERO; SH_COEFFS];
    for (k, o) in out.iter_mut().enumerate() {
        let d = SH_FRAME_DIRS[k];
        let w = t * d.x + b * d.y + n * d.z;
        *o = sh_band_value(c, sh_band(k), w);
    }
    out
}

/// The matrix `A_km = Y_{l}^{m}(d_k)` of one band over its slots of [`SH_FRAME_DIRS`]
/// (`(2l+1)²`, row-major, f64).
fn frame_matrix(band: usize) -> Vec<f64> {
    let lo = band * band;
    let n = 2 * band + 1;
    let mut a = vec![0.0; n * n];
    for k in 0..n {
        let d = SH_FRAME_DIRS[lo + k].as_dvec3();
        for (j, m) in (-(band as i32)..=band as i32).enumerate() {
            a[k * n + j] = sh_eval(band, m, d);
        }
    }
    a
}

/// Solves `A x = y` (n×n, row-major) by Gaussian elimination with partial pivoting; `None` when
/// singular.
fn solve(mut a: Vec<f64>, mut y: Vec<f64>) -> Option<Vec<f64>> {
    let n = y.len();
    for col in 0..n {
        let piv =
            (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if a[piv * n + col].abs() < 1e-12 {
            return None;
        }
        for k in 0..n {
            a.swap(col * n + k, piv * n + k);
        }
        y.swap(col, piv);
        for row in (col + 1)..n {
            let f = a[row * n + col] / a[col * n + col];
            for k in col..n {
                a[row * n + k] -= f * a[col * n + k];
            }
            y[row] -= f * y[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = ((row + 1)..n).map(|k| a[row * n + k] * x[k]).sum();
        x[row] = (y[row] - s) / a[row * n + row];
    }
    Some(x)
}

/// The weights `g = A⁻ᵀ f` per band, so that `Σ_i f_i c'_i = Σ_k g_k · value_k` with the values
/// of [`sh_frame_values`] (`c'` the world coefficients expressed in the local frame): band by
/// band, `value = A c'`, hence `f·c' = f·A⁻¹ value = (A⁻ᵀ f)·value`.
pub fn sh_frame_weights(f: &[f64; SH_COEFFS]) -> [f64; SH_COEFFS] {
    let mut g = [0.0; SH_COEFFS];
    for band in 0..SH_BANDS {
        let lo = band * band;
        let n = 2 * band + 1;
        let a = frame_matrix(band);
        let mut at = vec![0.0; n * n];
        for r in 0..n {
            for c in 0..n {
                at[c * n + r] = a[r * n + c];
            }
        }
        let x = solve(at, f[lo..lo + n].to_vec()).expect("SH_FRAME_DIRS give invertible matrices");
        g[lo..lo + n].copy_from_slice(&x);
    }
    g
}

/// The local shading frame of the BRDF tables (§3): `n`, and `t` the view direction's
/// projection on the tangent plane (so that `v = (sinθ, 0, cosθ)` locally), `b = n × t`. Where
/// the view is along `n` any tangent will do (the lobe is then symmetric about `n`).
pub fn sh_view_frame(n: Vec3, v: Vec3) -> (Vec3, Vec3, Vec3) {
    let tv = v - n * n.dot(v);
    let len = tv.length();
    let t = if len > 1e-6 {
        tv / len
    } else {
        let a = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        (a - n * n.dot(a)).normalize()
    };
    (t, n.cross(t), n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(i: u32) -> Vec3 {
        // A Fibonacci-sphere direction.
        let n = 97.0;
        let i = i % 97;
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / n;
        let phi = i as f32 * 2.399_963;
        let r = (1.0 - z * z).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    #[test]
    fn closed_form_matches_the_recurrence() {
        for i in 0..97 {
            let d = dir(i);
            let y = sh_basis(d);
            for (k, yk) in y.iter().enumerate() {
                let l = sh_band(k);
                let m = k as i32 - (l * l + l) as i32;
                let e = sh_eval(l, m, d.as_dvec3());
                assert!(
                    (f64::from(*yk) - e).abs() < 1e-6,
                    "Y{l},{m}({d}) {yk} vs {e}"
                );
            }
        }
    }

    #[test]
    fn the_basis_is_orthonormal() {
        // Midpoint quadrature in (cos θ, φ), exact enough for polynomials of degree ≤ 8.
        let (nz, np) = (200, 400);
        for l1 in 0..5usize {
            for m1 in -(l1 as i32)..=l1 as i32 {
                for l2 in 0..5usize {
                    for m2 in -(l2 as i32)..=l2 as i32 {
                        let mut s = 0.0;
                        for iz in 0..nz {
                            let z = -1.0 + 2.0 * (iz as f64 + 0.5) / nz as f64;
                            let r = (1.0 - z * z).sqrt();
                            for ip in 0..np {
                                let p = std::f64::consts::TAU * (ip as f64 + 0.5) / np as f64;
                                let d = DVec3::new(r * p.cos(), r * p.sin(), z);
                                s += sh_eval(l1, m1, d) * sh_eval(l2, m2, d);
                            }
                        }
                        s *= 4.0 * std::f64::consts::PI / (nz * np) as f64;
                        let e = if l1 == l2 && m1 == m2 { 1.0 } else { 0.0 };
                        assert!((s - e).abs() < 1e-3, "<Y{l1}{m1}, Y{l2}{m2}> = {s}");
                    }
                }
            }
        }
    }

    #[test]
    fn frame_change_is_exact_for_bands_0_to_3() {
        for i in 0..12 {
            let c: ShRgb = std::array::from_fn(|k| {
                let d = dir(i * 7 + k as u32);
                Vec3::new(d.x, d.y + 0.3, d.z * 2.0 - 0.1)
            });
            let f: [f64; SH_COEFFS] = std::array::from_fn(|k| f64::from(dir(i + 3 * k as u32).x));
            let n = dir(i * 3 + 1);
            let v = dir(i * 5 + 2);
            let (t, b, n) = sh_view_frame(n, v);
            // c expressed in the local frame, by projection of its reconstruction.
            let mut local = [DVec3::ZERO; SH_COEFFS];
            let (nz, np) = (300, 600);
            for iz in 0..nz {
                let z = -1.0 + 2.0 * (iz as f64 + 0.5) / nz as f64;
                let r = (1.0 - z * z).sqrt();
                for ip in 0..np {
                    let p = std::f64::consts::TAU * (ip as f64 + 0.5) / np as f64;
                    let dl = DVec3::new(r * p.cos(), r * p.sin(), z);
                    let dw =
                        (t.as_dvec3() * dl.x + b.as_dvec3() * dl.y + n.as_dvec3() * dl.z).as_vec3();
                    let val = sh_reconstruct(&c, dw).as_dvec3();
                    let y = sh_basis(dl.as_vec3());
                    for k in 0..SH_COEFFS {
                        local[k] += val * f64::from(y[k]);
                    }
                }
            }
            let w = 4.0 * std::f64::consts::PI / (nz * np) as f64;
            let direct: DVec3 = (0..SH_COEFFS).map(|k| local[k] * w * f[k]).sum();
            let g = sh_frame_weights(&f);
            let values = sh_frame_values(&c, t, b, n);
            let by_eval: DVec3 = (0..SH_COEFFS).map(|k| values[k].as_dvec3() * g[k]).sum();
            assert!(
                (direct - by_eval).length() < 2e-3 * (1.0 + direct.length()),
                "{direct} vs {by_eval}"
            );
        }
    }

    #[test]
    fn frame_matrices_are_well_conditioned() {
        // Columns of A⁻ᵀ by solving for unit vectors: the largest weight bounds the error growth.
        let mut worst: f64 = 0.0;
        for band in 2..SH_BANDS {
            let lo = band * band;
            let hi = (band + 1) * (band + 1);
            for k in lo..hi {
                let mut f = [0.0; SH_COEFFS];
                f[k] = 1.0;
                let g = sh_frame_weights(&f);
                worst = worst.max(g[lo..hi].iter().map(|x| x.abs()).sum());
            }
        }
        // ‖A⁻ᵀ‖₁ ≤ 4: a value's error of ε grows to at most 4ε.
        assert!(worst < 4.0, "‖A⁻ᵀ‖₁ = {worst}");
    }

    #[test]
    fn analytic_projections() {
        // Constant on a hemisphere, by quadrature of the projection.
        let n = Vec3::new(0.3, -0.5, 0.81).normalize();
        let l = Vec3::new(1.0, 0.5, 2.0);
        let mut c = [Vec3::ZERO; SH_COEFFS];
        let (nz, np) = (400, 800);
        let w = 4.0 * std::f32::consts::PI / (nz * np) as f32;
        for iz in 0..nz {
            let z = -1.0 + 2.0 * (iz as f32 + 0.5) / nz as f32;
            let r = (1.0 - z * z).sqrt();
            for ip in 0..np {
                let p = std::f32::consts::TAU * (ip as f32 + 0.5) / np as f32;
                let d = Vec3::new(r * p.cos(), r * p.sin(), z);
                if d.dot(n) > 0.0 {
                    sh_project_add(&mut c, d, l, w);
                }
            }
        }
        let e = sh_hemisphere_constant(n, l);
        for k in 0..SH_COEFFS {
            assert!((c[k] - e[k]).length() < 2e-2, "{k}: {} vs {}", c[k], e[k]);
        }
        // A single direction reconstructs to its basis values.
        let d = Vec3::new(0.2, 0.9, -0.3).normalize();
        let c = sh_delta(d, Vec3::ONE);
        let y = sh_basis(d);
        for k in 0..SH_COEFFS {
            assert_eq!(c[k], Vec3::splat(y[k]));
        }
        // A linear field a + g·d is reproduced exactly by bands 0 and 1.
        let (a, gx, gy, gz) = (
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.5, 0.0, -0.5),
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(-1.0, 0.0, 1.0),
        );
        let c = sh_sphere_linear(a, gx, gy, gz);
        for i in 0..20 {
            let d = dir(i * 4);
            let expected = a + gx * d.x + gy * d.y + gz * d.z;
            assert!((sh_reconstruct(&c, d) - expected).length() < 1e-5);
        }
    }
}
