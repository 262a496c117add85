//! Packing of the scene's geometry and materials into the flat GPU layouts.

use glam::Vec3;
use radcache_scene::{AlphaMode, Material, Scene, TextureRef, WrapMode};
use radcache_shared::consts::{ALPHA_BLEND, ALPHA_MASK, ALPHA_NONE};
use radcache_shared::gpu::{GpuMaterial, GpuMesh, GpuTexture, GpuUvMap, GpuVertex};

/// Geometry of every mesh in shared buffers.
#[derive(Debug, Default)]
pub(crate) struct PackedGeometry {
    /// All vertices (position + u, normal + v).
    pub vertices: Vec<GpuVertex>,
    /// A tangent per vertex when `normal_maps` was asked for (zero where a mesh has none), else
    /// empty.
    pub tangents: Vec<[f32; 4]>,
    /// TEXCOORD_1 per vertex when `texcoord1` was asked for (zero where a mesh has none), else
    /// empty.
    pub texcoords1: Vec<[f32; 2]>,
    /// Mesh-local indices of all meshes.
    pub indices: Vec<u32>,
    /// Material of every triangle.
    pub tri_materials: Vec<u32>,
    /// Where each mesh starts: first vertex, first index, first triangle, triangle count.
    pub meshes: Vec<GpuMesh>,
}

/// Packs every mesh of `scene`, with tangents when `normal_maps` (`ScenePlan::normal_maps`) and
/// TEXCOORD_1 when `texcoord1` (`ScenePlan::texcoord1`).
pub(crate) fn pack_geometry(scene: &Scene, normal_maps: bool, texcoord1: bool) -> PackedGeometry {
    let mut vertices = Vec::new();
    let mut tangents = Vec::new();
    let mut texcoords1 = Vec::new();
    let mut indices = Vec::new();
    let mut tri_materials = Vec::new();
    let mut meshes = Vec::with_capacity(scene.meshes.len());
    for mesh in &scene.meshes {
        meshes.push(GpuMesh {
            ranges: [
                vertices.len() as u32,
                indices.len() as u32,
                tri_materials.len() as u32,
                mesh.triangle_count() as u32,
            ],
        });
        for (i, p) in mesh.positions.iter().enumerate() {
            let n = mesh.normals.get(i).copied().unwrap_or(Vec3::ZERO);
            let uv = mesh.texcoords.get(i).copied().unwrap_or_default();
            vertices.push(GpuVertex {
                position_u: [p.x, p.y, p.z, uv.x],
                normal_v: [n.x, n.y, n.z, uv.y],
            });
        }
        if normal_maps {
            let t = |i: usize| mesh.tangents.get(i).map_or([0.0; 4], |t| t.to_array());
            tangents.extend((0..mesh.positions.len()).map(t));
        }
        if texcoord1 {
            let t = |i: usize| mesh.texcoords1.get(i).map_or([0.0; 2], |t| t.to_array());
            texcoords1.extend((0..mesh.positions.len()).map(t));
        }
        indices.extend_from_slice(&mesh.indices);
        tri_materials.extend_from_slice(&mesh.triangle_materials);
    }
    PackedGeometry {
        vertices,
        tangents,
        texcoords1,
        indices,
        tri_materials,
        meshes,
    }
}

/// The alpha test of `m` in `GpuMaterial::textures.w`: [`ALPHA_NONE`] (every point there:
/// opaque, or an untextured alpha that keeps every point), [`ALPHA_MASK`] or [`ALPHA_BLEND`].
fn alpha_test(m: &Material) -> i32 {
    if !m.has_alpha() {
        return ALPHA_NONE;
    }
    match m.alpha_mode {
        AlphaMode::Opaque => ALPHA_NONE,
        AlphaMode::Mask => ALPHA_MASK,
        AlphaMode::Blend => ALPHA_BLEND,
    }
}

/// Whether every triangle of a mesh with per-triangle materials `triangle_materials` is opaque
/// (no alpha test): its BLAS geometry can then be flagged opaque.
pub(crate) fn mesh_is_opaque(scene: &Scene, triangle_materials: &[u32]) -> bool {
    !triangle_materials
        .iter()
        .any(|&m| scene.materials[m as usize].has_alpha())
}

