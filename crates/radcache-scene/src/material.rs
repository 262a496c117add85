//! Metallic-roughness materials and the emission rule.
//!
//! Units: `emissive` is radiance in W/(sr·m²) (linear RGB): glTF `emissiveFactor` ×
//! `KHR_materials_emissive_strength.emissiveStrength` (× the emissive texture, if any, per texel).
//! Base colour factors are linear; base-colour and emissive textures are sRGB-encoded.
//! A negative `emissiveStrength` (the extension requires ≥ 0) makes the material non-emissive
//! with a warning, as non-finite factors do.
//!
//! **Emission rule.** An emissive triangle emits from its front face — the side from which its
//! vertices appear counter-clockwise, i.e. the side its geometric normal `(p1-p0)×(p2-p0)` points
//! to (flipped for instances whose transform has a negative determinant, per the glTF spec) — or
//! from both faces when the material is `doubleSided`. See [`emitted_radiance`].
//!
//! Alpha modes MASK and BLEND are rendered opaque (warning). Primitives without a material use
//! [`Material::default_material`]: a grey diffuse (base colour 0.8, metallic 0, roughness 1). This
//! deviates from the spec's default (metallic 1), which would be black in a diffuse-only renderer.

use glam::{Vec3, Vec4};

use crate::error::{label, Result, WarningKind, Warnings};
use crate::resources::Source;
use crate::texture::{TextureLoader, TextureRef};

/// A metallic-roughness material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// glTF material name.
    pub name: Option<String>,
    /// Linear base colour factor (RGBA).
    pub base_color: Vec4,
    /// Base colour texture (sRGB), multiplied with `base_color`.
    pub base_color_texture: Option<TextureRef>,
    /// Metallic factor in `[0, 1]`.
    pub metallic: f32,
    /// Roughness factor in `[0, 1]`.
    pub roughness: f32,
    /// Metallic-roughness texture (linear; B = metallic, G = roughness).
    pub metallic_roughness_texture: Option<TextureRef>,
    /// Index of refraction of the dielectric layer (`KHR_materials_ior`, default 1.5), ≥ 1.
    pub ior: f32,
    /// Strength of the dielectric's specular layer (`KHR_materials_specular.specularFactor`,
    /// default 1) in `[0, 1]`. 0 with metallic 0 makes the material exactly Lambertian.
    pub specular_factor: f32,
    /// Colour of the dielectric's F0 (`KHR_materials_specular.specularColorFactor`, linear,
    /// default 1).
    pub specular_color: Vec3,
    /// Emitted radiance W/(sr·m²): emissive factor × emissive strength.
    pub emissive: Vec3,
    /// Emissive texture (sRGB), multiplied with `emissive`.
    pub emissive_texture: Option<TextureRef>,
    /// Tangent-space normal map (linear; glTF `normalTexture`, docs/materials.md §12).
    pub normal_texture: Option<TextureRef>,
    /// `normalTexture.scale` (default 1): scales the map's x and y.
    pub normal_scale: f32,
    /// Whether both faces are shaded and (if emissive) emit.
    pub double_sided: bool,
}

impl Material {
    /// The material of primitives that have none (see module docs).
    pub fn default_material() -> Material {
        Material {
            name: Some("default".into()),
            base_color: Vec4::new(0.8, 0.8, 0.8, 1.0),
            base_color_texture: None,
            metallic: 0.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            ior: 1.5,
            specular_factor: 1.0,
            specular_color: Vec3::ONE,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            double_sided: false,
        }
    }

    /// Diffuse albedo of the untextured material: base colour × (1 − metallic).
    pub fn diffuse_albedo(&self) -> Vec3 {
        self.base_color.truncate() * (1.0 - self.metallic.clamp(0.0, 1.0))
    }

    /// True when the material reflects as a Lambertian surface alone: metallic 0 and no
    /// specular layer (`specularFactor` 0), so that the glTF BRDF is exactly `base colour/π`
    /// (docs/materials.md §4.2). A scene whose materials are all Lambertian compiles no
    /// specular code (`ScenePlan::specular`).
    pub fn is_lambertian(&self) -> bool {
        self.metallic == 0.0 && self.specular_factor == 0.0
    }

