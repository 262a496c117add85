//! Triangle meshes: one [`Mesh`] per glTF mesh, its primitives merged.
//!
//! Layout chosen for the GPU side (one BLAS per mesh): all TRIANGLES primitives of a glTF mesh are
//! concatenated into one vertex array (positions, normals, TEXCOORD_0, and TEXCOORD_1 where a
//! material samples it) and one `u32` index array,
//! with a per-triangle material id (`triangle_materials`) and per-primitive [`PrimitiveRange`]s
//! (contiguous triangle and vertex ranges with a single material).
//!
//! Clean-up rules, each reported as a [`Warning`](crate::Warning):
//! - primitives of another mode (points, lines, strips, fans) are skipped;
//! - degenerate triangles (repeated index, or `|e1 × e2| <= 1e-6 |e1| |e2|`) are dropped, with a count;
//! - a primitive without normals, or with a zero-length normal, gets flat normals: its vertices are
//!   de-indexed so that each triangle has its own three vertices carrying the face normal.
//! - a primitive whose material has a normal map gets tangents: its `TANGENT` attribute, else
//!   MikkTSpace tangents of the coordinates the map samples (its set, through its transform; its
//!   vertices split where they need two); without normals or that set its normal map is ignored
//!   (zero tangents);
//! - a primitive whose material samples TEXCOORD_1 keeps it (zero coordinates, with a warning,
//!   where the attribute is missing); other primitives' TEXCOORD_1 is not read.
//!
//! NaN/Inf in positions, normals, texcoords or tangents and indices out of range are errors.

use glam::{Vec2, Vec3, Vec4};

use crate::accessor;
use crate::error::{label, Error, Result, WarningKind, Warnings};
use crate::math::{triangle_cross, Aabb};
use crate::resources::Source;
use crate::tangent::{generate_tangents, sanitize_tangent};
use crate::texture::TextureRef;

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
    /// TEXCOORD_1: same length as `positions` when some primitive's material samples a texture
    /// through it ([`Material::uses_texcoord1`](crate::Material::uses_texcoord1)), else empty.
    /// Zero on the vertices of the other primitives and where the attribute is missing.
    pub texcoords1: Vec<Vec2>,
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

/// What a primitive's material needs from its vertices.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct VertexNeeds {
    /// The material's normal map, whose coordinates generated tangents follow.
    pub(crate) normal_map: Option<TextureRef>,
    /// Some texture reference of the material samples TEXCOORD_1.
    pub(crate) texcoord1: bool,
}

/// One primitive's data after reading and validation.
struct PrimData {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    texcoords: Option<Vec<Vec2>>,
    /// TEXCOORD_1, read only when the material samples it.
    texcoords1: Option<Vec<Vec2>>,
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
/// `needs` says what glTF material `i` needs from its vertices.
pub(crate) fn load_mesh(
    src: &Source,
    m: &gltf::Mesh<'_>,
    material_of: &mut dyn FnMut(Option<usize>) -> u32,
    needs: &dyn Fn(u32) -> VertexNeeds,
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
        // The default material (no glTF material) has no textures.
        let prim_needs = prim
            .material()
            .index()
            .map_or(VertexNeeds::default(), |i| needs(i as u32));
        let Some(data) = read_primitive(src, &prim, prim_needs, &user, warnings)? else {
            continue;
        };
        let material = material_of(prim.material().index());
        let at = PrimAt {
            gltf_primitive: prim.index(),
            material,
            needs: prim_needs,
        };
        append_primitive(src, &mut mesh, data, at, &user, warnings)?;
    }
    if !mesh.tangents.is_empty() {
        mesh.tangents.resize(mesh.positions.len(), Vec4::ZERO);
    }
    if !mesh.texcoords1.is_empty() {
        mesh.texcoords1.resize(mesh.positions.len(), Vec2::ZERO);
    }
    for &p in &mesh.positions {
        mesh.bounds.extend(p);
    }
    Ok(mesh)
}

/// Reads a primitive's attributes; `TANGENT` only when the material has a normal map, else
/// `tangents` is `None` (with a normal map and no `TANGENT`, `tangents` is an empty list:
/// generate them); TEXCOORD_1 only when the material samples it.
fn read_primitive(
    src: &Source,
    prim: &gltf::Primitive<'_>,
    needs: VertexNeeds,
    user: &str,
    warnings: &mut Warnings,
) -> Result<Option<PrimData>> {
    let want_tangents = needs.normal_map.is_some();
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
    let read_texcoords = |set: u32| -> Result<Option<Vec<Vec2>>> {
        let Some(acc) = prim.get(&gltf::Semantic::TexCoords(set)) else {
            return Ok(None);
        };
        let what = format!("TEXCOORD_{set}");
        let u = format!("{user} {what}");
        let v = accessor::read_vec2(src, &acc, &u)?;
        check_finite(src, accessor::element_label(&acc, &u), &v, |v| {
            v.is_finite()
        })?;
        if v.len() != n {
            return Err(count_err(&acc, &what, v.len()));
        }
        Ok(Some(v))
    };
    let texcoords = read_texcoords(0)?;
    let texcoords1 = if needs.texcoord1 {
        read_texcoords(1)?
    } else {
        None
    };
    if needs.texcoord1 && texcoords1.is_none() {
        let msg = format!(
            "{}: {user}: no TEXCOORD_1 although its material samples a texture through it; \
             those lookups use (0, 0)",
            src.path.display()
        );
        warnings.push(WarningKind::TextureIgnored, 1, msg);
    }
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
        texcoords1,
        tangents,
        indices,
    }))
}

