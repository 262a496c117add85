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
//! **Extensions.** `KHR_materials_ior` gives `ior` (values below 1 are clamped to 1; 0 is the
//! extension's specular-glossiness compatibility mode, an infinite ior, stored as [`IOR_INFINITE`]).
//! `KHR_materials_specular` gives `specular_factor` and `specular_color`; its two textures are not
//! sampled (warning; the factors are used). A material without `KHR_materials_specular` has the
//! specification's specular layer (F0 0.04): only `specularFactor` 0 with metallic 0 is exactly
//! Lambertian. Other material extensions (transmission, volume, clearcoat, sheen, ...) are not
//! implemented: such materials render with the core model, and the file's [`MaterialNotes`] name
//! each extension once (warning and `radcache info`).
//!
//! **Texture references** ([`TextureRef`]) sample TEXCOORD_0 or TEXCOORD_1 (`texCoord`; a set
//! above 1 drops the texture with a warning) through their `KHR_texture_transform`, whose
//! `texCoord` overrides the reference's (docs/materials.md §13), on every slot radcache samples:
//! base colour, metallic-roughness, normal and emissive.
//! Occlusion textures are not used: a global-illumination renderer computes occlusion itself.
//!
//! Alpha modes (docs/materials.md §11): MASK keeps a point whose alpha (base colour factor alpha ×
//! base colour texture alpha) is at least `alphaCutoff` (default 0.5); BLEND keeps it with
//! probability alpha (stochastic coverage). Primitives without a material use
//! [`Material::default_material`], the specification's default: base colour 1, metallic 1,
//! roughness 1.

use std::collections::BTreeMap;

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
    /// Index of refraction of the dielectric layer (`KHR_materials_ior`, default 1.5), ≥ 1;
    /// [`IOR_INFINITE`] for the extension's `ior: 0`.
    pub ior: f32,
    /// Strength of the dielectric's specular layer (`KHR_materials_specular.specularFactor`,
    /// default 1) in `[0, 1]`. 0 with metallic 0 makes the material exactly Lambertian.
    pub specular_factor: f32,
    /// Colour of the dielectric's F0 (`KHR_materials_specular.specularColorFactor`, linear,
    /// default 1), ≥ 0; may exceed 1 (the BRDF clamps F0 to 1).
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
    /// glTF `alphaMode`.
    pub alpha_mode: AlphaMode,
    /// glTF `alphaCutoff` (MASK only; default 0.5).
    pub alpha_cutoff: f32,
}

/// glTF `alphaMode`: how the alpha of the base colour (factor × texture) makes a surface point
/// present or missing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlphaMode {
    /// Every point is there (alpha ignored).
    #[default]
    Opaque,
    /// A point is there when its alpha is at least the cutoff.
    Mask,
    /// A point is there with probability alpha (stochastic coverage).
    Blend,
}

/// The `ior` that stands for `KHR_materials_ior`'s `ior: 0` (an infinite index of refraction,
/// Fresnel term 1): large enough that `((ior − 1)/(ior + 1))²` is exactly 1 in f32, small enough
/// that `1/ior` stays a normal f32.
pub const IOR_INFINITE: f32 = 1e9;

/// Material extensions the loader reads (`KHR_texture_transform` on texture references). Any
/// other extension on a material or on one of its texture references is reported in
/// [`MaterialNotes`].
pub const IMPLEMENTED_MATERIAL_EXTENSIONS: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_texture_transform",
];

/// What the file's materials ask for that radcache does not render (summary and `radcache info`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MaterialNotes {
    /// Extensions used by materials that radcache does not implement, sorted by name, each with
    /// the number of materials using it.
    pub unsupported_extensions: Vec<(String, usize)>,
    /// Number of materials with an occlusion texture (not used: occlusion is computed).
    pub occlusion_textures: usize,
}

