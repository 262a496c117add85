//! The scene on the GPU: vertex, index, material, texture, light and environment buffers, one
//! BLAS per mesh, and a TLAS of the instances at the current time.
//!
//! Geometry is static per mesh (no skinning or morphing), so BLASes are built once; when time
//! moves, only what changed is redone: instance transforms are rewritten and the TLAS is refitted
//! (rebuilt every [`REFITS_PER_REBUILD`] refits, so its quality does not decay over long
//! animations); emitters and lights are rewritten only when an emissive instance or a light node
//! moved. Host-visible buffers are written directly: call [`GpuScene::set_time`] and
//! [`GpuScene::set_view`] only between submissions that read the scene.

use glam::{Mat3, Mat4, Vec3};
use radcache_scene::{Environment, Scene, ScenePlan};
use radcache_shared::gpu::{
    FrameConstants, GpuAlias, GpuEmitter, GpuInstance, GpuLight, GpuMesh, GpuVertex,
};
use radcache_vk::{
    vk, Blas, BlasBuildStats, BlasGeometry, BlasShape, Buffer, Context, Recorder, Tlas,
    TlasInstance, TlasUpdate,
};

use crate::error::Result;
use crate::scene::budget::MemoryNeed;
use crate::scene::env_map::{gpu_alias, EnvMap};
use crate::scene::lights::{gpu_emitters, gpu_lights};
use crate::scene::pack::{mesh_is_opaque, pack_geometry, pack_materials, PackedGeometry};
use crate::scene::upload::{cols, host_buffer, rows3x4, storage};

pub mod budget;
pub(crate) mod env_map;
pub mod features;
pub(crate) mod lights;
pub(crate) mod pack;
pub(crate) mod upload;
mod view;

/// A full TLAS rebuild after this many refits.
pub const REFITS_PER_REBUILD: u32 = 16;

/// Figures of the upload, for reports.
#[derive(Debug, Clone, Default)]
pub struct UploadStats {
    /// BLAS build figures.
    pub blas: BlasBuildStats,
    /// Bytes of scene buffers (geometry, materials, textures, lights, environment).
    pub buffer_bytes: u64,
    /// Number of BLASes (meshes with triangles).
    pub blas_count: usize,
    /// The device memory the upload was planned for (checked against the device before it).
    pub memory_need: MemoryNeed,
}

/// The scene's GPU resources at one time.
pub struct GpuScene {
    plan: ScenePlan,
    frame: Buffer,
    vertices: Buffer,
    tangents: Buffer,
    texcoords1: Buffer,
    indices: Buffer,
    instances: Buffer,
    tri_materials: Buffer,
    materials: Buffer,
    textures: Buffer,
    texels: Buffer,
    emitters: Buffer,
    emitter_alias: Buffer,
    lights: Buffer,
    env_texels: Buffer,
    env_alias: Buffer,
    blases: Vec<Option<Blas>>,
    tlas: Tlas,
    meshes: Vec<GpuMesh>,
    instance_mesh: Vec<usize>,
    transforms: Vec<Mat4>,
    time: Option<f32>,
    pending: Option<TlasUpdate>,
    refits: u32,
    constants: FrameConstants,
    env_constant: Vec3,
    env_scale: f32,
    env_size: (u32, u32),
    emitter_count: u32,
    emitter_power: f32,
    light_count: u32,
    scene_scale: f32,
    stats: UploadStats,
}

impl std::fmt::Debug for GpuScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuScene")
            .field("plan", &self.plan)
            .field("emitter_count", &self.emitter_count)
            .field("light_count", &self.light_count)
            .field("scene_scale", &self.scene_scale)
            .finish_non_exhaustive()
    }
}

