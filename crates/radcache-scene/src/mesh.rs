//! Triangle meshes: one [`Mesh`] per glTF mesh, its primitives merged.
//!
//! Layout chosen for the GPU side (one BLAS per mesh): all TRIANGLES primitives of a glTF mesh are
//! concatenated into one vertex array (positions, normals, texcoord0) and one `u32` index array,
//! with a per-triangle material id (`triangle_materials`) and per-primitive [`PrimitiveRange`]s
//! (contiguous triangle and vertex ranges with a single material).
//!
//! Clean-up rules, each reported as a [`Warning`](crate::Warning):
//! - primitives of another mode (points, lines, strips, fans) are skipped;
//! - degenerate triangles (repeated index, or `|e1 × e2| <= 1e-6 |e1| |e2|`) are dropped, with a count;
//! - a primitive without normals, or with a zero-length normal, gets flat normals: its vertices are
//!   de-indexed so that each triangle has its own three vertices carrying the face normal.
//! - a primitive whose material has a normal map gets tangents: its `TANGENT` attribute, else
//!   MikkTSpace tangents (its vertices split where they need two); without normals or TEXCOORD_0
//!   its normal map is ignored (zero tangents).
//!
//! NaN/Inf in positions, normals, texcoords or tangents and indices out of range are errors.

use glam::{Vec2, Vec3, Vec4};

use crate::accessor;
use crate::error::{label, Error, Result, WarningKind, Warnings};
use crate::math::{triangle_cross, Aabb};
use crate::resources::Source;
use crate::tangent::{generate_tangents, sanitize_tangent};

/// A triangle mesh in its local (object) space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// glTF mesh name.
    pub name: Option<String>,
    /// Vertex positions (m).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, same length as `positions`.
    pub normals: Vec<Vec3>,
    /// TEXCOORD_0, same length as `positions` (zero where the primitive had none).
    pub texcoords: Vec<Vec2>,
    /// Tangents (xyz, and w = ±1: bitangent = w · normal × tangent; see [`crate::tangent`]): same
    /// length as `positions` when some primitive's material has a normal map, else empty. Zero
    /// on the vertices of primitives that use no normal map.
    pub tangents: Vec<Vec4>,
    /// Three indices per triangle into the vertex arrays, counter-clockwise front faces.
    pub indices: Vec<u32>,
    /// Material index (into `Scene::materials`) of each triangle.
    pub triangle_materials: Vec<u32>,
    /// The kept primitives, in glTF order.
    pub primitives: Vec<PrimitiveRange>,
    /// Local-space bounds of `positions`.
    pub bounds: Aabb,
}

/// A contiguous range of a [`Mesh`] coming from one glTF primitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PrimitiveRange {
    /// Index of the primitive in the glTF mesh.
    pub gltf_primitive: usize,
    /// Material index (into `Scene::materials`).
    pub material: u32,
    /// First triangle (into `Mesh::triangle_materials`; indices start at `3 * first_triangle`).
    pub first_triangle: u32,
    /// Number of triangles.
    pub triangle_count: u32,
    /// First vertex of the range.
    pub first_vertex: u32,
    /// Number of vertices.
    pub vertex_count: u32,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The three local-space positions of triangle `t` (panics if `t` is out of range).
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[3 * t..3 * t + 3];
        [
            self.positions[i[0] as usize],
            self.positions[i[1] as usize],
            self.positions[i[2] as usize],
        ]
    }
}

/// Is the triangle degenerate (zero area or repeated index)?
pub fn is_degenerate(idx: [u32; 3], p: &[Vec3; 3]) -> bool {
    if idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2] {
        return true;
    }
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let c = triangle_cross(p).length_squared();
    let threshold = 1e-12 * e1.length_squared() * e2.length_squared();
    c.is_nan() || c <= threshold || c == 0.0
}

/// One primitive's data after reading and validation.
struct PrimData {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    texcoords: Option<Vec<Vec2>>,
    tangents: Option<Vec<Vec4>>,
    indices: Vec<u32>,
}

fn check_finite<T: Copy>(
    src: &Source,
    element: String,
    data: &[T],
    finite: impl Fn(T) -> bool,
) -> Result<()> {
    match data.iter().position(|&v| !finite(v)) {
        Some(position) => Err(Error::NonFinite {
            path: src.path(),
            element,
            position,
        }),
        None => Ok(()),
    }
}

