//! Plain descriptions of glTF elements handed to [`GltfBuilder`](super::GltfBuilder).

use crate::animation::{Interpolation, Property};
use crate::light::LightKind;
use crate::texture::TextureTransform;

/// Index component type of a primitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IndexFormat {
    /// The smallest of u16/u32 that fits (u8 is allowed by glTF but discouraged by the validator).
    #[default]
    Auto,
    /// Unsigned byte.
    U8,
    /// Unsigned short.
    U16,
    /// Unsigned int.
    U32,
}

/// A metallic-roughness material.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDesc {
    /// Name.
    pub name: String,
    /// Linear base colour factor.
    pub base_color: [f32; 4],
    /// Metallic factor.
    pub metallic: f32,
    /// Roughness factor.
    pub roughness: f32,
    /// Emitted radiance W/(sr·m²) (split into factor × strength on write).
    pub emissive: [f32; 3],
    /// Double-sided flag.
    pub double_sided: bool,
    /// Base colour texture index (from [`GltfBuilder::add_texture_rgba8`](super::GltfBuilder::add_texture_rgba8)).
    pub base_color_texture: Option<usize>,
    /// Emissive texture index.
    pub emissive_texture: Option<usize>,
    /// Metallic-roughness texture index (linear; G = roughness, B = metallic).
    pub metallic_roughness_texture: Option<usize>,
    /// `KHR_materials_specular.specularFactor`: 0 makes a metallic-0 material exactly Lambertian;
    /// 1 (the specification's default, F0 0.04 at ior 1.5) writes no extension.
    pub specular: f32,
    /// `KHR_materials_ior.ior`, written when set (the default is 1.5).
    pub ior: Option<f32>,
    /// Normal texture index and its `scale`.
    pub normal_texture: Option<(usize, f32)>,
    /// `alphaMode` other than OPAQUE (e.g. `"BLEND"`), for tests.
    pub alpha_mode: Option<String>,
    /// `alphaCutoff` (written when set).
    pub alpha_cutoff: Option<f32>,
    /// How the base colour texture maps texture coordinates.
    pub base_color_uv: TexCoordDesc,
    /// How the emissive texture maps texture coordinates.
    pub emissive_uv: TexCoordDesc,
    /// How the metallic-roughness texture maps texture coordinates.
    pub metallic_roughness_uv: TexCoordDesc,
    /// How the normal texture maps texture coordinates.
    pub normal_uv: TexCoordDesc,
}

/// How a material's texture reference maps texture coordinates: its `texCoord` and its
/// `KHR_texture_transform`, written on its textureInfo.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoordDesc {
    /// `texCoord` of the textureInfo (written when not 0).
    pub tex_coord: u32,
    /// `KHR_texture_transform`'s offset, rotation and scale (written when set).
    pub transform: Option<TextureTransform>,
    /// `KHR_texture_transform`'s `texCoord`, which overrides `tex_coord` (written when set, with
    /// the transform or with an identity one).
    pub transform_tex_coord: Option<u32>,
}

impl MaterialDesc {
    /// A Lambertian material of linear albedo `rgb`: metallic 0, roughness 1 and specular 0
    /// (written as `KHR_materials_specular.specularFactor` 0, without which glTF has a specular
    /// layer).
    pub fn diffuse(name: &str, rgb: [f32; 3]) -> MaterialDesc {
        MaterialDesc {
            name: name.into(),
            base_color: [rgb[0], rgb[1], rgb[2], 1.0],
            metallic: 0.0,
            roughness: 1.0,
            emissive: [0.0; 3],
            double_sided: false,
            base_color_texture: None,
            emissive_texture: None,
            metallic_roughness_texture: None,
            specular: 0.0,
            ior: None,
            normal_texture: None,
            alpha_mode: None,
            alpha_cutoff: None,
            base_color_uv: TexCoordDesc::default(),
            emissive_uv: TexCoordDesc::default(),
            metallic_roughness_uv: TexCoordDesc::default(),
            normal_uv: TexCoordDesc::default(),
        }
    }

    /// A metallic-roughness material with the specification's specular layer (specular 1, no
    /// extension written).
    pub fn metal_rough(name: &str, rgb: [f32; 3], metallic: f32, roughness: f32) -> MaterialDesc {
        MaterialDesc {
            metallic,
            roughness,
            specular: 1.0,
            ..MaterialDesc::diffuse(name, rgb)
        }
    }

    /// A Lambertian material that also emits `radiance`.
    pub fn emitter(name: &str, rgb: [f32; 3], radiance: [f32; 3]) -> MaterialDesc {
        MaterialDesc {
            emissive: radiance,
            ..MaterialDesc::diffuse(name, rgb)
        }
    }
}

/// One primitive of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveDesc {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals (optional).
    pub normals: Option<Vec<[f32; 3]>>,
    /// TEXCOORD_0 (optional).
    pub texcoords: Option<Vec<[f32; 2]>>,
    /// TEXCOORD_1 (optional).
    pub texcoords1: Option<Vec<[f32; 2]>>,
    /// TANGENT (optional).
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Indices (optional: non-indexed).
    pub indices: Option<Vec<u32>>,
    /// Index component type.
    pub index_format: IndexFormat,
    /// Material index.
    pub material: Option<usize>,
    /// Primitive mode (4 = TRIANGLES).
    pub mode: u32,
}

impl PrimitiveDesc {
    /// An indexed triangle primitive.
    pub fn triangles(
        positions: Vec<[f32; 3]>,
        normals: Option<Vec<[f32; 3]>>,
        indices: Vec<u32>,
        material: Option<usize>,
    ) -> PrimitiveDesc {
        PrimitiveDesc {
            positions,
            normals,
            texcoords: None,
            texcoords1: None,
            tangents: None,
            indices: Some(indices),
            index_format: IndexFormat::Auto,
            material,
            mode: 4,
        }
    }
}

/// A node.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeDesc {
    /// Name.
    pub name: Option<String>,
    /// Translation.
    pub translation: Option<[f32; 3]>,
    /// Rotation quaternion (x, y, z, w).
    pub rotation: Option<[f32; 4]>,
    /// Scale.
    pub scale: Option<[f32; 3]>,
    /// Column-major matrix (instead of TRS).
    pub matrix: Option<[f32; 16]>,
    /// Mesh index.
    pub mesh: Option<usize>,
    /// Camera index.
    pub camera: Option<usize>,
    /// Punctual light index.
    pub light: Option<usize>,
    /// Child node indices.
    pub children: Vec<usize>,
}

/// A punctual light.
#[derive(Clone, Debug, PartialEq)]
pub struct LightDesc {
    /// Name.
    pub name: Option<String>,
    /// Kind (and spot cone angles).
    pub kind: LightKind,
    /// Linear colour.
    pub color: [f32; 3],
    /// Candela (point/spot) or lux (directional).
    pub intensity: f32,
    /// Range (m).
    pub range: Option<f32>,
}

/// One animation channel (its sampler is written alongside).
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelDesc {
    /// Target node.
    pub node: usize,
    /// Target property.
    pub property: Property,
    /// Interpolation.
    pub interpolation: Interpolation,
    /// Key times (s).
    pub times: Vec<f32>,
    /// Flat output values: 3 or 4 per element; CUBICSPLINE has 3 elements per key (in, value, out).
    pub values: Vec<f32>,
}