/// The texture coordinates of reference `t` (set 0 and the identity for none).
fn uv_map(t: Option<TextureRef>) -> GpuUvMap {
    let t = t.unwrap_or(TextureRef::new(0));
    let [u, v] = t.transform.matrix();
    GpuUvMap {
        row_u: [u[0], u[1], u[2], t.tex_coord as f32],
        row_v: [v[0], v[1], v[2], 0.0],
    }
}

/// Materials, texture descriptors and the shared RGBA8 texel array.
pub(crate) fn pack_materials(scene: &Scene) -> (Vec<GpuMaterial>, Vec<GpuTexture>, Vec<u32>) {
    let materials: Vec<GpuMaterial> = scene
        .materials
        .iter()
        .zip(&scene.material_emission)
        .map(|(m, e)| GpuMaterial {
            base_color: m.base_color.to_array(),
            emission: [
                m.emissive.x,
                m.emissive.y,
                m.emissive.z,
                if m.double_sided { 1.0 } else { 0.0 },
            ],
            textures: [
                m.base_color_texture.map_or(-1, |t| t.texture as i32),
                m.emissive_texture.map_or(-1, |t| t.texture as i32),
                m.metallic_roughness_texture
                    .map_or(-1, |t| t.texture as i32),
                alpha_test(m),
            ],
            params: [
                m.metallic,
                m.roughness,
                radcache_scene::luminance(*e),
                m.ior,
            ],
            specular: [
                m.specular_color.x,
                m.specular_color.y,
                m.specular_color.z,
                m.specular_factor,
            ],
            alpha: [m.alpha_cutoff, 0.0, 0.0, 0.0],
            normal_map: [
                m.normal_texture.map_or(-1.0, |t| t.texture as f32),
                m.normal_scale,
                0.0,
                0.0,
            ],
            base_color_uv: uv_map(m.base_color_texture),
            emissive_uv: uv_map(m.emissive_texture),
            metallic_roughness_uv: uv_map(m.metallic_roughness_texture),
            normal_uv: uv_map(m.normal_texture),
        })
        .collect();
    let mut texels: Vec<u32> = Vec::new();
    let mut image_offsets = Vec::with_capacity(scene.images.len());
    for image in &scene.images {
        image_offsets.push(texels.len() as u32);
        texels.extend(
            image
                .rgba8
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        );
    }
    let wrap = |w: WrapMode| match w {
        WrapMode::Repeat => 0u32,
        WrapMode::ClampToEdge => 1,
        WrapMode::MirroredRepeat => 2,
    };
    let textures: Vec<GpuTexture> = scene
        .textures
        .iter()
        .map(|t| {
            let image = &scene.images[t.image];
            let srgb = if image.srgb { 0x100 } else { 0 };
            GpuTexture {
                info: [
                    image_offsets[t.image],
                    image.width,
                    image.height,
                    wrap(t.wrap_s)
                        | (wrap(t.wrap_t) << 4)
                        | srgb
                        | if t.nearest { 0x200 } else { 0 },
                ],
            }
        })
        .collect();
    (materials, textures, texels)
}

#[cfg(test)]
mod tests {
    use glam::Vec2;
    use radcache_scene::TextureTransform;

    use super::*;

    #[test]
    fn a_reference_packs_its_set_and_its_matrix_rows() {
        let t = TextureRef {
            texture: 2,
            tex_coord: 1,
            transform: TextureTransform {
                offset: Vec2::new(0.25, -0.5),
                rotation: 0.5,
                scale: Vec2::new(2.0, 3.0),
            },
        };
        let m = uv_map(Some(t));
        let (s, c) = 0.5f32.sin_cos();
        assert_eq!(m.row_u, [2.0 * c, 3.0 * s, 0.25, 1.0]);
        assert_eq!(m.row_v, [-2.0 * s, 3.0 * c, -0.5, 0.0]);
        // The rows give what the CPU transform gives.
        let uv = Vec2::new(0.3, 0.7);
        let p = [uv.x, uv.y, 1.0];
        let dot = |r: [f32; 4]| r[0] * p[0] + r[1] * p[1] + r[2] * p[2];
        let got = Vec2::new(dot(m.row_u), dot(m.row_v));
        assert!((got - t.transform.apply(uv)).abs().max_element() < 1e-6);
        let none = uv_map(None);
        assert_eq!(
            (none.row_u, none.row_v),
            ([1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0])
        );
    }
}
