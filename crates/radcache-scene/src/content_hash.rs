//! [`Scene::content_hash`]: a stable 64-bit hash of what a scene's lighting depends on (geometry,
//! materials, textures, lights, the environment and the animation of everything but the camera),
//! so a cache file's records can be refused for another scene (`radcache render --cache-in`).
//!
//! The hash is FNV-1a (64-bit) over the fields in a fixed order, each number as its
//! little-endian bytes (floats by their bits), each list preceded by its length, so it is the
//! same on every machine and every run. Names and the file's path are left out (renaming a mesh
//! or moving the file changes no record), and so is the camera: its node's channels and its
//! projection (a cache is meant to serve other views of the same scene).

use glam::{Mat4, Vec3, Vec4};

use crate::animation::{Interpolation, Property};
use crate::environment::Environment;
use crate::light::LightKind;
use crate::scene::Scene;
use crate::texture::{TextureRef, WrapMode};

/// FNV-1a, 64-bit (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    /// Adds `bytes`.
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// Adds a `u32` (little-endian).
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    /// Adds a length or an index (as a `u64`, little-endian).
    pub fn usize(&mut self, v: usize) {
        self.bytes(&(v as u64).to_le_bytes());
    }

    /// Adds an `f32` by its bits.
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }

    /// Adds each float of `values`.
    pub fn floats(&mut self, values: &[f32]) {
        self.usize(values.len());
        for &v in values {
            self.f32(v);
        }
    }

    /// The hash so far.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

fn vec3(h: &mut Fnv1a, v: Vec3) {
    h.floats(&v.to_array());
}

fn vec4(h: &mut Fnv1a, v: Vec4) {
    h.floats(&v.to_array());
}

fn mat4(h: &mut Fnv1a, m: &Mat4) {
    h.floats(&m.to_cols_array());
}

fn texture_ref(h: &mut Fnv1a, t: Option<TextureRef>) {
    match t {
        None => h.u32(0),
        Some(t) => {
            h.u32(1);
            h.usize(t.texture);
            // Only where not the default (TEXCOORD_0, no transform), so that the hash of a
            // scene without them is what it was before they were read.
            if t.tex_coord != 0 || !t.transform.is_identity() {
                h.bytes(b"uv map");
                h.u32(t.tex_coord);
                for row in t.transform.matrix() {
                    h.floats(&row);
                }
            }
        }
    }
}

fn wrap(w: WrapMode) -> u32 {
    match w {
        WrapMode::Repeat => 0,
        WrapMode::ClampToEdge => 1,
        WrapMode::MirroredRepeat => 2,
    }
}

impl Scene {
    /// A stable hash of the scene's content: geometry (vertices, normals, texture coordinates
    /// (TEXCOORD_1 where kept), triangles and their materials, the instances and their
    /// transforms at t = 0), materials (with their texture references' sets and transforms, and
    /// normal maps), textures and images, punctual lights and their placement, the environment, and the
    /// animation channels of every node but the camera's. Two loads of the same file (or of a
    /// copy under another name or with another camera) give the same value.
    pub fn content_hash(&self) -> u64 {
        let mut h = Fnv1a::default();
        h.bytes(b"radcache scene content 1");
        h.usize(self.meshes.len());
        for m in &self.meshes {
            h.usize(m.positions.len());
            for (&p, &n) in m.positions.iter().zip(&m.normals) {
                vec3(&mut h, p);
                vec3(&mut h, n);
            }
            for t in &m.texcoords {
                h.floats(&t.to_array());
            }
            if !m.texcoords1.is_empty() {
                h.bytes(b"TEXCOORD_1");
                for t in &m.texcoords1 {
                    h.floats(&t.to_array());
                }
            }
            h.usize(m.indices.len());
            m.indices.iter().for_each(|&i| h.u32(i));
            m.triangle_materials.iter().for_each(|&i| h.u32(i));
        }
        h.usize(self.materials.len());
        for m in &self.materials {
            vec4(&mut h, m.base_color);
            texture_ref(&mut h, m.base_color_texture);
            h.f32(m.metallic);
            h.f32(m.roughness);
            texture_ref(&mut h, m.metallic_roughness_texture);
            h.f32(m.ior);
            h.f32(m.specular_factor);
            vec3(&mut h, m.specular_color);
            vec3(&mut h, m.emissive);
            texture_ref(&mut h, m.emissive_texture);
            if m.normal_texture.is_some() {
                h.bytes(b"normal map");
                texture_ref(&mut h, m.normal_texture);
                h.f32(m.normal_scale);
            }
            h.u32(u32::from(m.double_sided));
            h.u32(m.alpha_mode as u32);
            h.f32(m.alpha_cutoff);
        }
        h.usize(self.textures.len());
        for t in &self.textures {
            h.usize(t.image);
            h.u32(wrap(t.wrap_s));
            h.u32(wrap(t.wrap_t));
            h.u32(u32::from(t.nearest));
        }
        h.usize(self.images.len());
        for i in &self.images {
            h.u32(i.width);
            h.u32(i.height);
            h.u32(u32::from(i.srgb));
            h.usize(i.rgba8.len());
            h.bytes(&i.rgba8);
        }
        h.usize(self.instances.len());
        for (i, m) in self.instances.iter().zip(&self.instance_transforms(0.0)) {
            h.usize(i.mesh);
            mat4(&mut h, m);
        }
        h.usize(self.lights.len());
        for l in &self.lights {
            match l.kind {
                LightKind::Point => h.u32(0),
                LightKind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => {
                    h.u32(1);
                    h.f32(inner_cone_angle);
                    h.f32(outer_cone_angle);
                }
                LightKind::Directional => h.u32(2),
            }
            vec3(&mut h, l.color);
            h.f32(l.intensity);
            h.f32(l.range.unwrap_or(-1.0));
        }
        let world = self.world_transforms(0.0);
        h.usize(self.light_instances.len());
        for l in &self.light_instances {
            h.usize(l.light);
            mat4(&mut h, &world[l.node]);
        }
        match &self.environment {
            Environment::None => h.u32(0),
            Environment::Constant(c) => {
                h.u32(1);
                vec3(&mut h, *c);
            }
            Environment::Map { path, scale } => {
                h.u32(2);
                h.bytes(path.to_string_lossy().as_bytes());
                h.f32(*scale);
            }
        }
        let camera = self.camera.node;
        for a in &self.animations {
            for c in a.channels.iter().filter(|c| Some(c.node) != camera) {
                h.usize(c.node);
                h.u32(match c.property {
                    Property::Translation => 0,
                    Property::Rotation => 1,
                    Property::Scale => 2,
                });
                h.u32(match c.sampler.interpolation {
                    Interpolation::Step => 0,
                    Interpolation::Linear => 1,
                    Interpolation::CubicSpline => 2,
                });
                h.floats(&c.sampler.times);
                h.usize(c.sampler.values.len());
                c.sampler.values.iter().for_each(|&v| vec4(&mut h, v));
            }
        }
        h.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::Fnv1a;

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        let hash = |s: &str| {
            let mut h = Fnv1a::default();
            h.bytes(s.as_bytes());
            h.finish()
        };
        assert_eq!(hash(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(hash("a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(hash("foobar"), 0x8594_4171_f739_67e8);
    }
}
