//! Fresnel terms (`docs/materials.md` §2).

use glam::Vec3;

/// Schlick's weight `(1 − cosθ)^5`, with `cosθ` clamped to `[0, 1]`.
///
/// Source: C. Schlick, *An Inexpensive BRDF Model for Physically-based Rendering*, 1994;
/// glTF 2.0 specification, Appendix B (Fresnel).
pub fn schlick_weight(cos_theta: f32) -> f32 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's approximation `F = F0 + (F90 − F0)(1 − cosθ)^5`, per channel.
///
/// `cos_theta` is `|v·h|` for a microfacet (glTF Appendix B); `F(1) = F0`, `F(0) = F90`.
pub fn fresnel_schlick(f0: Vec3, f90: f32, cos_theta: f32) -> Vec3 {
    f0 + (Vec3::splat(f90) - f0) * schlick_weight(cos_theta)
}

/// Reflectance at normal incidence of a dielectric of index `ior` in air:
/// `F0 = ((ior − 1)/(ior + 1))²` (glTF Appendix B; `KHR_materials_ior`). 1.5 gives 0.04.
/// `ior` values below 1 are clamped to 1 (`F0 = 0`).
pub fn f0_from_ior(ior: f32) -> f32 {
    let ior = ior.max(1.0);
    let r = (ior - 1.0) / (ior + 1.0);
    r * r
}

/// The dielectric F0 of `KHR_materials_specular`: `min(F0(ior) · specularColor, 1)` per channel.
/// The specular factor (the extension's `specular`) is applied by the caller, as a weight of the
/// whole Fresnel mix ([`crate::brdf`]).
pub fn dielectric_f0(ior: f32, specular_colour: Vec3) -> Vec3 {
    (specular_colour.max(Vec3::ZERO) * f0_from_ior(ior)).min(Vec3::ONE)
}

/// The largest of the three channels (the extension's `max_value`).
pub fn max_component(c: Vec3) -> f32 {
    c.x.max(c.y).max(c.z)
}

/// The mean of the three channels.
pub fn mean_component(c: Vec3) -> f32 {
    (c.x + c.y + c.z) * (1.0 / 3.0)
}
