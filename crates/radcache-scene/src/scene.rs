//! The loaded [`Scene`] and its time-dependent queries (transforms, camera, lights, emitters,
//! bounds at time `t`). Loading itself lives in `load.rs`, the summary in `summary.rs`.
//!
//! Transforms are named `a_from_b`: `instance_transforms(t)[i]` is `world_from_object` of
//! instance `i` at time `t` (seconds, clamped to each channel's key range).

use std::path::PathBuf;

use glam::{Mat4, Vec3};

use crate::animation::Animation;
use crate::camera::{Camera, CameraView};
use crate::emissive::{EmissiveTriangle, EmitterTable};
use crate::environment::Environment;
use crate::light::{LightInstance, PunctualLight, WorldLight};
use crate::material::{Material, MaterialNotes};
use crate::math::{Aabb, Trs};
use crate::mesh::Mesh;
use crate::node::{LocalTransform, Node};
use crate::texture::{Image, Texture};

/// A mesh placed by a node (once, or once per instance of its `EXT_mesh_gpu_instancing`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index into `Scene::meshes`.
    pub mesh: usize,
    /// Index into `Scene::nodes`.
    pub node: usize,
    /// `node_from_object`: the instance's own transform under its node (its
    /// `EXT_mesh_gpu_instancing` translation, rotation and scale; identity for a plain node).
    pub local: Mat4,
    /// True when the world transform changes over the animation range (TLAS refit needed).
    pub dynamic: bool,
}

/// A glTF scene flattened for rendering. Fields are plain data; indices refer to sibling vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The glTF file.
    pub path: PathBuf,
    /// All nodes of the file (see `Node::in_scene`).
    pub nodes: Vec<Node>,
    /// Root nodes of the chosen scene.
    pub roots: Vec<usize>,
    /// In-scene nodes in traversal order (parents first).
    pub order: Vec<usize>,
    /// One mesh per glTF mesh.
    pub meshes: Vec<Mesh>,
    /// Materials; the default material is appended last when a primitive has none.
    pub materials: Vec<Material>,
    /// What the materials use that radcache does not render (unsupported extensions, occlusion
    /// textures); printed by the summary.
    pub material_notes: MaterialNotes,
    /// Mean emitted radiance per material (emissive × mean emissive texture), for sampling weights.
    pub material_emission: Vec<Vec3>,
    /// Textures used by materials.
    pub textures: Vec<Texture>,
    /// Images used by textures.
    pub images: Vec<Image>,
    /// Punctual light definitions.
    pub lights: Vec<PunctualLight>,
    /// Lights placed by in-scene nodes, in traversal order.
    pub light_instances: Vec<LightInstance>,
    /// Meshes (with at least one triangle) placed by in-scene nodes, in traversal order.
    pub instances: Vec<Instance>,
    /// The selected camera.
    pub camera: Camera,
    /// Number of camera nodes in the scene.
    pub camera_count: usize,
    /// TRS animations.
    pub animations: Vec<Animation>,
    /// The environment.
    pub environment: Environment,
    /// `animated[n]`: node `n` is the target of at least one non-constant channel.
    pub animated: Vec<bool>,
    /// `dynamic[n]`: node `n`'s world transform changes (it or an ancestor is animated).
    pub dynamic: Vec<bool>,
}

impl Scene {
    /// `[t0, t1]` covered by the animations' keys, or `None` without animation channels.
    pub fn time_range(&self) -> Option<(f32, f32)> {
        let mut range: Option<(f32, f32)> = None;
        for ch in self.animations.iter().flat_map(|a| &a.channels) {
            let (a, b) = ch.sampler.time_range();
            range = Some(range.map_or((a, b), |(lo, hi)| (lo.min(a), hi.max(b))));
        }
        range
    }

    /// Every key time of every channel, sorted and de-duplicated.
    pub fn key_times(&self) -> Vec<f32> {
        let mut t: Vec<f32> = self
            .animations
            .iter()
            .flat_map(|a| &a.channels)
            .flat_map(|c| c.sampler.times.iter().copied())
            .collect();
        t.sort_by(f32::total_cmp);
        t.dedup();
        t
    }

