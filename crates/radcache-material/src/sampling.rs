//! Importance sampling of the BRDF and its pdf (`docs/materials.md` §5). Directions are in the
//! local frame, `n = +Z`; `u` components are uniform random numbers in `[0, 1)`.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::Vec3;

use crate::brdf::{brdf_eval, Material, COS_MIN};
use crate::fresnel::{dielectric_f0, fresnel_schlick, max_component, mean_component};
use crate::ggx::{alpha_from_roughness, ggx_d, smith_g1};

/// A cosine-distributed direction on the upper hemisphere, pdf `l.z/π`:
/// `r = sqrt(u1)`, `φ = 2π u2`, `l = (r cosφ, r sinφ, sqrt(1 − u1))` (Malley's method).
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let r = u1.clamp(0.0, 1.0).sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(
        r * phi.cos(),
        r * phi.sin(),
        (1.0 - u1).clamp(0.0, 1.0).sqrt(),
    )
}

/// The pdf (solid angle) of [`sample_cosine_hemisphere`]: `max(l.z, 0)/π`.
pub fn cosine_hemisphere_pdf(l: Vec3) -> f32 {
    l.z.max(0.0) * FRAC_1_PI
}

/// A microfacet normal `m` drawn from the GGX distribution of visible normals for the view `v`
/// (`v.z > 0`), `D_v(m) = G1(v) max(v·m, 0) D(m) / (n·v)` (Heitz 2018), by the spherical-cap
/// construction of Dupuy & Benyoub 2023: stretch `v` to the α = 1 configuration,
/// `v_s = normalize(α v_x, α v_y, v_z)`; draw `c` uniformly on the spherical cap
/// `z ∈ (−v_s.z, 1]` (`φ = 2π u1`, `z = (1 − u2)(1 + v_s.z) − v_s.z`); the visible normal of the
/// hemisphere is `h_s = c + v_s`; unstretch `m = normalize(α h_s.x, α h_s.y, h_s.z)`.
pub fn sample_ggx_vndf(alpha: f32, v: Vec3, u1: f32, u2: f32) -> Vec3 {
    let vs = Vec3::new(alpha * v.x, alpha * v.y, v.z).normalize_or(Vec3::Z);
    let phi = 2.0 * PI * u1;
    let z = (1.0 - u2) * (1.0 + vs.z) - vs.z;
    let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
    let c = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), z);
    let hs = c + vs;
    Vec3::new(alpha * hs.x, alpha * hs.y, hs.z.max(0.0)).normalize_or(Vec3::Z)
}

/// The density of [`sample_ggx_vndf`] over microfacet normals:
/// `D_v(m) = G1(v) max(v·m, 0) D(m) / (n·v)` (Heitz 2018; Heitz 2014).
/// 0 for `v.z < COS_MIN`.
pub fn ggx_vndf_pdf(alpha: f32, v: Vec3, m: Vec3) -> f32 {
    if v.z < COS_MIN {
        return 0.0;
    }
    smith_g1(alpha, v.z) * v.dot(m).max(0.0) * ggx_d(alpha, m) / v.z
}

/// The mirror reflection of `v` about `m`: `2(v·m)m − v`.
pub fn reflect(v: Vec3, m: Vec3) -> Vec3 {
    m * (2.0 * v.dot(m)) - v
}

/// The density (solid angle, over the whole sphere) of `l = reflect(v, m)` with `m` from
/// [`sample_ggx_vndf`]: `D_v(h)/(4 v·h) = G1(v) D(h) / (4 n·v)`, `h = normalize(v + l)`,
/// evaluated as `0.5 D(h) / (n·v + sqrt(α² + (1 − α²)(n·v)²))` (no division by `n·v`).
/// It integrates to 1 over the sphere; directions below the horizon carry part of it.
pub fn ggx_reflection_pdf(alpha: f32, v: Vec3, l: Vec3) -> f32 {
    if v.z < COS_MIN {
        return 0.0;
    }
    let sum = v + l;
    let len = sum.length();
    if len <= 0.0 {
        return 0.0;
    }
    let h = sum / len;
    let a2 = alpha * alpha;
    let root = (a2 + (1.0 - a2) * v.z * v.z).sqrt();
    0.5 * ggx_d(alpha, h) / (v.z + root)
}