/// Loads glTF mesh `m`. `material_of` maps a primitive's material (None = default) to an index;
/// `normal_mapped` says whether glTF material `i` has a normal map.
pub(crate) fn load_mesh(
    src: &Source,
    m: &gltf::Mesh<'_>,
    material_of: &mut dyn FnMut(Option<usize>) -> u32,
    normal_mapped: &dyn Fn(u32) -> bool,
    warnings: &mut Warnings,
) -> Result<Mesh> {
    let mesh_label = label("mesh", m.index(), m.name());
    let mut mesh = Mesh {
        name: m.name().map(str::to_string),
        bounds: Aabb::EMPTY,
        ..Mesh::default()
    };
    for prim in m.primitives() {
        let user = format!("{mesh_label} primitive {}", prim.index());
        if prim.mode() != gltf::mesh::Mode::Triangles {
            warnings.push(
                WarningKind::UnsupportedPrimitiveMode,
                1,
                format!(
                    "{}: {user}: mode {:?} is not TRIANGLES; skipped",
                    src.path.display(),
                    prim.mode()
                ),
            );
            continue;
        }
        if prim.morph_targets().len() > 0 {
            warnings.push(
                WarningKind::SkinOrMorphIgnored,
                1,
                format!(
                    "{}: {user}: morph targets ignored (rest pose used)",
                    src.path.display()
                ),
            );
        }
        // The default material (no glTF material) has no normal map.
        let want_tangents = prim
            .material()
            .index()
            .is_some_and(|i| normal_mapped(i as u32));
        let Some(data) = read_primitive(src, &prim, want_tangents, &user, warnings)? else {
            continue;
        };
        let material = material_of(prim.material().index());
        append_primitive(
            src,
            &mut mesh,
            data,
            prim.index(),
            material,
            &user,
            warnings,
        )?;
    }
    if !mesh.tangents.is_empty() {
        mesh.tangents.resize(mesh.positions.len(), Vec4::ZERO);
    }
    for &p in &mesh.positions {
        mesh.bounds.extend(p);
    }
    Ok(mesh)
}

/// Reads a primitive's attributes; `TANGENT` only when `want_tangents` (a normal-mapped
/// material), else `tangents` is `None`. With `want_tangents` and no `TANGENT`, `tangents` is an
/// empty list: generate them.
fn read_primitive(
    src: &Source,
    prim: &gltf::Primitive<'_>,
    want_tangents: bool,
    user: &str,
    warnings: &mut Warnings,
) -> Result<Option<PrimData>> {
    let Some(pos_acc) = prim.get(&gltf::Semantic::Positions) else {
        warnings.push(
            WarningKind::Other,
            1,
            format!(
                "{}: {user}: no POSITION attribute; skipped",
                src.path.display()
            ),
        );
        return Ok(None);
    };
    let pos_user = format!("{user} POSITION");
    let positions = accessor::read_vec3(src, &pos_acc, &pos_user)?;
    check_finite(
        src,
        accessor::element_label(&pos_acc, &pos_user),
        &positions,
        |v| v.is_finite(),
    )?;
    let n = positions.len();
    let count_err = |acc: &gltf::Accessor<'_>, what: &str, have: usize| Error::Accessor {
        path: src.path(),
        element: accessor::element_label(acc, &format!("{user} {what}")),
        reason: format!("has {have} elements but POSITION has {n}"),
    };
    let normals = match prim.get(&gltf::Semantic::Normals) {
        Some(acc) => {
            let u = format!("{user} NORMAL");
            let v = accessor::read_vec3(src, &acc, &u)?;
            check_finite(src, accessor::element_label(&acc, &u), &v, |v| {
                v.is_finite()
            })?;
            if v.len() != n {
                return Err(count_err(&acc, "NORMAL", v.len()));
            }
            Some(v)
        }
        None => None,
    };
    let texcoords = match prim.get(&gltf::Semantic::TexCoords(0)) {
        Some(acc) => {
            let u = format!("{user} TEXCOORD_0");
            let v = accessor::read_vec2(src, &acc, &u)?;
            check_finite(src, accessor::element_label(&acc, &u), &v, |v| {
                v.is_finite()
            })?;
            if v.len() != n {
                return Err(count_err(&acc, "TEXCOORD_0", v.len()));
            }
            Some(v)
        }
        None => None,
    };
    let tangents = match prim
        .get(&gltf::Semantic::Tangents)
        .filter(|_| want_tangents)
    {
        Some(acc) => {
            let u = format!("{user} TANGENT");
            let v = accessor::read_any_vec(src, &acc, &u, 4)?;
            check_finite(src, accessor::element_label(&acc, &u), &v, |v| {
                v.is_finite()
            })?;
            if v.len() != n {
                return Err(count_err(&acc, "TANGENT", v.len()));
            }
            Some(v)
        }
        None => want_tangents.then(Vec::new),
    };
    let mut indices = match prim.indices() {
        Some(acc) => {
            let u = format!("{user} indices");
            let idx = accessor::read_indices(src, &acc, &u)?;
            if let Some(position) = idx.iter().position(|&i| i as usize >= n) {
                return Err(Error::IndexOutOfRange {
                    path: src.path(),
                    element: accessor::element_label(&acc, &u),
                    index: idx[position],
                    position,
                    vertex_count: n,
                });
            }
            idx
        }
        None => {
            let n32 = u32::try_from(n).map_err(|_| Error::Invalid {
                path: src.path(),
                element: user.to_string(),
                reason: format!("{n} vertices exceed the u32 range"),
            })?;
            (0..n32).collect()
        }
    };
    if !indices.len().is_multiple_of(3) {
        warnings.push(
            WarningKind::Other,
            1,
            format!(
                "{}: {user}: {} indices is not a multiple of 3; trailing indices ignored",
                src.path.display(),
                indices.len()
            ),
        );
        indices.truncate(indices.len() / 3 * 3);
    }
    Ok(Some(PrimData {
        positions,
        normals,
        texcoords,
        tangents,
        indices,
    }))
}

