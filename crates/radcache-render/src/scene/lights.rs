//! Emitters and punctual lights in their GPU layouts.

use glam::Vec2;
use radcache_scene::{EmitterTable, LightKind, Scene, WorldLight};
use radcache_shared::gpu::{GpuEmitter, GpuLight};

/// The emissive triangles of `table` as `GpuEmitter`s: world corners ordered so that the shader's
/// `cross(p1 − p0, p2 − p0)` points to the front side (mirroring transforms included), texture
/// coordinates (TEXCOORD_0, and TEXCOORD_1 where the mesh keeps it: the shader maps them as each
/// texture reference says, the emissive one for the radiance and the base colour one for the
/// coverage of an alpha-tested emitter) and material for textured emission.
pub(crate) fn gpu_emitters(scene: &Scene, table: &EmitterTable) -> Vec<GpuEmitter> {
    table
        .triangles
        .iter()
        .map(|tri| {
            let mesh = &scene.meshes[tri.mesh];
            let idx = &mesh.indices[3 * tri.triangle..3 * tri.triangle + 3];
            // Both sets of texture coordinates of corner k.
            let uv = |k: usize| {
                let i = idx[k] as usize;
                let get = |set: &[Vec2]| set.get(i).copied().unwrap_or_default();
                (get(&mesh.texcoords), get(&mesh.texcoords1))
            };
            let material = mesh.triangle_materials[tri.triangle];
            let [p0, mut p1, mut p2] = tri.positions;
            let (mut c1, mut c2) = (uv(1), uv(2));
            // The shader takes the front side from the corner order: keep it equal to the
            // CPU's normal (which accounts for mirroring transforms).
            if (p1 - p0).cross(p2 - p0).dot(tri.normal) < 0.0 {
                std::mem::swap(&mut p1, &mut p2);
                std::mem::swap(&mut c1, &mut c2);
            }
            let c0 = uv(0);
            let ((uv0, t0), (uv1, t1), (uv2, t2)) = (c0, c1, c2);
            GpuEmitter {
                p0: [p0.x, p0.y, p0.z, tri.area],
                p1: [p1.x, p1.y, p1.z, 0.0],
                p2: [p2.x, p2.y, p2.z, 0.0],
                radiance: [
                    tri.radiance.x,
                    tri.radiance.y,
                    tri.radiance.z,
                    if tri.double_sided { 1.0 } else { 0.0 },
                ],
                uvs: [uv0.x, uv0.y, uv1.x, uv1.y],
                uv2_material: [uv2.x, uv2.y, material as f32, 0.0],
                uvs1: [t0.x, t0.y, t1.x, t1.y],
                uv1_2: [t2.x, t2.y, 0.0, 0.0],
            }
        })
        .collect()
}

/// Punctual lights in world space as `GpuLight`s (KHR_lights_punctual units; spot cones as the
/// extension's recommended angle scale and offset).
pub(crate) fn gpu_lights(lights: &[WorldLight]) -> Vec<GpuLight> {
    lights
        .iter()
        .map(|l| {
            let (kind, spot) = match l.kind {
                LightKind::Point => (0.0, [0.0; 4]),
                LightKind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => {
                    // glTF KHR_lights_punctual's recommended falloff.
                    let scale = 1.0 / (inner_cone_angle.cos() - outer_cone_angle.cos()).max(0.001);
                    (1.0, [scale, -outer_cone_angle.cos() * scale, 0.0, 0.0])
                }
                LightKind::Directional => (2.0, [0.0; 4]),
            };
            let i = l.color * l.intensity;
            GpuLight {
                position: [l.position.x, l.position.y, l.position.z, kind],
                direction: [
                    l.direction.x,
                    l.direction.y,
                    l.direction.z,
                    l.range.unwrap_or(0.0),
                ],
                intensity: [i.x, i.y, i.z, 0.0],
                spot,
            }
        })
        .collect()
}
