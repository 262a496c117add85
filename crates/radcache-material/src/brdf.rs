//! The glTF 2.0 metallic-roughness BRDF (`docs/materials.md` §1, §4, §6).

use glam::Vec3;

use crate::fresnel::{dielectric_f0, fresnel_schlick, max_component};
use crate::ggx::{alpha_from_roughness, ggx_d, smith_v_correlated};

/// Cosines to the normal below this value count as "at or below the horizon": the BRDF, its pdf
/// and the sample weights are 0 there. It bounds `V ≤ 0.5/(2·COS_MIN·α)` and so keeps every
/// value finite in f32 (§4.3). Declared in `radcache_shared::consts` (generated for GLSL).
pub use radcache_shared::consts::COS_MIN;
use radcache_shared::consts::{
    SCHLICK_MEAN_C0, SCHLICK_MEAN_C1, SCHLICK_MEAN_C2, SCHLICK_MEAN_C3, SCHLICK_MEAN_C4,
};

/// One material's parameters at a shading point: the glTF metallic-roughness factors (after
/// textures), `KHR_materials_ior`'s `ior` and `KHR_materials_specular`'s `specular` /
/// `specularColor`. All colours are linear RGB.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// `baseColorFactor × baseColorTexture` (rgb).
    pub base_colour: Vec3,
    /// `metallicFactor × metallicRoughnessTexture.b`, in `[0, 1]`.
    pub metallic: f32,
    /// `roughnessFactor × metallicRoughnessTexture.g`, in `[0, 1]` (α = roughness²).
    pub roughness: f32,
    /// Index of refraction of the dielectric (`KHR_materials_ior`; 1.5 without it).
    pub ior: f32,
    /// Strength of the dielectric specular layer (`KHR_materials_specular`; 1 without it).
    pub specular_factor: f32,
    /// F0 colour of the dielectric specular layer (`KHR_materials_specular`; 1 without it).
    pub specular_colour: Vec3,
}

impl Material {
    /// The core glTF material (no extension): `ior` 1.5, specular factor and colour 1.
    pub fn metal_rough(base_colour: Vec3, metallic: f32, roughness: f32) -> Self {
        Self {
            base_colour,
            metallic,
            roughness,
            ior: 1.5,
            specular_factor: 1.0,
            specular_colour: Vec3::ONE,
        }
    }
}

impl Default for Material {
    /// The glTF default material: base colour 1, metallic 1, roughness 1.
    fn default() -> Self {
        Self::metal_rough(Vec3::ONE, 1.0, 1.0)
    }
}

/// The BRDF split in its two lobes; `diffuse + specular` is the BRDF. Both already carry the
/// `mix(dielectric, metal, metallic)` weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfLobes {
    /// `(1 − metallic)(1 − s·max(F_d(v·h))) · base/π`.
    pub diffuse: Vec3,
    /// `(metallic·F_m(v·h) + (1 − metallic)·s·F_d(v·h)) · D(h) · V(l, v)`.
    pub specular: Vec3,
}

/// The BRDF's two lobes for the view direction `v` and the light direction `l` (unit vectors,
/// local frame, `n = +Z`). glTF Appendix B with `KHR_materials_specular`'s `fresnel_mix`:
///
/// ```text
/// h = normalize(l + v),  α = max(roughness², ALPHA_MIN)
/// F_m = F0_m + (1 − F0_m)(1 − v·h)^5,  F0_m = base                 conductor_fresnel
/// F_d = F0_d + (1 − F0_d)(1 − v·h)^5,  F0_d = min(F0(ior)·specularColor, 1)
/// diffuse  = (1 − metallic) · (1 − s·max(F_d)) · base/π            fresnel_mix, base layer
/// specular = (metallic·F_m + (1 − metallic)·s·F_d) · D(h) · V       fresnel_mix / metal layer
/// ```
///
/// with `s` the specular factor, D [`ggx_d`], V [`smith_v_correlated`]. Zero lobes when `v.z` or
/// `l.z` is below [`COS_MIN`]. Reciprocal: every term is symmetric in `l` and `v`.
pub fn brdf_eval_lobes(m: &Material, v: Vec3, l: Vec3) -> BrdfLobes {
    let zero = BrdfLobes {
        diffuse: Vec3::ZERO,
        specular: Vec3::ZERO,
    };
    if v.z < COS_MIN || l.z < COS_MIN {
        return zero;
    }
    let sum = v + l;
    let len = sum.length();
    if len <= 0.0 {
        return zero;
    }
    let h = sum / len;
    let v_dot_h = v.dot(h).clamp(0.0, 1.0);
    let metallic = m.metallic.clamp(0.0, 1.0);
    let s = m.specular_factor.clamp(0.0, 1.0);
    let base = m.base_colour.max(Vec3::ZERO);

    let f_metal = fresnel_schlick(base.min(Vec3::ONE), 1.0, v_dot_h);
    let f_diel = fresnel_schlick(dielectric_f0(m.ior, m.specular_colour), 1.0, v_dot_h);

    let alpha = alpha_from_roughness(m.roughness);
    let dv = ggx_d(alpha, h) * smith_v_correlated(alpha, l.z, v.z);

    let diffuse =
        base * ((1.0 - metallic) * (1.0 - s * max_component(f_diel)) * std::f32::consts::FRAC_1_PI);
    let specular = (f_metal * metallic + f_diel * ((1.0 - metallic) * s)) * dv;
    BrdfLobes { diffuse, specular }
}