/// The probability of sampling the specular lobe for the view direction `v.z = n_dot_v`, from
/// the lobes' albedos estimated with the Fresnel term at `n·v`:
///
/// `w_s = metallic·mean(F_m(n·v)) + (1 − metallic)·s·max(F_d(n·v))`,
/// `w_d = (1 − metallic)·(1 − s·max(F_d(n·v)))·mean(base)`, `p = w_s/(w_s + w_d)`
/// (0.5 when both are 0). Any `p` keeps the estimator unbiased: each lobe's sampler covers the
/// whole upper hemisphere.
pub fn specular_lobe_probability(m: &Material, n_dot_v: f32) -> f32 {
    let metallic = m.metallic.clamp(0.0, 1.0);
    let s = m.specular_factor.clamp(0.0, 1.0);
    let cos = n_dot_v.clamp(0.0, 1.0);
    let base = m.base_colour.max(Vec3::ZERO);
    let f_metal = fresnel_schlick(base.min(Vec3::ONE), 1.0, cos);
    let f_diel = max_component(fresnel_schlick(
        dielectric_f0(m.ior, m.specular_colour),
        1.0,
        cos,
    ));
    let w_s = metallic * mean_component(f_metal) + (1.0 - metallic) * s * f_diel;
    let w_d = (1.0 - metallic) * (1.0 - s * f_diel) * mean_component(base);
    let total = w_s + w_d;
    if total > 0.0 {
        (w_s / total).clamp(0.0, 1.0)
    } else {
        0.5
    }
}

/// The pdf (solid angle, over the sphere) of [`brdf_sample`]: the lobe mixture
/// `p·ggx_reflection_pdf(α, v, l) + (1 − p)·cosine_hemisphere_pdf(l)`,
/// `p` = [`specular_lobe_probability`]. 0 for `v.z < COS_MIN`.
pub fn brdf_pdf(m: &Material, v: Vec3, l: Vec3) -> f32 {
    if v.z < COS_MIN {
        return 0.0;
    }
    let p = specular_lobe_probability(m, v.z);
    let alpha = alpha_from_roughness(m.roughness);
    p * ggx_reflection_pdf(alpha, v, l) + (1.0 - p) * cosine_hemisphere_pdf(l)
}

/// One BRDF sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfSample {
    /// The sampled direction `l` (unit, local frame; may lie below the horizon).
    pub l: Vec3,
    /// [`brdf_pdf`] at `l` (solid angle).
    pub pdf: f32,
    /// The estimator weight `f(v, l)·(n·l)/pdf`; 0 when `l.z < COS_MIN` or `pdf = 0`.
    pub weight: Vec3,
}

/// Samples `l` for the view direction `v`: `u.z < p` ([`specular_lobe_probability`]) picks the
/// specular lobe (`l = reflect(v, m)`, `m` from [`sample_ggx_vndf`] with `u.x, u.y`), otherwise
/// the diffuse lobe ([`sample_cosine_hemisphere`]). The pdf is the mixture [`brdf_pdf`] (one-sample
/// MIS over the lobes). For `v.z < COS_MIN` the sample is `l = +Z` with pdf and weight 0.
pub fn brdf_sample(m: &Material, v: Vec3, u: Vec3) -> BrdfSample {
    if v.z < COS_MIN {
        return BrdfSample {
            l: Vec3::Z,
            pdf: 0.0,
            weight: Vec3::ZERO,
        };
    }
    let p = specular_lobe_probability(m, v.z);
    let l = if u.z < p {
        let alpha = alpha_from_roughness(m.roughness);
        reflect(v, sample_ggx_vndf(alpha, v, u.x, u.y)).normalize_or(Vec3::Z)
    } else {
        sample_cosine_hemisphere(u.x, u.y)
    };
    let pdf = brdf_pdf(m, v, l);
    let weight = if l.z < COS_MIN || pdf <= 0.0 {
        Vec3::ZERO
    } else {
        brdf_eval(m, v, l) * (l.z / pdf)
    };
    BrdfSample { l, pdf, weight }
}