fn append_primitive(
    src: &Source,
    mesh: &mut Mesh,
    data: PrimData,
    gltf_primitive: usize,
    material: u32,
    user: &str,
    warnings: &mut Warnings,
) -> Result<()> {
    let PrimData {
        positions,
        normals,
        texcoords,
        tangents,
        indices,
    } = data;
    let mut kept: Vec<[u32; 3]> = Vec::with_capacity(indices.len() / 3);
    for t in indices.chunks_exact(3) {
        let idx = [t[0], t[1], t[2]];
        let p = idx.map(|i| positions[i as usize]);
        if !is_degenerate(idx, &p) {
            kept.push(idx);
        }
    }
    let dropped = indices.len() / 3 - kept.len();
    if dropped > 0 {
        warnings.push(
            WarningKind::DegenerateTriangles,
            dropped,
            format!(
                "{}: {user}: dropped {dropped} degenerate triangle(s)",
                src.path.display()
            ),
        );
    }
    let usable_normals = normals.filter(|ns| ns.iter().all(|v| v.length_squared() > 1e-20));
    let first_vertex = mesh.positions.len();
    let first_triangle = mesh.triangle_materials.len();
    let too_big = || Error::Invalid {
        path: src.path(),
        element: user.to_string(),
        reason: "mesh exceeds 2^32 vertices".into(),
    };
    let tc = |i: u32| texcoords.as_ref().map_or(Vec2::ZERO, |t| t[i as usize]);
    let ignored = |why: &str| {
        format!(
            "{}: {user}: {why}; its material's normal map is ignored",
            src.path.display()
        )
    };
    let mut prim_tangents = None;
    match usable_normals {
        Some(ns) => {
            let mut ns: Vec<Vec3> = ns.iter().map(|n| n.normalize()).collect();
            let mut uvs: Vec<Vec2> = (0..positions.len() as u32).map(tc).collect();
            let mut positions = positions;
            match (tangents, texcoords.is_some()) {
                (None, _) => {}
                (Some(_), false) => {
                    let msg = ignored("no TEXCOORD_0");
                    warnings.push(WarningKind::TextureIgnored, 1, msg);
                }
                (Some(file), true) if !file.is_empty() => {
                    let t = file.iter().zip(&ns).map(|(&t, &n)| sanitize_tangent(t, n));
                    prim_tangents = Some(t.collect());
                }
                (Some(_), true) => {
                    let g = generate_tangents(&positions, &ns, &uvs, &kept);
                    positions = g.source.iter().map(|&v| positions[v as usize]).collect();
                    ns = g.source.iter().map(|&v| ns[v as usize]).collect();
                    uvs = g.source.iter().map(|&v| uvs[v as usize]).collect();
                    kept = g.triangles;
                    prim_tangents = Some(g.tangents);
                }
            }
            let base = u32::try_from(first_vertex).map_err(|_| too_big())?;
            u32::try_from(first_vertex + positions.len()).map_err(|_| too_big())?;
            mesh.normals.extend(ns);
            mesh.texcoords.extend(uvs);
            mesh.positions.extend_from_slice(&positions);
            for t in &kept {
                mesh.indices.extend(t.iter().map(|&i| base + i));
            }
        }
        None => {
            if tangents.is_some() {
                let msg = ignored("no usable normals (flat normals generated)");
                warnings.push(WarningKind::TextureIgnored, 1, msg);
            }
            warnings.push(
                WarningKind::GeneratedNormals,
                1,
                format!(
                    "{}: {user}: missing or zero-length normals; flat normals generated",
                    src.path.display()
                ),
            );
            u32::try_from(first_vertex + 3 * kept.len()).map_err(|_| too_big())?;
            for t in &kept {
                let p = t.map(|i| positions[i as usize]);
                let n = triangle_cross(&p).normalize_or(Vec3::Z);
                for (k, &i) in t.iter().enumerate() {
                    mesh.indices.push(mesh.positions.len() as u32);
                    mesh.positions.push(p[k]);
                    mesh.normals.push(n);
                    mesh.texcoords.push(tc(i));
                }
            }
        }
    }
    if let Some(t) = prim_tangents {
        mesh.tangents.resize(first_vertex, Vec4::ZERO);
        mesh.tangents.extend(t);
    }
    mesh.triangle_materials
        .extend(std::iter::repeat_n(material, kept.len()));
    mesh.primitives.push(PrimitiveRange {
        gltf_primitive,
        material,
        first_triangle: first_triangle as u32,
        triangle_count: kept.len() as u32,
        first_vertex: first_vertex as u32,
        vertex_count: (mesh.positions.len() - first_vertex) as u32,
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_detection() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(!is_degenerate([0, 1, 2], &p));
        assert!(is_degenerate([0, 0, 2], &p));
        let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        assert!(is_degenerate([0, 1, 2], &line));
        let same = [Vec3::ONE; 3];
        assert!(is_degenerate([0, 1, 2], &same));
    }
}