/// The BRDF `f(v, l)` (per RGB channel, sr⁻¹): the sum of [`brdf_eval_lobes`].
pub fn brdf_eval(m: &Material, v: Vec3, l: Vec3) -> Vec3 {
    let lobes = brdf_eval_lobes(m, v, l);
    lobes.diffuse + lobes.specular
}

/// Coefficients of [`schlick_hemispherical_mean`] in `t = 1 − n·v`, lowest power first
/// (least-squares fit, maximum error 8·10⁻⁶ over `n·v ∈ [0, 1]`; §6).
/// `SCHLICK_MEAN_C0..C4` are declared in `radcache_shared::consts` (generated for GLSL).
const SCHLICK_MEAN_COEFFS: [f32; 5] = [
    SCHLICK_MEAN_C0,
    SCHLICK_MEAN_C1,
    SCHLICK_MEAN_C2,
    SCHLICK_MEAN_C3,
    SCHLICK_MEAN_C4,
];

/// `W(n·v) = ∫ (1 − v·h)^5 (n·l)/π dl` over the upper hemisphere, `h = normalize(v + l)`: the
/// cosine-weighted mean of Schlick's weight over all light directions, by the degree-4 fit
/// `SCHLICK_MEAN_COEFFS` in `t = 1 − n·v` (`W(1) = 8.2·10⁻⁵`, `W(0) = 0.0282`).
pub fn schlick_hemispherical_mean(n_dot_v: f32) -> f32 {
    let t = 1.0 - n_dot_v.clamp(0.0, 1.0);
    let c = SCHLICK_MEAN_COEFFS;
    c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * c[4])))
}

/// The diffuse lobe's share for the view direction (`n_dot_v = v.z`; 0 below [`COS_MIN`]):
///
/// `share = (1 − metallic) · (1 − s · (F0 + (1 − F0) · W(n·v)))`, `F0 = max(F0_d)`,
///
/// so that the cached indirect diffuse light at a pixel is `share · base · E/π`, `E` the cached
/// irradiance. The diffuse lobe weights each light direction by `1 − s·max(F_d(v·h))`
/// ([`brdf_eval_lobes`]); the factor is its cosine-weighted mean over the hemisphere, which is
/// exact when the incident radiance is uniform (and `max(F_d) = F0 + (1 − F0)(1 − v·h)^5` with
/// the largest channel's F0, Schlick being increasing in F0). For non-uniform light the error
/// in the diffuse radiance is at most `s (1 − F0) max_l (1 − v·h)^5 · base · E/π`, i.e.
/// `(1 − cos(45° + θv/2))^5`: 0.002 at θv = 0°, 0.09 at 45°, 0.22 at 60° (§6). Replacing `v·h`
/// by `n·v` instead (`1 − F(n·v)`) would underestimate the diffuse light at grazing views
/// (0.59 instead of 0.94 at θv = 80°, ior 1.5).
pub fn diffuse_share(m: &Material, n_dot_v: f32) -> f32 {
    if n_dot_v < COS_MIN {
        return 0.0;
    }
    let metallic = m.metallic.clamp(0.0, 1.0);
    let s = m.specular_factor.clamp(0.0, 1.0);
    let f0 = max_component(dielectric_f0(m.ior, m.specular_colour));
    let mean_f = f0 + (1.0 - f0) * schlick_hemispherical_mean(n_dot_v);
    (1.0 - metallic) * (1.0 - s * mean_f)
}
