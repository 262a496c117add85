//! Uniform tessellation of a [`Scene`]'s meshes, for `cargo xtask bench scaling`.
//!
//! Each triangle `(p0, p1, p2)` is split into `n²` congruent sub-triangles on the barycentric grid
//! of step `1/n`: grid vertex `(i, j)` (`i + j <= n`) has the weights `((n−i−j)/n, i/n, j/n)`, and
//! its position, normal (renormalised), texcoord and tangent (the first corner's handedness) are
//! those weights applied to the corners'. Sub-triangles keep the parent's material and winding,
//! so the surface, its shading normals and its texture mapping are unchanged: a render of the
//! tessellated scene differs only by noise.
//!
//! Every weight is an integer divided by `n` in `f32`, and a vertex is the plain sum `Σ w_k p_k`,
//! so the vertices two neighbours place on their shared edge are bitwise equal (no cracks).
//! Each triangle gets its own `(n+1)(n+2)/2` grid vertices (shared edges are duplicated, as in a
//! de-indexed mesh). Derived data is rebuilt: primitive ranges and bounds here; emitters are
//! computed from the meshes by `Scene::emitters_at`, so they follow.

use anyhow::{ensure, Result};
use glam::Vec3;
use radcache_scene::math::Aabb;
use radcache_scene::{Mesh, PrimitiveRange, Scene};

/// Vertices of one triangle's grid at level `n`.
fn grid_vertices(n: u32) -> u32 {
    (n + 1) * (n + 2) / 2
}

/// Index of grid vertex `(i, j)` within its triangle's grid (rows of constant `j`).
fn grid_index(n: u32, i: u32, j: u32) -> u32 {
    j * (n + 1) - j * j.saturating_sub(1) / 2 + i
}

/// The `n²` sub-triangles of the grid as grid-vertex triples, in the parent's winding.
fn grid_triangles(n: u32) -> Vec<[u32; 3]> {
    let mut tris = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n - j {
            tris.push([
                grid_index(n, i, j),
                grid_index(n, i + 1, j),
                grid_index(n, i, j + 1),
            ]);
            if i + j + 1 < n {
                tris.push([
                    grid_index(n, i + 1, j),
                    grid_index(n, i + 1, j + 1),
                    grid_index(n, i, j + 1),
                ]);
            }
        }
    }
    tris
}

/// `mesh` with every triangle split into `n²` sub-triangles (`n >= 1`; `n = 1` returns a copy).
pub fn subdivide_mesh(mesh: &Mesh, n: u32) -> Result<Mesh> {
    ensure!(n >= 1, "the subdivision level must be at least 1");
    if n == 1 {
        return Ok(mesh.clone());
    }
    let per_tri = grid_vertices(n) as usize;
    let tris = mesh.triangle_count();
    let vertex_total = tris * per_tri;
    ensure!(
        u32::try_from(vertex_total).is_ok(),
        "{vertex_total} vertices exceed the u32 index range"
    );
    let weights: Vec<[f32; 3]> = (0..=n)
        .flat_map(|j| (0..=n - j).map(move |i| (i, j)))
        .map(|(i, j)| {
            let w = |k: u32| k as f32 / n as f32;
            [w(n - i - j), w(i), w(j)]
        })
        .collect();
    debug_assert_eq!(weights.len(), per_tri);
    let pattern = grid_triangles(n);
    let mut out = Mesh {
        name: mesh.name.clone(),
        positions: Vec::with_capacity(vertex_total),
        normals: Vec::with_capacity(vertex_total),
        texcoords: Vec::with_capacity(vertex_total),
        texcoords1: Vec::with_capacity(if mesh.texcoords1.is_empty() {
            0
        } else {
            vertex_total
        }),
        tangents: Vec::with_capacity(if mesh.tangents.is_empty() {
            0
        } else {
            vertex_total
        }),
        indices: Vec::with_capacity(tris * pattern.len() * 3),
        triangle_materials: Vec::with_capacity(tris * pattern.len()),
        primitives: Vec::with_capacity(mesh.primitives.len()),
        bounds: Aabb::EMPTY,
    };
    for (t, &material) in mesh.triangle_materials.iter().enumerate().take(tris) {
        let idx: [usize; 3] = std::array::from_fn(|k| mesh.indices[3 * t + k] as usize);
        let p = idx.map(|i| mesh.positions[i]);
        let nrm = idx.map(|i| mesh.normals[i]);
        let uv = idx.map(|i| mesh.texcoords[i]);
        let uv1 = idx.map(|i| mesh.texcoords1.get(i).copied().unwrap_or_default());
        let tan = idx.map(|i| mesh.tangents.get(i).copied().unwrap_or_default());
        let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or(Vec3::Z);
        let base = out.positions.len() as u32;
        for w in &weights {
            out.positions.push(p[0] * w[0] + p[1] * w[1] + p[2] * w[2]);
            out.normals
                .push((nrm[0] * w[0] + nrm[1] * w[1] + nrm[2] * w[2]).normalize_or(face));
            out.texcoords
                .push(uv[0] * w[0] + uv[1] * w[1] + uv[2] * w[2]);
            if !mesh.texcoords1.is_empty() {
                out.texcoords1
                    .push(uv1[0] * w[0] + uv1[1] * w[1] + uv1[2] * w[2]);
            }
            if !mesh.tangents.is_empty() {
                // The handedness of the first corner (a triangle's corners share it).
                let t =
                    tan[0].truncate() * w[0] + tan[1].truncate() * w[1] + tan[2].truncate() * w[2];
                out.tangents.push(t.extend(tan[0].w));
            }
        }
        for tri in &pattern {
            out.indices.extend(tri.iter().map(|&k| base + k));
            out.triangle_materials.push(material);
        }
    }
    let (nn, per_tri32) = (n * n, per_tri as u32);
    out.primitives = mesh
        .primitives
        .iter()
        .map(|r| PrimitiveRange {
            first_triangle: r.first_triangle * nn,
            triangle_count: r.triangle_count * nn,
            first_vertex: r.first_triangle * per_tri32,
            vertex_count: r.triangle_count * per_tri32,
            ..*r
        })
        .collect();
    for &q in &out.positions {
        out.bounds.extend(q);
    }
    Ok(out)
}

