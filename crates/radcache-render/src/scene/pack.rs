//! Packing of the scene's geometry and materials into the flat GPU layouts.

use glam::Vec3;
use radcache_scene::{AlphaMode, Material, Scene, WrapMode};
use radcache_shared::gpu::{GpuMaterial, GpuMesh, GpuTexture, GpuVertex};

/// Geometry of every mesh in shared buffers.
#[derive(Debug, Default)]
pub(crate) struct PackedGeometry {
    /// All vertices (position + u, normal + v).
    pub vertices: Vec<GpuVertex>,
    /// A tangent per vertex when `normal_maps` was asked for (zero where a mesh has none), else
    /// empty.
    pub tangents: Vec<[f32; 4]>,
    /// Mesh-local indices of all meshes.
    pub indices: Vec<u32>,
    /// Material of every triangle.
    pub tri_materials: Vec<u32>,
    /// Where each mesh starts: first vertex, first index, first triangle, triangle count.
    pub meshes: Vec<GpuMesh>,
}

/// Packs every mesh of `scene`, with tangents when `normal_maps` (`ScenePlan::normal_maps`).
pub(crate) fn pack_geometry(scene: &Scene, normal_maps: bool) -> PackedGeometry {
    let mut vertices = Vec::new();
    let mut tangents = Vec::new();
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
        indices.extend_from_slice(&mesh.indices);
        tri_materials.extend_from_slice(&mesh.triangle_materials);
    }
    PackedGeometry {
        vertices,
        tangents,
        indices,
        tri_materials,
        meshes,
    }
}

/// The alpha test of `m` in `GpuMaterial::textures.w`: 0 none (every point there: opaque, or an
/// untextured alpha that keeps every point), 1 MASK, 2 BLEND.
fn alpha_test(m: &Material) -> i32 {
    if !m.has_alpha() {
        return 0;
    }
    match m.alpha_mode {
        AlphaMode::Opaque => 0,
        AlphaMode::Mask => 1,
        AlphaMode::Blend => 2,
    }
}

/// Whether every triangle of a mesh with per-triangle materials `triangle_materials` is opaque
/// (no alpha test): its BLAS geometry can then be flagged opaque.
pub(crate) fn mesh_is_opaque(scene: &Scene, triangle_materials: &[u32]) -> bool {
    !triangle_materials
        .iter()
        .any(|&m| scene.materials[m as usize].has_alpha())
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