    /// Local transforms of all nodes at time `t`.
    pub fn local_transforms(&self, t: f32) -> Vec<Mat4> {
        let mut trs: Vec<Option<Trs>> = vec![None; self.nodes.len()];
        for ch in self.animations.iter().flat_map(|a| &a.channels) {
            let Some(node) = self.nodes.get(ch.node) else {
                continue;
            };
            let base = match node.local {
                LocalTransform::Trs(b) => b,
                LocalTransform::Matrix(_) => continue,
            };
            ch.apply(t, trs[ch.node].get_or_insert(base));
        }
        self.nodes
            .iter()
            .zip(trs)
            .map(|(n, a)| a.map_or_else(|| n.local.matrix(), |a| a.matrix()))
            .collect()
    }

    /// `world_from_node` of every node at time `t` (identity for nodes outside the scene).
    pub fn world_transforms(&self, t: f32) -> Vec<Mat4> {
        let local = self.local_transforms(t);
        let mut world = vec![Mat4::IDENTITY; self.nodes.len()];
        for &n in &self.order {
            world[n] = match self.nodes[n].parent {
                Some(p) => world[p] * local[n],
                None => local[n],
            };
        }
        world
    }

    /// `world_from_object` of each instance at time `t` (same order as `instances`).
    pub fn instance_transforms(&self, t: f32) -> Vec<Mat4> {
        let world = self.world_transforms(t);
        self.instances
            .iter()
            .map(|i| world[i.node] * i.local)
            .collect()
    }

    /// The selected camera's frame at time `t`.
    pub fn camera_at(&self, t: f32) -> CameraView {
        let m = match self.camera.node {
            Some(n) => self.world_transforms(t)[n],
            None => self.camera.fixed_world_from_camera,
        };
        CameraView::from_world(&m, self.camera.perspective)
    }

    /// The punctual lights in world space at time `t` (same order as `light_instances`).
    pub fn lights_at(&self, t: f32) -> Vec<WorldLight> {
        let world = self.world_transforms(t);
        self.light_instances
            .iter()
            .map(|li| WorldLight::new(&self.lights[li.light], &world[li.node]))
            .collect()
    }

    /// Emissive triangles in world space at time `t`, with their sampling table.
    pub fn emitters_at(&self, t: f32) -> EmitterTable {
        let xforms = self.instance_transforms(t);
        let mut tris = Vec::new();
        for (ii, (inst, m)) in self.instances.iter().zip(&xforms).enumerate() {
            let mesh = &self.meshes[inst.mesh];
            for (tri, &mat) in mesh.triangle_materials.iter().enumerate() {
                let material = &self.materials[mat as usize];
                let radiance = self.material_emission[mat as usize];
                if radiance.max_element() <= 0.0 {
                    continue;
                }
                let ids = (ii, inst.mesh, tri);
                let local = mesh.triangle(tri);
                tris.extend(EmissiveTriangle::new(
                    ids,
                    &local,
                    m,
                    radiance,
                    material.double_sided,
                ));
            }
        }
        EmitterTable::new(tris)
    }

    /// World-space bounds of all instances at time `t`.
    pub fn bounds_at(&self, t: f32) -> Aabb {
        let xforms = self.instance_transforms(t);
        self.instances
            .iter()
            .zip(&xforms)
            .fold(Aabb::EMPTY, |b, (i, m)| {
                b.union(&self.meshes[i.mesh].bounds.transformed(m))
            })
    }

    /// Bounds over the animation range: the union of `bounds_at` at every key time and at 64
    /// uniform steps (an approximation between samples).
    pub fn bounds_over_range(&self) -> Aabb {
        let Some((t0, t1)) = self.time_range() else {
            return self.bounds_at(0.0);
        };
        let mut times = self.key_times();
        times.extend((0..=64).map(|k| t0 + (t1 - t0) * k as f32 / 64.0));
        times
            .iter()
            .fold(Aabb::EMPTY, |b, &t| b.union(&self.bounds_at(t)))
    }

    /// Number of triangles over all meshes (each counted once).
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(Mesh::triangle_count).sum()
    }

    /// Number of triangles over all instances.
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh].triangle_count())
            .sum()
    }
}