/// `scene` with every mesh subdivided by [`subdivide_mesh`].
pub fn subdivide_scene(scene: &Scene, n: u32) -> Result<Scene> {
    let meshes = scene
        .meshes
        .iter()
        .map(|m| subdivide_mesh(m, n))
        .collect::<Result<Vec<_>>>()?;
    Ok(Scene {
        meshes,
        ..scene.clone()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// Area of a triangle, in f64.
    fn area(p: &[Vec3; 3]) -> f64 {
        let d = |v: Vec3| v.as_dvec3();
        0.5 * (d(p[1]) - d(p[0])).cross(d(p[2]) - d(p[0])).length()
    }

    /// Two triangles sharing the edge (1, 2), in two primitives, with distinct normals and uvs.
    fn quad() -> Mesh {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.3, 0.1, 0.2),
            Vec3::new(0.2, 0.9, -0.4),
            Vec3::new(1.5, 1.2, -0.1),
        ];
        let normals = vec![
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(0.0, 0.6, 0.8),
            Vec3::new(-0.48, 0.6, 0.64),
        ];
        let texcoords = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
        ];
        let mut bounds = Aabb::EMPTY;
        positions.iter().for_each(|&p| bounds.extend(p));
        let prim = |k: u32, material| PrimitiveRange {
            gltf_primitive: k as usize,
            material,
            first_triangle: k,
            triangle_count: 1,
            first_vertex: 0,
            vertex_count: 4,
        };
        Mesh {
            name: Some("quad".into()),
            positions,
            normals,
            texcoords,
            texcoords1: Vec::new(),
            tangents: Vec::new(),
            indices: vec![0, 1, 2, 2, 1, 3],
            triangle_materials: vec![3, 5],
            primitives: vec![prim(0, 3), prim(1, 5)],
            bounds,
        }
    }

    /// Barycentric weights of `q` in `p` (least squares in the triangle's plane).
    fn barycentric(p: &[Vec3; 3], q: Vec3) -> [f32; 3] {
        let (e1, e2, d) = (p[1] - p[0], p[2] - p[0], q - p[0]);
        let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (r1, r2) = (d.dot(e1), d.dot(e2));
        let det = a * c - b * b;
        let (w1, w2) = ((c * r1 - b * r2) / det, (a * r2 - b * r1) / det);
        [1.0 - w1 - w2, w1, w2]
    }

    #[test]
    fn triangle_count_is_n_squared() {
        let m = quad();
        for n in 1..=10 {
            let s = subdivide_mesh(&m, n).unwrap();
            assert_eq!(s.triangle_count(), m.triangle_count() * (n * n) as usize);
            assert_eq!(grid_triangles(n).len(), (n * n) as usize);
            assert_eq!(s.triangle_materials.len(), s.triangle_count());
            assert!(s.indices.iter().all(|&i| (i as usize) < s.positions.len()));
            assert_eq!(s.normals.len(), s.positions.len());
            assert_eq!(s.texcoords.len(), s.positions.len());
        }
        assert!(subdivide_mesh(&m, 0).is_err());
    }

    #[test]
    fn area_is_preserved_and_winding_kept() {
        let m = quad();
        for n in [2, 3, 4, 8, 10] {
            let s = subdivide_mesh(&m, n).unwrap();
            let nn = (n * n) as usize;
            for t in 0..m.triangle_count() {
                let parent = m.triangle(t);
                let pn = (parent[1] - parent[0]).cross(parent[2] - parent[0]);
                let sum: f64 = (t * nn..(t + 1) * nn)
                    .map(|k| {
                        let c = s.triangle(k);
                        let cn = (c[1] - c[0]).cross(c[2] - c[0]);
                        assert!(cn.dot(pn) > 0.0, "sub-triangle {k} flipped");
                        area(&c)
                    })
                    .sum();
                let want = area(&parent);
                assert!((sum - want).abs() <= 1e-6 * want, "n={n}: {sum} vs {want}");
                // Congruent: every sub-triangle has 1/n² of the area.
                for k in t * nn..(t + 1) * nn {
                    let a = area(&s.triangle(k));
                    assert!((a * nn as f64 - want).abs() <= 1e-5 * want);
                }
            }
        }
    }

    #[test]
    fn vertices_lie_in_their_parent_and_attributes_interpolate() {
        let m = quad();
        let n = 5;
        let s = subdivide_mesh(&m, n).unwrap();
        let per = grid_vertices(n) as usize;
        assert_eq!(s.positions.len(), per * m.triangle_count());
        for t in 0..m.triangle_count() {
            let idx: [usize; 3] = std::array::from_fn(|k| m.indices[3 * t + k] as usize);
            let p = idx.map(|i| m.positions[i]);
            let plane = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            for v in t * per..(t + 1) * per {
                let q = s.positions[v];
                assert!(
                    (q - p[0]).dot(plane).abs() < 1e-6,
                    "vertex {v} off the plane"
                );
                let w = barycentric(&p, q);
                assert!(
                    w.iter().all(|&x| (-1e-5..=1.0 + 1e-5).contains(&x)),
                    "{w:?}"
                );
                // Grid weights are multiples of 1/n.
                assert!(w
                    .iter()
                    .all(|&x| (x * n as f32 - (x * n as f32).round()).abs() < 1e-4));
                let blend = |f: &dyn Fn(usize) -> Vec3| (0..3).map(|k| f(idx[k]) * w[k]).sum();
                let want_n: Vec3 = blend(&|i| m.normals[i]);
                let got = s.normals[v];
                assert!((got.length() - 1.0).abs() < 1e-5);
                assert!(
                    (got - want_n.normalize()).length() < 1e-4,
                    "{got} vs {want_n}"
                );
                let want_uv: Vec3 = blend(&|i| m.texcoords[i].extend(0.0));
                assert!((s.texcoords[v] - want_uv.truncate()).length() < 1e-5);
            }
        }
        // The grid's corners are the parent's corners, exactly.
        for k in 0..3 {
            let corner = [
                grid_index(n, 0, 0),
                grid_index(n, n, 0),
                grid_index(n, 0, n),
            ][k];
            assert_eq!(
                s.positions[corner as usize],
                m.positions[m.indices[k] as usize]
            );
            assert_eq!(s.normals[corner as usize], m.normals[m.indices[k] as usize]);
        }
    }

    #[test]
    fn shared_edges_match_bitwise_and_ranges_follow() {
        let m = quad();
        let n = 7;
        let s = subdivide_mesh(&m, n).unwrap();
        let per = grid_vertices(n) as usize;
        let on_edge = |t: usize| -> Vec<[u32; 3]> {
            let (a, b) = (m.positions[1], m.positions[2]);
            let mut v: Vec<[u32; 3]> = s.positions[t * per..(t + 1) * per]
                .iter()
                .filter(|q| (**q - a).cross(b - a).length() < 1e-6)
                .map(|q| q.to_array().map(f32::to_bits))
                .collect();
            v.sort_unstable();
            v
        };
        let (e0, e1) = (on_edge(0), on_edge(1));
        assert_eq!(e0.len(), n as usize + 1);
        assert_eq!(e0, e1);
        assert_eq!(s.bounds, m.bounds);
        let nn = n * n;
        for (r, parent) in s.primitives.iter().zip(&m.primitives) {
            assert_eq!(r.material, parent.material);
            assert_eq!(r.triangle_count, parent.triangle_count * nn);
            let first = r.first_triangle as usize;
            let mats = &s.triangle_materials[first..first + r.triangle_count as usize];
            assert!(mats.iter().all(|&x| x == parent.material));
            let (lo, hi) = (r.first_vertex, r.first_vertex + r.vertex_count);
            let tris = &s.indices[3 * first..3 * (first + r.triangle_count as usize)];
            assert!(tris.iter().all(|i| (lo..hi).contains(i)));
        }
    }

    #[test]
    fn cornell_box_keeps_its_emitters_and_bounds() {
        let path = crate::root().join("assets/cornell/cornell.gltf");
        let (scene, _) = Scene::load(&path, &radcache_scene::LoadOptions::default()).unwrap();
        let s = subdivide_scene(&scene, 3).unwrap();
        assert_eq!(s.triangle_count(), 9 * scene.triangle_count());
        assert_eq!(s.bounds_at(0.0), scene.bounds_at(0.0));
        let (a, b) = (scene.emitters_at(0.0), s.emitters_at(0.0));
        assert_eq!(b.triangles.len(), 9 * a.triangles.len());
        let rel = (a.total_power - b.total_power).abs() / a.total_power;
        assert!(rel < 1e-5, "{} vs {}", a.total_power, b.total_power);
        assert_eq!(s.materials, scene.materials);
    }
}