impl Material {
    /// The material of primitives that have none: the glTF specification's default (base colour
    /// 1, metallic 1, roughness 1, no emission), a rough white metal.
    pub fn default_material() -> Material {
        Material {
            name: Some("default".into()),
            base_color: Vec4::ONE,
            base_color_texture: None,
            metallic: 1.0,
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
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
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

    /// True when some point of the surface may be missing: alpha mode MASK or BLEND, unless the
    /// alpha is the constant factor (no base colour texture) and keeps every point (MASK with
    /// factor ≥ cutoff, BLEND with factor 1). Such materials need the alpha test in every ray
    /// query and the G-buffer (`ScenePlan::alpha`); the others are opaque.
    pub fn has_alpha(&self) -> bool {
        let a = self.base_color.w;
        let textured = self.base_color_texture.is_some();
        match self.alpha_mode {
            AlphaMode::Opaque => false,
            AlphaMode::Mask => textured || a < self.alpha_cutoff,
            AlphaMode::Blend => textured || a < 1.0,
        }
    }

    /// True when the material emits light (non-zero `emissive`).
    pub fn is_emissive(&self) -> bool {
        self.emissive.max_element() > 0.0
    }

    /// The texture references radcache samples: base colour, metallic-roughness, emissive and
    /// normal, those that are set.
    pub fn texture_refs(&self) -> impl Iterator<Item = TextureRef> {
        [
            self.base_color_texture,
            self.metallic_roughness_texture,
            self.emissive_texture,
            self.normal_texture,
        ]
        .into_iter()
        .flatten()
    }

    /// True when some texture reference samples TEXCOORD_1: the material's primitives keep it.
    pub fn uses_texcoord1(&self) -> bool {
        self.texture_refs().any(|t| t.tex_coord == 1)
    }

    /// True when some texture reference has a `KHR_texture_transform` other than the identity.
    pub fn has_uv_transform(&self) -> bool {
        self.texture_refs().any(|t| !t.transform.is_identity())
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

/// Loads all glTF materials in order (the default material is appended by the caller if used),
/// and notes what they use that is not rendered.
pub(crate) fn load_materials(
    src: &Source,
    textures: &mut TextureLoader,
    warnings: &mut Warnings,
) -> Result<(Vec<Material>, MaterialNotes)> {
    let mut out = Vec::new();
    let file = src.path.display();
    // Unsupported extension → labels of the materials using it.
    let mut unsupported: BTreeMap<&str, Vec<String>> = BTreeMap::new();
    let mut occlusion_textures = 0;
    for m in src.doc.materials() {
        let index = m.index().unwrap_or(out.len());
        let user = label("material", index, m.name());
        let raw = src.raw_materials.get(index);
        for name in raw.into_iter().flat_map(|r| &r.extensions) {
            if !IMPLEMENTED_MATERIAL_EXTENSIONS.contains(&name.as_str()) {
                unsupported.entry(name).or_default().push(user.clone());
            }
        }
        if m.occlusion_texture().is_some() {
            occlusion_textures += 1;
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
        // Clamps `v` to `[lo, hi]`; a non-finite `v` becomes `fallback` with a warning.
        let mut sane = |v: f32, what: &str, lo: f32, hi: f32, fallback: f32| -> f32 {
            if v.is_finite() {
                v.clamp(lo, hi)
            } else {
                warnings.push(
                    WarningKind::Other,
                    1,
                    format!("{file}: {user}: non-finite {what}; using {fallback}"),
                );
                fallback
            }
        };
        let base_color = Vec4::from_array(
            base_color
                .to_array()
                .map(|c| sane(c, "base colour", 0.0, 1.0, 0.0)),
        );
        let emissive = Vec3::from_array(
            emissive
                .to_array()
                .map(|c| sane(c, "emission", 0.0, f32::MAX, 0.0)),
        );
        let metallic = sane(pbr.metallic_factor(), "metallic factor", 0.0, 1.0, 0.0);
        let roughness = sane(pbr.roughness_factor(), "roughness factor", 0.0, 1.0, 0.0);
        let ior = match m.ior() {
            None => 1.5,
            Some(0.0) => IOR_INFINITE,
            Some(v) => sane(v, "ior", 1.0, IOR_INFINITE, 1.5),
        };
        let specular = m.specular();
        let (specular_factor, specular_color) = match &specular {
            None => (1.0, Vec3::ONE),
            Some(sp) => (
                sane(sp.specular_factor(), "specularFactor", 0.0, 1.0, 1.0),
                Vec3::from_array(
                    sp.specular_color_factor()
                        .map(|c| sane(c, "specularColorFactor", 0.0, f32::MAX, 1.0)),
                ),
            ),
        };
        if let Some(sp) = &specular {
            let ignored: Vec<&str> = [
                ("specularTexture", sp.specular_texture().is_some()),
                (
                    "specularColorTexture",
                    sp.specular_color_texture().is_some(),
                ),
            ]
            .into_iter()
            .filter_map(|(name, present)| present.then_some(name))
            .collect();
            if !ignored.is_empty() {
                let msg = format!(
                    "{file}: {user}: KHR_materials_specular {} not supported; using the factors",
                    ignored.join(" and ")
                );
                warnings.push(WarningKind::TextureIgnored, 1, msg);
            }
        }
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
            ior,
            specular_factor,
            specular_color,
            emissive,
            emissive_texture: textures.get(src, m.emissive_texture(), true, &user, warnings)?,
            normal_texture: textures.get_normal(
                src,
                m.normal_texture(),
                raw.and_then(|r| r.normal_texture_transform.as_ref()),
                &user,
                warnings,
            )?,
            normal_scale: m.normal_texture().map_or(1.0, |t| t.scale()),
            double_sided: m.double_sided(),
            alpha_mode: match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => AlphaMode::Mask,
                gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            },
            alpha_cutoff: m.alpha_cutoff().unwrap_or(0.5),
        });
    }
    for (name, users) in &unsupported {
        let n = users.len();
        let msg = format!(
            "{file}: extension {name} is not implemented ({n} material{}: {}); they render with the core metallic-roughness model",
            if n == 1 { "" } else { "s" },
            users.join(", ")
        );
        warnings.push(WarningKind::MaterialExtensionIgnored, n, msg);
    }
    let notes = MaterialNotes {
        unsupported_extensions: unsupported
            .into_iter()
            .map(|(name, users)| (name.to_string(), users.len()))
            .collect(),
        occlusion_textures,
    };
    Ok((out, notes))
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