/// Where a primitive goes and what its material needs.
#[derive(Clone, Copy, Debug)]
struct PrimAt {
    gltf_primitive: usize,
    material: u32,
    needs: VertexNeeds,
}

fn append_primitive(
    src: &Source,
    mesh: &mut Mesh,
    data: PrimData,
    at: PrimAt,
    user: &str,
    warnings: &mut Warnings,
) -> Result<()> {
    let PrimAt {
        gltf_primitive,
        material,
        needs,
    } = at;
    let PrimData {
        positions,
        normals,
        texcoords,
        texcoords1,
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
    let tc1 = |i: u32| texcoords1.as_ref().map_or(Vec2::ZERO, |t| t[i as usize]);
    // The normal map's set is there (without a normal map nothing asks).
    let map_set_present = match needs.normal_map {
        Some(r) if r.tex_coord == 1 => texcoords1.is_some(),
        _ => texcoords.is_some(),
    };
    let map_set = needs.normal_map.map_or(0, |r| r.tex_coord);
    let ignored = |why: &str| {
        format!(
            "{}: {user}: {why}; its material's normal map is ignored",
            src.path.display()
        )
    };
    let mut prim_tangents = None;
    let prim_uv1: Option<Vec<Vec2>>;
    match usable_normals {
        Some(ns) => {
            let mut ns: Vec<Vec3> = ns.iter().map(|n| n.normalize()).collect();
            let count = positions.len() as u32;
            let mut uvs: Vec<Vec2> = (0..count).map(tc).collect();
            let mut uvs1: Vec<Vec2> = (0..count).map(tc1).collect();
            let mut positions = positions;
            match (tangents, map_set_present) {
                (None, _) => {}
                (Some(_), false) => {
                    let msg = ignored(&format!("no TEXCOORD_{map_set}"));
                    warnings.push(WarningKind::TextureIgnored, 1, msg);
                }
                (Some(file), true) if !file.is_empty() => {
                    let t = file.iter().zip(&ns).map(|(&t, &n)| sanitize_tangent(t, n));
                    prim_tangents = Some(t.collect());
                }
                (Some(_), true) => {
                    // The tangent frame of the coordinates the map is sampled at.
                    let mapped: Vec<Vec2> = match needs.normal_map {
                        Some(map) => uvs
                            .iter()
                            .zip(&uvs1)
                            .map(|(&a, &b)| map.map(a, b))
                            .collect(),
                        None => uvs.clone(),
                    };
                    let g = generate_tangents(&positions, &ns, &mapped, &kept);
                    let remap = |v: &[Vec2]| -> Vec<Vec2> {
                        g.source.iter().map(|&i| v[i as usize]).collect()
                    };
                    uvs = remap(&uvs);
                    uvs1 = remap(&uvs1);
                    positions = g.source.iter().map(|&v| positions[v as usize]).collect();
                    ns = g.source.iter().map(|&v| ns[v as usize]).collect();
                    kept = g.triangles;
                    prim_tangents = Some(g.tangents);
                }
            }
            let base = u32::try_from(first_vertex).map_err(|_| too_big())?;
            u32::try_from(first_vertex + positions.len()).map_err(|_| too_big())?;
            mesh.normals.extend(ns);
            mesh.texcoords.extend(uvs);
            prim_uv1 = needs.texcoord1.then_some(uvs1);
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
            let mut uvs1 = Vec::new();
            for t in &kept {
                let p = t.map(|i| positions[i as usize]);
                let n = triangle_cross(&p).normalize_or(Vec3::Z);
                for (k, &i) in t.iter().enumerate() {
                    mesh.indices.push(mesh.positions.len() as u32);
                    mesh.positions.push(p[k]);
                    mesh.normals.push(n);
                    mesh.texcoords.push(tc(i));
                    uvs1.push(tc1(i));
                }
            }
            prim_uv1 = needs.texcoord1.then_some(uvs1);
        }
    }
    if let Some(t) = prim_uv1 {
        mesh.texcoords1.resize(first_vertex, Vec2::ZERO);
        mesh.texcoords1.extend(t);
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
