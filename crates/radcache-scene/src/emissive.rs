//! World-space emissive triangles and their power-proportional sampling table.
//!
//! Each triangle of an instance whose material emits becomes an [`EmissiveTriangle`] with
//! `power = luminance(L) · area · π · (2 if double-sided else 1)` — the flux of a Lambertian emitter
//! of radiance `L` (luminance-weighted) from one or both faces. `L` is the material's `emissive`,
//! times the mean of its emissive texture when it has one (an approximation used only for the
//! sampling weights). The [`EmitterTable`] samples triangles with probability ∝ power.

use glam::{Mat4, Vec3};

use crate::alias::AliasTable;
use crate::material::emitted_radiance;
use crate::math::{luminance, triangle_cross};

/// An emitting triangle in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissiveTriangle {
    /// Index into `Scene::instances`.
    pub instance: usize,
    /// Mesh index.
    pub mesh: usize,
    /// Triangle index within the mesh.
    pub triangle: usize,
    /// World-space vertices.
    pub positions: [Vec3; 3],
    /// Unit front-face normal in world space (CCW side; flipped for mirroring transforms).
    pub normal: Vec3,
    /// Area in m².
    pub area: f32,
    /// Emitted radiance W/(sr·m²).
    pub radiance: Vec3,
    /// Emits from both faces.
    pub double_sided: bool,
}

impl EmissiveTriangle {
    /// Builds the triangle from object-space vertices and the instance transform. Returns `None`
    /// for a zero-area result.
    pub fn new(
        ids: (usize, usize, usize),
        local: &[Vec3; 3],
        world_from_object: &Mat4,
        radiance: Vec3,
        double_sided: bool,
    ) -> Option<EmissiveTriangle> {
        let positions = local.map(|p| world_from_object.transform_point3(p));
        let cross = triangle_cross(&positions);
        let len = cross.length();
        if len.is_nan() || len <= 0.0 || !len.is_finite() {
            return None;
        }
        let flip = if world_from_object.determinant() < 0.0 {
            -1.0
        } else {
            1.0
        };
        Some(EmissiveTriangle {
            instance: ids.0,
            mesh: ids.1,
            triangle: ids.2,
            positions,
            normal: cross / len * flip,
            area: 0.5 * len,
            radiance,
            double_sided,
        })
    }

    /// Radiance leaving the triangle towards direction `dir` (from the triangle to the viewer):
    /// see [`emitted_radiance`].
    pub fn emitted_radiance(&self, dir: Vec3) -> Vec3 {
        emitted_radiance(self.normal, self.radiance, self.double_sided, dir)
    }

    /// Luminance-weighted emitted power (W): `luminance(L) · area · π · (2 if double-sided)`.
    pub fn power(&self) -> f32 {
        let sides = if self.double_sided { 2.0 } else { 1.0 };
        luminance(self.radiance) * self.area * std::f32::consts::PI * sides
    }
}

/// All emissive triangles at one time, with an alias table for power-proportional sampling.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EmitterTable {
    /// The triangles (order: instances in order, triangles in mesh order).
    pub triangles: Vec<EmissiveTriangle>,
    /// Alias table over `triangles`, weights = power.
    pub table: AliasTable,
    /// Sum of the triangles' power (W).
    pub total_power: f32,
}

impl EmitterTable {
    /// Builds the table for `triangles`.
    pub fn new(triangles: Vec<EmissiveTriangle>) -> EmitterTable {
        let power: Vec<f32> = triangles.iter().map(EmissiveTriangle::power).collect();
        let table = AliasTable::new(&power);
        EmitterTable {
            total_power: table.total_weight as f32,
            triangles,
            table,
        }
    }

    /// Samples a triangle with probability ∝ power from `u ∈ [0, 1)`: `(index, pmf)`.
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        self.table.sample(u)
    }
}