    /// True when the material emits light (non-zero `emissive`).
    pub fn is_emissive(&self) -> bool {
        self.emissive.max_element() > 0.0
    }
}

/// Radiance emitted by a surface point with unit front normal `normal` towards direction `dir`
/// (pointing away from the surface, towards the viewer): `radiance` on the front side
/// (`dot(normal, dir) > 0`), on the back side only when `double_sided`, else zero.
pub fn emitted_radiance(normal: Vec3, radiance: Vec3, double_sided: bool, dir: Vec3) -> Vec3 {
    let c = normal.dot(dir);
    if c > 0.0 || (double_sided && c < 0.0) {
        radiance
    } else {
        Vec3::ZERO
    }
}

/// Loads all glTF materials in order (the default material is appended by the caller if used).
pub(crate) fn load_materials(
    src: &Source,
    textures: &mut TextureLoader,
    warnings: &mut Warnings,
) -> Result<Vec<Material>> {
    let mut out = Vec::new();
    for m in src.doc.materials() {
        let index = m.index().unwrap_or(out.len());
        let user = label("material", index, m.name());
        let file = src.path.display();
        match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => {}
            mode => {
                let msg = format!("{file}: {user}: alpha mode {mode:?} rendered opaque");
                warnings.push(WarningKind::AlphaModeIgnored, 1, msg);
            }
        }
        let pbr = m.pbr_metallic_roughness();
        let mut strength = m.emissive_strength().unwrap_or(1.0);
        if strength < 0.0 {
            let msg = format!(
                "{file}: {user}: negative emissiveStrength {strength}; using 0 (not emissive)"
            );
            warnings.push(WarningKind::Other, 1, msg);
            strength = 0.0;
        }
        let emissive = Vec3::from(m.emissive_factor()) * strength;
        let base_color = Vec4::from(pbr.base_color_factor());
        let mut sane = |v: f32, what: &str, lo: f32, hi: f32| -> f32 {
            if v.is_finite() {
                v.clamp(lo, hi)
            } else {
                warnings.push(
                    WarningKind::Other,
                    1,
                    format!("{file}: {user}: non-finite {what}; using {lo}"),
                );
                lo
            }
        };
        let base_color = Vec4::from_array(
            base_color
                .to_array()
                .map(|c| sane(c, "base colour", 0.0, 1.0)),
        );
        let emissive = Vec3::from_array(
            emissive
                .to_array()
                .map(|c| sane(c, "emission", 0.0, f32::MAX)),
        );
        let metallic = sane(pbr.metallic_factor(), "metallic factor", 0.0, 1.0);
        let roughness = sane(pbr.roughness_factor(), "roughness factor", 0.0, 1.0);
        out.push(Material {
            name: m.name().map(str::to_string),
            base_color,
            base_color_texture: textures.get(
                src,
                pbr.base_color_texture(),
                true,
                &user,
                warnings,
            )?,
            metallic,
            roughness,
            metallic_roughness_texture: textures.get(
                src,
                pbr.metallic_roughness_texture(),
                false,
                &user,
                warnings,
            )?,
            ior: 1.5,
            specular_factor: 1.0,
            specular_color: Vec3::ONE,
            emissive,
            emissive_texture: textures.get(src, m.emissive_texture(), true, &user, warnings)?,
            normal_texture: textures.get_normal(src, m.normal_texture(), &user, warnings)?,
            normal_scale: m.normal_texture().map_or(1.0, |t| t.scale()),
            double_sided: m.double_sided(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn albedo_and_emission_rule() {
        let mut m = Material::default_material();
        m.base_color = Vec4::new(0.5, 0.4, 0.2, 1.0);
        m.metallic = 0.25;
        assert!((m.diffuse_albedo() - Vec3::new(0.375, 0.3, 0.15)).length() < 1e-6);
        let le = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(emitted_radiance(Vec3::Z, le, false, Vec3::Z), le);
        assert_eq!(emitted_radiance(Vec3::Z, le, false, -Vec3::Z), Vec3::ZERO);
        assert_eq!(emitted_radiance(Vec3::Z, le, true, -Vec3::Z), le);
        assert_eq!(emitted_radiance(Vec3::Z, le, true, Vec3::X), Vec3::ZERO);
    }
}
