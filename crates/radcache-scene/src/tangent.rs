//! Vertex tangents for normal maps (docs/materials.md §12).
//!
//! A tangent is `xyz` (along increasing u) and `w = ±1`, the handedness: the bitangent is
//! `w · (normal × tangent)` and points along decreasing v, i.e. up in the image, as glTF's
//! normal maps expect (+Y up, texture origin top-left). Tangents come from the `TANGENT`
//! attribute, or are generated with MikkTSpace (the `bevy_mikktspace` crate), as the glTF
//! specification asks. MikkTSpace measures its bitangent along increasing v, so the generated
//! sign is negated.
//!
//! A tangent that is not finite, has no length or is parallel to the normal is replaced by a
//! unit vector perpendicular to the normal ([`sanitize_tangent`]).

use std::collections::HashMap;

use bevy_mikktspace::{Geometry, TangentSpace};
use glam::{Vec2, Vec3, Vec4};

/// `t` (a `TANGENT` value or a generated one) made usable at a vertex of normal `n`: kept as it
/// is when finite and not parallel to `n` (only `w` is reduced to its sign, +1 for 0), else any
/// unit vector perpendicular to `n` with `w = 1`.
pub fn sanitize_tangent(t: Vec4, n: Vec3) -> Vec4 {
    let xyz = t.truncate();
    let w = if t.w < 0.0 { -1.0 } else { 1.0 };
    let len = xyz.length();
    let across = n.cross(xyz).length();
    if t.is_finite() && len > 1e-20 && across > 1e-4 * len * n.length() {
        xyz.extend(w)
    } else {
        let n = n.normalize_or(Vec3::Z);
        n.any_orthonormal_vector().extend(1.0)
    }
}

/// Tangents generated for an indexed triangle list, with the vertices split where MikkTSpace
/// gives the corners of one vertex different tangents (a UV seam, a mirrored half).
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratedTangents {
    /// The input vertex of each output vertex: output vertex `i < n` is input vertex `i`; split
    /// copies follow.
    pub source: Vec<u32>,
    /// One tangent per output vertex.
    pub tangents: Vec<Vec4>,
    /// The triangles over the output vertices.
    pub triangles: Vec<[u32; 3]>,
}

struct Input<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    texcoords: &'a [Vec2],
    triangles: &'a [[u32; 3]],
    corners: Vec<Option<TangentSpace>>,
}

impl Input<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.triangles[face][vert] as usize
    }
}

impl Geometry for Input<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.texcoords[self.vertex(face, vert)].to_array()
    }

    fn set_tangent(&mut self, tangent: Option<TangentSpace>, face: usize, vert: usize) {
        self.corners[3 * face + vert] = tangent;
    }
}

