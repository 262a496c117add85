//! Test geometry: a UV sphere mesh and a CPU ray–triangle reference (Möller–Trumbore in f64).

use glam::{DVec3, Vec3};

/// An indexed triangle mesh.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangle indices (3 per triangle).
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Corners of triangle `t`.
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [
            self.positions[i[0] as usize],
            self.positions[i[1] as usize],
            self.positions[i[2] as usize],
        ]
    }
}

/// A UV sphere of radius `r` with `rings` × `segments` quads (poles as triangle fans), counter-
/// clockwise seen from outside. Triangles: 2·segments·(rings−1).
pub fn uv_sphere(r: f32, rings: u32, segments: u32) -> Mesh {
    let mut m = Mesh::default();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            m.positions.push(Vec3::new(
                r * theta.sin() * phi.cos(),
                r * theta.cos(),
                r * theta.sin() * phi.sin(),
            ));
        }
    }
    let idx = |i: u32, j: u32| i * segments + (j % segments);
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1));
            if i != 0 {
                m.indices.extend([a, b, c]);
            }
            if i != rings - 1 {
                m.indices.extend([b, d, c]);
            }
        }
    }
    m
}

/// An axis-aligned box [lo, hi] with inward-facing triangles (a room), 12 triangles.
pub fn room(lo: Vec3, hi: Vec3) -> Mesh {
    let mut m = Mesh::default();
    for z in [lo.z, hi.z] {
        for y in [lo.y, hi.y] {
            for x in [lo.x, hi.x] {
                m.positions.push(Vec3::new(x, y, z));
            }
        }
    }
    // Faces as quads (a, b, c, d), wound so that normals point inward.
    let quads = [
        [0, 2, 3, 1], // z = lo, normal +z
        [4, 5, 7, 6], // z = hi, normal −z
        [0, 1, 5, 4], // y = lo, normal +y
        [2, 6, 7, 3], // y = hi, normal −y
        [0, 4, 6, 2], // x = lo, normal +x
        [1, 3, 7, 5], // x = hi, normal −x
    ];
    for [a, b, c, d] in quads {
        m.indices.extend([a, b, c, a, c, d]);
    }
    m
}

/// A ray–triangle hit: distance and barycentrics (u, v) of corners 1 and 2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriHit {
    /// Distance along the (unnormalised) direction.
    pub t: f64,
    /// Barycentric of corner 1.
    pub u: f64,
    /// Barycentric of corner 2.
    pub v: f64,
}

impl TriHit {
    /// Distance of the hit point to the nearest triangle edge, in barycentric units.
    pub fn edge_distance(&self) -> f64 {
        self.u.min(self.v).min(1.0 - self.u - self.v)
    }
}

/// Möller–Trumbore in f64, both faces; `slack` widens the barycentric test (0 for exact).
pub fn intersect(o: DVec3, d: DVec3, tri: [Vec3; 3], slack: f64) -> Option<TriHit> {
    let (p0, p1, p2) = (tri[0].as_dvec3(), tri[1].as_dvec3(), tri[2].as_dvec3());
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - p0;
    let u = tv.dot(pv) * inv;
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    let t = e2.dot(qv) * inv;
    let ok = u >= -slack && v >= -slack && u + v <= 1.0 + slack;
    ok.then_some(TriHit { t, u, v })
}