impl GpuScene {
    /// Uploads `scene` (and the environment map, when the scene uses one) and builds its BLASes.
    /// The TLAS is built by the first [`GpuScene::set_time`] + [`GpuScene::record_update`].
    /// A scene that needs more device memory than the device has ([`MemoryNeed`]) is refused
    /// before anything is uploaded.
    pub fn new(ctx: &Context, scene: &Scene, env_map: Option<&EnvMap>) -> Result<GpuScene> {
        let plan = scene.plan();
        let mut stats = UploadStats::default();
        let PackedGeometry {
            vertices,
            tangents,
            texcoords1,
            indices,
            tri_materials,
            meshes,
        } = pack_geometry(scene, plan.normal_maps, plan.texcoord1);
        let (materials, textures, texels) = pack_materials(scene);
        let bytes = |n: usize| n as u64;
        let max_emitters = emissive_triangles(scene);
        let need = memory_need(
            ctx,
            scene,
            env_map,
            max_emitters,
            bytes(
                size_of_val(&vertices[..])
                    + size_of_val(&tangents[..])
                    + size_of_val(&texcoords1[..])
                    + size_of_val(&indices[..])
                    + size_of_val(&tri_materials[..]),
            ),
            bytes(
                size_of_val(&materials[..]) + size_of_val(&textures[..]) + size_of_val(&texels[..]),
            ),
        );
        need.check(ctx.info(), &scene.path)?;
        stats.memory_need = need;
        let geometry_usage = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
            | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
        let none = vk::BufferUsageFlags::empty();
        let vertex_buf = storage(
            ctx,
            "scene.vertices",
            geometry_usage,
            bytemuck::cast_slice(&vertices),
        )?;
        let index_buf = storage(
            ctx,
            "scene.indices",
            geometry_usage,
            bytemuck::cast_slice(&indices),
        )?;
        let tri_mat_buf = storage(
            ctx,
            "scene.triangle_materials",
            none,
            bytemuck::cast_slice(&tri_materials),
        )?;
        // Empty without normal maps: `storage` then makes a 16-byte placeholder.
        let tangent_buf = storage(ctx, "scene.tangents", none, bytemuck::cast_slice(&tangents))?;
        // Empty without TEXCOORD_1: a placeholder too.
        let texcoord1_buf = storage(
            ctx,
            "scene.texcoords1",
            none,
            bytemuck::cast_slice(&texcoords1),
        )?;

        let material_buf = storage(
            ctx,
            "scene.materials",
            none,
            bytemuck::cast_slice(&materials),
        )?;
        let texture_buf = storage(ctx, "scene.textures", none, bytemuck::cast_slice(&textures))?;
        let texel_buf = storage(ctx, "scene.texels", none, bytemuck::cast_slice(&texels))?;

        // Environment.
        let (env_constant, env_scale) = match &scene.environment {
            Environment::None => (Vec3::ZERO, 0.0),
            Environment::Constant(l) => (*l, 0.0),
            Environment::Map { scale, .. } => (Vec3::ZERO, *scale),
        };
        let (env_texels, env_alias, env_size) = match (env_map, &scene.environment) {
            (Some(map), Environment::Map { .. }) => (
                map.texels.clone(),
                map.alias.clone(),
                (map.width, map.height),
            ),
            _ => (Vec::new(), Vec::new(), (0, 0)),
        };
        let env_texel_buf = storage(
            ctx,
            "scene.env_texels",
            none,
            bytemuck::cast_slice(&env_texels),
        )?;
        let env_alias_buf = storage(
            ctx,
            "scene.env_alias",
            none,
            bytemuck::cast_slice(&env_alias),
        )?;

        // One BLAS per mesh with triangles, one geometry holding all of its primitives (so several
        // materials): non-opaque when any of its triangles' materials is alpha-tested.
        let geoms: Vec<(usize, BlasGeometry<'_>)> = scene
            .meshes
            .iter()
            .enumerate()
            .filter(|(_, m)| m.triangle_count() > 0)
            .map(|(i, m)| {
                let r = meshes[i].ranges;
                (
                    i,
                    BlasGeometry {
                        name: "scene.blas",
                        vertices: &vertex_buf,
                        vertex_offset: u64::from(r[0]) * std::mem::size_of::<GpuVertex>() as u64,
                        vertex_stride: std::mem::size_of::<GpuVertex>() as u64,
                        vertex_count: m.positions.len() as u32,
                        indices: &index_buf,
                        index_offset: u64::from(r[1]) * 4,
                        triangle_count: m.triangle_count() as u32,
                        opaque: mesh_is_opaque(scene, &m.triangle_materials),
                    },
                )
            })
            .collect();
        let mut blases: Vec<Option<Blas>> = (0..scene.meshes.len()).map(|_| None).collect();
        if !geoms.is_empty() {
            let list: Vec<BlasGeometry<'_>> = geoms.iter().map(|(_, g)| *g).collect();
            let (built, blas_stats) = ctx.build_blases(&list)?;
            for ((mesh, _), blas) in geoms.iter().zip(built) {
                blases[*mesh] = Some(blas);
            }
            stats.blas = blas_stats;
            stats.blas_count = geoms.len();
        }
        drop(geoms);

        let instance_count = scene.instances.len() as u64;
        let tlas = Tlas::new(ctx, "scene.tlas", scene.instances.len().max(1) as u32)?;
        let instances = host_buffer(
            ctx,
            "scene.instances",
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            instance_count * std::mem::size_of::<GpuInstance>() as u64,
        )?;
        let emitters = host_buffer(
            ctx,
            "scene.emitters",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            (max_emitters * std::mem::size_of::<GpuEmitter>()) as u64,
        )?;
        let emitter_alias = host_buffer(
            ctx,
            "scene.emitter_alias",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            (max_emitters * std::mem::size_of::<GpuAlias>()) as u64,
        )?;
        let lights = host_buffer(
            ctx,
            "scene.lights",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            (scene.light_instances.len() * std::mem::size_of::<GpuLight>()) as u64,
        )?;
        let frame = host_buffer(
            ctx,
            "scene.frame",
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            std::mem::size_of::<FrameConstants>() as u64,
        )?;
        stats.buffer_bytes = [
            &vertex_buf,
            &tangent_buf,
            &texcoord1_buf,
            &index_buf,
            &tri_mat_buf,
            &material_buf,
            &texture_buf,
            &texel_buf,
            &env_texel_buf,
            &env_alias_buf,
            &instances,
            &emitters,
            &emitter_alias,
            &lights,
        ]
        .iter()
        .map(|b| b.size())
        .sum();
        let bounds = scene.bounds_over_range();
        let diagonal = if bounds.is_empty() {
            1.0
        } else {
            bounds.size().length()
        };
        Ok(GpuScene {
            plan,
            frame,
            vertices: vertex_buf,
            tangents: tangent_buf,
            texcoords1: texcoord1_buf,
            indices: index_buf,
            instances,
            tri_materials: tri_mat_buf,
            materials: material_buf,
            textures: texture_buf,
            texels: texel_buf,
            emitters,
            emitter_alias,
            lights,
            env_texels: env_texel_buf,
            env_alias: env_alias_buf,
            blases,
            tlas,
            meshes,
            instance_mesh: scene.instances.iter().map(|i| i.mesh).collect(),
            transforms: Vec::new(),
            time: None,
            pending: None,
            refits: 0,
            constants: bytemuck::Zeroable::zeroed(),
            env_constant,
            env_scale,
            env_size,
            emitter_count: 0,
            emitter_power: 0.0,
            light_count: 0,
            scene_scale: if diagonal.is_finite() && diagonal > 0.0 {
                diagonal
            } else {
                1.0
            },
            stats,
        })
    }

    /// The scene has a constant environment (a sky) that emits light.
    pub fn has_constant_environment(&self) -> bool {
        self.env_constant.max_element() > 0.0
    }

    /// The plan the scene was uploaded with.
    pub fn plan(&self) -> &ScenePlan {
        &self.plan
    }

    /// Upload figures.
    pub fn stats(&self) -> &UploadStats {
        &self.stats
    }

    /// Bounding-box diagonal over the animation (the scale epsilons are relative to).
    pub fn scene_scale(&self) -> f32 {
        self.scene_scale
    }

    /// `(custom index, triangle count)` of every instance that has triangles, for rasterization.
    pub fn instance_draws(&self) -> Vec<(u32, u32)> {
        self.instance_mesh
            .iter()
            .enumerate()
            .filter_map(|(i, &m)| {
                let n = self.meshes[m].ranges[3];
                (n > 0).then_some((i as u32, n))
            })
            .collect()
    }

    /// The instances at the current time (`GpuInstance` per instance, by custom index) and
    /// their number.
    pub fn instances(&self) -> (&Buffer, u32) {
        (&self.instances, self.instance_mesh.len() as u32)
    }

    /// Emissive triangles at the current time.
    pub fn emitter_count(&self) -> u32 {
        self.emitter_count
    }

    /// Moves the scene to time `t`: rewrites instances, emitters and lights that changed and marks
    /// the TLAS for a refit (or a build, the first time). Returns true when anything moved.
    pub fn set_time(&mut self, scene: &Scene, t: f32) -> Result<bool> {
        if self.time == Some(t) {
            return Ok(false);
        }
        let transforms = scene.instance_transforms(t);
        let first = self.time.is_none();
        let moved = first || transforms != self.transforms;
        self.time = Some(t);
        if moved {
            let gpu: Vec<GpuInstance> = scene
                .instances
                .iter()
                .zip(&transforms)
                .map(|(inst, m)| {
                    let r = self.meshes[inst.mesh].ranges;
                    let mut normal = Mat4::from_mat3(Mat3::from_mat4(*m).inverse().transpose());
                    // w.w carries the handedness: a mirroring transform flips the front face.
                    normal.w_axis.w = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
                    GpuInstance {
                        world_from_object: cols(*m),
                        normal_to_world: cols(normal),
                        mesh: [inst.mesh as u32, r[0], r[1], r[2]],
                    }
                })
                .collect();
            self.instances.write(0, &gpu)?;
            self.pending = Some(if first || self.refits >= REFITS_PER_REBUILD {
                TlasUpdate::Rebuild
            } else {
                TlasUpdate::Refit
            });
            self.write_emitters(scene, t)?;
            self.transforms = transforms;
        }
        let lights_moved = first || self.plan.animation.lights;
        if lights_moved {
            self.write_lights(scene, t)?;
        }
        Ok(moved || lights_moved)
    }

    fn write_emitters(&mut self, scene: &Scene, t: f32) -> Result<()> {
        if !self.plan.has_emissive() {
            return Ok(());
        }
        let table = scene.emitters_at(t);
        let gpu = gpu_emitters(scene, &table);
        self.emitters.write(0, &gpu)?;
        self.emitter_alias.write(0, &gpu_alias(&table.table))?;
        self.emitter_count = gpu.len() as u32;
        self.emitter_power = table.total_power;
        Ok(())
    }

    fn write_lights(&mut self, scene: &Scene, t: f32) -> Result<()> {
        let lights = gpu_lights(&scene.lights_at(t));
        self.lights.write(0, &lights)?;
        self.light_count = lights.len() as u32;
        Ok(())
    }

    /// Records the pending TLAS build or refit (nothing when the scene did not move).
    pub fn record_update(&mut self, ctx: &Context, rec: &mut Recorder) -> Result<()> {
        let Some(update) = self.pending.take() else {
            return Ok(());
        };
        let (blases, instance_mesh) = (&self.blases, &self.instance_mesh);
        let instances: Vec<TlasInstance<'_>> = self
            .transforms
            .iter()
            .enumerate()
            .filter_map(|(i, m)| {
                let blas = blases[*instance_mesh.get(i)?].as_ref()?;
                Some(TlasInstance {
                    blas,
                    transform: rows3x4(*m),
                    custom_index: i as u32,
                    mask: 0xff,
                })
            })
            .collect();
        let tlas = &mut self.tlas;
        rec.pass("scene.tlas", |rec| {
            rec.build_tlas(ctx, tlas, &instances, update)
        })?;
        self.refits = match update {
            TlasUpdate::Rebuild => 0,
            TlasUpdate::Refit => self.refits + 1,
        };
        Ok(())
    }
}

/// What uploading `scene` will take of device memory, from the packed sizes of its geometry and
/// textures, its environment map, its instances, `emitters` emissive triangles and lights, and the
/// driver's sizes of every acceleration structure.
fn memory_need(
    ctx: &Context,
    scene: &Scene,
    env_map: Option<&EnvMap>,
    emitters: usize,
    geometry: u64,
    textures: u64,
) -> MemoryNeed {
    let environment = match (env_map, &scene.environment) {
        (Some(map), Environment::Map { .. }) => {
            (size_of_val(&map.texels[..]) + size_of_val(&map.alias[..])) as u64
        }
        _ => 0,
    };
    let shapes: Vec<BlasShape> = scene
        .meshes
        .iter()
        .filter(|m| m.triangle_count() > 0)
        .map(|m| BlasShape {
            vertex_count: m.positions.len() as u32,
            triangle_count: m.triangle_count() as u32,
        })
        .collect();
    let tlas = Tlas::sizes(ctx, scene.instances.len().max(1) as u32);
    let instances = scene.instances.len() * (size_of::<GpuInstance>() + 64)
        + emitters * (size_of::<GpuEmitter>() + size_of::<GpuAlias>())
        + scene.light_instances.len() * size_of::<GpuLight>();
    MemoryNeed {
        geometry,
        textures,
        environment,
        instances: instances as u64,
        acceleration: MemoryNeed::acceleration(&ctx.blas_sizes(&shapes), tlas),
    }
}

/// Emissive triangles over all instances (the emitter buffers' capacity): each mesh counted once,
/// then summed over the instances that place it.
fn emissive_triangles(scene: &Scene) -> usize {
    let per_mesh: Vec<usize> = scene
        .meshes
        .iter()
        .map(|mesh| {
            mesh.triangle_materials
                .iter()
                .filter(|&&m| scene.material_emission[m as usize].max_element() > 0.0)
                .count()
        })
        .collect();
    scene.instances.iter().map(|i| per_mesh[i.mesh]).sum()
}