/// MikkTSpace tangents of the triangles `triangles` over the vertex arrays (unit normals, and
/// the texture coordinates the normal map samples: its set through its transform), in glTF's
/// convention (see the module docs), sanitized.
pub fn generate_tangents(
    positions: &[Vec3],
    normals: &[Vec3],
    texcoords: &[Vec2],
    triangles: &[[u32; 3]],
) -> GeneratedTangents {
    let mut input = Input {
        positions,
        normals,
        texcoords,
        triangles,
        corners: vec![None; 3 * triangles.len()],
    };
    // The crate's error type has no variant: generation cannot fail.
    let _ = bevy_mikktspace::generate_tangents(&mut input);
    let n = positions.len();
    let mut tangents: Vec<Option<Vec4>> = vec![None; n];
    let mut source: Vec<u32> = (0..n as u32).collect();
    let mut splits: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    let mut out_triangles = Vec::with_capacity(triangles.len());
    for (face, tri) in triangles.iter().enumerate() {
        let mut out = *tri;
        for (k, &v) in tri.iter().enumerate() {
            let normal = normals[v as usize];
            let t = input.corners[3 * face + k].map_or(Vec4::ZERO, |ts| {
                let e = ts.tangent_encoded();
                Vec4::new(e[0], e[1], e[2], -e[3])
            });
            let t = sanitize_tangent(t, normal);
            match tangents[v as usize] {
                None => tangents[v as usize] = Some(t),
                Some(have) if have == t => {}
                Some(_) => {
                    let key = (v, t.to_array().map(f32::to_bits));
                    out[k] = *splits.entry(key).or_insert_with(|| {
                        source.push(v);
                        tangents.push(Some(t));
                        (source.len() - 1) as u32
                    });
                }
            }
        }
        out_triangles.push(out);
    }
    let tangents = tangents
        .iter()
        .zip(&source)
        .map(|(t, &v)| t.unwrap_or_else(|| sanitize_tangent(Vec4::ZERO, normals[v as usize])))
        .collect();
    GeneratedTangents {
        source,
        tangents,
        triangles: out_triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit quad in the plane y = 0 facing +Y, corners (0,0,0), (0,0,1), (1,0,1), (1,0,0), with
    /// texture coordinates `uv(corner)`.
    fn quad(uv: impl Fn(Vec3) -> Vec2) -> GeneratedTangents {
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let t: Vec<Vec2> = p.iter().map(|&q| uv(q)).collect();
        generate_tangents(&p, &[Vec3::Y; 4], &t, &[[0, 1, 2], [0, 2, 3]])
    }

    fn assert_all(g: &GeneratedTangents, want: Vec4) {
        assert_eq!(g.source, vec![0, 1, 2, 3], "no vertex needed a split");
        for t in &g.tangents {
            assert!((*t - want).abs().max_element() < 1e-6, "{t} != {want}");
        }
    }

    #[test]
    fn a_quad_gets_the_tangent_of_its_uv_layout() {
        // u along +x, v along +z (glTF v runs down the image, so "up" is −z): tangent +x and a
        // bitangent normal × tangent = −z, i.e. w = +1.
        assert_all(
            &quad(|p| Vec2::new(p.x, p.z)),
            Vec4::new(1.0, 0.0, 0.0, 1.0),
        );
        // v along −z: the bitangent (up the image) is +z = −(normal × tangent).
        assert_all(
            &quad(|p| Vec2::new(p.x, 1.0 - p.z)),
            Vec4::new(1.0, 0.0, 0.0, -1.0),
        );
        // u along −z, v along −x (a mirrored layout): tangent −z, up the image +x =
        // −(normal × tangent), w = −1.
        assert_all(
            &quad(|p| Vec2::new(1.0 - p.z, 1.0 - p.x)),
            Vec4::new(0.0, 0.0, -1.0, -1.0),
        );
    }

    #[test]
    fn a_seam_splits_the_shared_vertices() {
        // The second triangle's texture is the first one's mirrored about the shared diagonal
        // (vertex 3 takes vertex 1's texture coordinates): tangent +z with w = −1 there, +x with
        // w = +1 in the first, so the diagonal's two vertices are split.
        let p = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let uv = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        let g = generate_tangents(&p, &[Vec3::Y; 4], &uv, &[[0, 1, 2], [0, 2, 3]]);
        for (tri, out) in [[0u32, 1, 2], [0, 2, 3]].iter().zip(&g.triangles) {
            for (k, &v) in tri.iter().enumerate() {
                assert_eq!(g.source[out[k] as usize], v);
            }
        }
        let want = [
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 1.0, -1.0),
        ];
        for (out, want) in g.triangles.iter().zip(want) {
            for &v in out {
                let t = g.tangents[v as usize];
                assert!((t - want).abs().max_element() < 1e-6, "{t} != {want}");
            }
        }
        assert_eq!(g.source.len(), 6, "vertices 0 and 2 split: {:?}", g.source);
    }

    #[test]
    fn unusable_tangents_are_replaced_by_a_perpendicular() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let keep = Vec4::new(0.3, 0.4, -0.3, -1.0);
        assert_eq!(sanitize_tangent(keep, n), keep);
        assert_eq!(
            sanitize_tangent(Vec4::new(1.0, 0.0, 0.0, 0.0), n).w,
            1.0,
            "w 0 becomes +1"
        );
        for bad in [
            Vec4::ZERO,
            Vec4::new(f32::NAN, 0.0, 1.0, 1.0),
            Vec4::new(0.0, f32::INFINITY, 0.0, 1.0),
            n.extend(1.0),
            (-n * 3.0).extend(-1.0),
        ] {
            let t = sanitize_tangent(bad, n);
            assert!(t.is_finite(), "{bad} → {t}");
            assert!((t.truncate().length() - 1.0).abs() < 1e-6, "{bad} → {t}");
            assert!(t.truncate().dot(n).abs() < 1e-6, "{bad} → {t}");
            assert_eq!(t.w.abs(), 1.0);
        }
    }
}
