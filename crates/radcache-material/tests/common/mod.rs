//! Shared test helpers: a seeded random generator, quadratures of the directional albedo, and
//! the χ² machinery of the sampling test.

#![allow(dead_code)]

use glam::Vec3;
use radcache_material::ggx::alpha_from_roughness;
use radcache_material::sampling::reflect;
use radcache_material::{brdf_eval_lobes, Material};

/// SplitMix64: a small seeded generator, so that every statistical test uses fixed seeds.
#[derive(Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 24 bits.
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / 16_777_216.0)
    }

    pub fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.f32(), self.f32(), self.f32())
    }

    /// A uniformly distributed unit vector on the upper hemisphere (`z >= 0`).
    pub fn hemisphere(&mut self) -> Vec3 {
        let z = self.f32();
        let phi = 2.0 * std::f32::consts::PI * self.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// The view direction at polar angle `theta_deg` in the xz-plane.
pub fn view_at(theta_deg: f32) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin(), 0.0, t.cos())
}

/// `∫ f_diffuse(v, l) (n·l) dl` by the midpoint rule on the cosine-weighted map
/// (`l = (√ξ1 cos 2πξ2, √ξ1 sin 2πξ2, √(1 − ξ1))`, `dl (n·l) = π dξ`), `n × n` points.
pub fn diffuse_albedo(m: &Material, v: Vec3, n: usize) -> [f64; 3] {
    let mut acc = [0.0f64; 3];
    for i in 0..n {
        let x1 = (i as f64 + 0.5) / n as f64;
        for j in 0..n {
            let x2 = (j as f64 + 0.5) / n as f64;
            let r = x1.sqrt();
            let phi = 2.0 * std::f64::consts::PI * x2;
            let l = Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                (1.0 - x1).sqrt() as f32,
            );
            let d = brdf_eval_lobes(m, v, l).diffuse;
            for c in 0..3 {
                acc[c] += d[c] as f64;
            }
        }
    }
    let w = std::f64::consts::PI / (n * n) as f64;
    acc.map(|a| a * w)
}

/// `∫ f_specular(v, l) (n·l) dl`, integrated over microfacet normals `m` (`l = reflect(v, m)`,
/// `dl = 4 |v·m| dm`) by the midpoint rule on the map of the GGX distribution of `D(m)(n·m)`,
/// `tan²θ_m = α² ξ1/(1 − ξ1)`, `φ = 2π ξ2`, whose density `D(m)(n·m)` divides the integrand:
/// this resolves the lobe at every α down to `ALPHA_MIN`. `n1 × n2` points.
pub fn specular_albedo(m: &Material, v: Vec3, n1: usize, n2: usize) -> [f64; 3] {
    let alpha = alpha_from_roughness(m.roughness) as f64;
    let mut acc = [0.0f64; 3];
    for i in 0..n1 {
        let x1 = (i as f64 + 0.5) / n1 as f64;
        let tan2 = alpha * alpha * x1 / (1.0 - x1);
        let cos_m = 1.0 / (1.0 + tan2).sqrt();
        let sin_m = (1.0 - cos_m * cos_m).max(0.0).sqrt();
        let d = alpha * alpha
            / (std::f64::consts::PI * (cos_m.powi(2) * (alpha * alpha - 1.0) + 1.0).powi(2));
        for j in 0..n2 {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / n2 as f64;
            let mm = Vec3::new(
                (sin_m * phi.cos()) as f32,
                (sin_m * phi.sin()) as f32,
                cos_m as f32,
            );
            let v_dot_m = v.dot(mm) as f64;
            if v_dot_m <= 0.0 {
                continue;
            }
            let l = reflect(v, mm).normalize();
            if l.z <= 0.0 {
                continue;
            }
            let s = brdf_eval_lobes(m, v, l).specular;
            let jac = l.z as f64 * 4.0 * v_dot_m / (d * cos_m);
            for c in 0..3 {
                acc[c] += s[c] as f64 * jac;
            }
        }
    }
    let w = 1.0 / (n1 * n2) as f64;
    acc.map(|a| a * w)
}

/// The directional albedo `∫ f(v, l)(n·l) dl`, per channel: [`diffuse_albedo`] (256²) plus
/// [`specular_albedo`] (1024 × 512).
pub fn albedo(m: &Material, v: Vec3) -> [f64; 3] {
    let d = diffuse_albedo(m, v, 256);
    let s = specular_albedo(m, v, 1024, 512);
    [d[0] + s[0], d[1] + s[1], d[2] + s[2]]
}

/// The standard normal CDF, by Abramowitz & Stegun 7.1.26 (|error| < 1.5·10⁻⁷).
pub fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-z * z).exp();
    if x >= 0.0 {
        1.0 - 0.5 * erfc
    } else {
        0.5 * erfc
    }
}

/// The upper tail `P(X ≥ x)` of a χ² variable with `k` degrees of freedom, by the
/// Wilson–Hilferty cube-root normal approximation (good to a few per cent of the p-value for
/// `k ≳ 30`, which every test here has).
pub fn chi2_survival(x: f64, k: f64) -> f64 {
    let s = 2.0 / (9.0 * k);
    let z = ((x / k).powf(1.0 / 3.0) - (1.0 - s)) / s.sqrt();
    1.0 - normal_cdf(z)
}

/// Pearson's statistic of `observed` against `expected`, pooling every cell whose expected count
/// is below 5 into one cell (as pbrt's and Mitsuba's χ² tests do). Returns `(χ², dof)`.
pub fn chi2_statistic(observed: &[f64], expected: &[f64]) -> (f64, usize) {
    let (mut chi2, mut cells) = (0.0, 0usize);
    let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pooled_e > 0.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        cells += 1;
    }
    (chi2, cells.saturating_sub(1))
}
