//! Normal maps in the loader (docs/materials.md §12): `normalTexture` and its scale, tangents
//! from `TANGENT` (kept as they are) or generated with MikkTSpace in glTF's convention, the cases
//! where the map is ignored, the plan's `normal_maps` flag, and two real files from
//! `../shared/models/` (DamagedHelmet: a normal map without TANGENT; Suzanne: TANGENT without a
//! normal map).

mod common;

use std::path::{Path, PathBuf};

use common::{load, temp_dir, warnings_of, write};
use glam::{Vec2, Vec3, Vec4};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{Scene, WarningKind};

/// The unit quad of the plane y = 0 facing +Y (counter-clockwise from above), with u along +x
/// and v along +z.
fn quad(material: Option<usize>) -> PrimitiveDesc {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ];
    PrimitiveDesc {
        texcoords: Some(positions.iter().map(|p| [p[0], p[2]]).collect()),
        ..PrimitiveDesc::triangles(
            positions,
            Some(vec![[0.0, 1.0, 0.0]; 4]),
            vec![0, 1, 2, 0, 2, 3],
            material,
        )
    }
}

/// A builder with a 2×2 normal texture and a material using it with `scale`; returns the
/// builder and the material.
fn normal_mapped(scale: f32) -> (GltfBuilder, usize) {
    let mut b = GltfBuilder::new();
    let texel = [200u8, 128, 230, 255];
    let tex = b.add_texture_rgba8(2, 2, &texel.repeat(4), 10497).unwrap();
    let m = b.add_material(&MaterialDesc {
        normal_texture: Some((tex, scale)),
        ..MaterialDesc::diffuse("bumpy", [0.5; 3])
    });
    (b, m)
}

/// Adds a mesh of `prims`, a node for it and the scene; writes and loads.
fn finish(
    mut b: GltfBuilder,
    prims: &[PrimitiveDesc],
    tag: &str,
) -> (Scene, Vec<radcache_scene::Warning>) {
    let mesh = b.add_mesh("m", prims);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    load(&write(&b, &temp_dir(tag), tag))
}

#[track_caller]
fn close4(a: Vec4, b: Vec4) {
    assert!((a - b).abs().max_element() < 1e-6, "{a} != {b}");
}

#[test]
fn generated_tangents_follow_the_texture_layout() {
    let (b, m) = normal_mapped(0.7);
    let (scene, warnings) = finish(b, &[quad(Some(m))], "generated");
    assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (0, 0));
    let mat = &scene.materials[0];
    assert_eq!(mat.normal_scale, 0.7);
    let tex = mat.normal_texture.expect("normal texture");
    let image = &scene.images[scene.textures[tex.texture].image];
    assert!(!image.srgb, "normal maps are linear data");
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.tangents.len(), 4, "no vertex needed a split");
    // u along +x; v along +z runs down the image, so the bitangent (up) is −z = +y × +x: w = +1.
    for &t in &mesh.tangents {
        close4(t, Vec4::new(1.0, 0.0, 0.0, 1.0));
    }
    let plan = scene.plan();
    assert!(plan.normal_maps);
    assert!(plan.to_string().contains("normal maps: yes"), "{plan}");
}

#[test]
fn the_tangent_attribute_is_used_as_it_is() {
    let (b, m) = normal_mapped(1.0);
    // Not unit, not perpendicular to the normal, w = −1: kept bit for bit. The last one is
    // parallel to the normal, so it is replaced by a unit perpendicular.
    let file = [
        [0.6, 0.0, 0.8, -1.0],
        [0.3, 0.2, -0.9, 1.0],
        [2.0, 0.5, 0.0, -1.0],
        [0.0, 1.0, 0.0, 1.0],
    ];
    let prim = PrimitiveDesc {
        tangents: Some(file.to_vec()),
        ..quad(Some(m))
    };
    let (scene, warnings) = finish(b, &[prim], "attribute");
    assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (0, 0));
    let t = &scene.meshes[0].tangents;
    for k in 0..3 {
        assert_eq!(t[k].to_array().map(f32::to_bits), file[k].map(f32::to_bits));
    }
    assert!((t[3].truncate().length() - 1.0).abs() < 1e-6 && t[3].y.abs() < 1e-6);
    assert_eq!(t[3].w, 1.0);
}

#[test]
fn without_normals_or_texcoords_the_map_is_ignored() {
    let (b, m) = normal_mapped(1.0);
    let prim = PrimitiveDesc {
        texcoords: None,
        ..quad(Some(m))
    };
    let (scene, warnings) = finish(b, &[prim], "no-uv");
    assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (1, 1));
    assert!(
        warnings[0].message.contains("no TEXCOORD_0"),
        "{warnings:?}"
    );
    assert!(scene.meshes[0].tangents.is_empty());
    assert!(!scene.plan().normal_maps);

    let (b, m) = normal_mapped(1.0);
    let prim = PrimitiveDesc {
        normals: None,
        tangents: Some(vec![[1.0, 0.0, 0.0, 1.0]; 4]),
        ..quad(Some(m))
    };
    let (scene, warnings) = finish(b, &[prim], "no-normals");
    assert_eq!(
        warnings_of(&warnings, WarningKind::GeneratedNormals),
        (1, 1)
    );
    assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (1, 1));
    assert!(scene.meshes[0].tangents.is_empty());
    assert!(!scene.plan().normal_maps);
}

#[test]
fn only_normal_mapped_primitives_carry_tangents() {
    let (mut b, m) = normal_mapped(1.0);
    let plain = b.add_material(&MaterialDesc::diffuse("plain", [0.5; 3]));
    // A plain primitive with a TANGENT attribute (not read), then a normal-mapped one, then a
    // plain one without.
    let first = PrimitiveDesc {
        tangents: Some(vec![[0.0, 0.0, 1.0, 1.0]; 4]),
        ..quad(Some(plain))
    };
    let (scene, _) = finish(
        b,
        &[first.clone(), quad(Some(m)), quad(Some(plain))],
        "mixed",
    );
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.tangents.len(), mesh.positions.len());
    assert_eq!(mesh.positions.len(), 12);
    for (i, &t) in mesh.tangents.iter().enumerate() {
        let want = if (4..8).contains(&i) {
            Vec4::new(1.0, 0.0, 0.0, 1.0)
        } else {
            Vec4::ZERO
        };
        close4(t, want);
    }
    assert!(scene.plan().normal_maps);

    // No normal-mapped material: no tangents at all, even where the file has them.
    let mut b = GltfBuilder::new();
    let plain = b.add_material(&MaterialDesc::diffuse("plain", [0.5; 3]));
    let (scene, _) = finish(
        b,
        &[PrimitiveDesc {
            material: Some(plain),
            ..first
        }],
        "plain",
    );
    assert!(scene.meshes[0].tangents.is_empty());
    let plan = scene.plan();
    assert!(!plan.normal_maps);
    assert!(plan.to_string().contains("normal maps: none"), "{plan}");
}

/// `shared/models/<rel>` in the nearest ancestor of the repository that has `shared/models`
/// (CI: beside the checkout; a worktree may sit deeper).
fn shared_model(rel: &str) -> PathBuf {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let repo = repo.canonicalize().unwrap();
    let models = repo
        .ancestors()
        .skip(1)
        .map(|d| d.join("shared/models"))
        .find(|d| d.is_dir())
        .unwrap_or_else(|| panic!("no shared/models beside {} or above it", repo.display()));
    models.join(rel)
}

#[test]
fn damaged_helmet_gets_mikktspace_tangents_in_the_gltf_convention() {
    let path = shared_model("DamagedHelmet/glTF-Binary/DamagedHelmet.glb");
    let (scene, _) = load(&path);
    let plan = scene.plan();
    assert!(plan.normal_maps, "{plan}");
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.tangents.len(), mesh.positions.len());
    for (t, n) in mesh.tangents.iter().zip(&mesh.normals) {
        assert!(t.is_finite() && t.w.abs() == 1.0, "{t}");
        assert!((t.truncate().length() - 1.0).abs() < 1e-3, "{t}");
        assert!(t.truncate().dot(*n).abs() < 1e-3, "{t} against {n}");
    }
    // Per triangle: the tangent runs along increasing u, the bitangent w·(n × t) along
    // decreasing v (up the image).
    let (mut faces, mut along_u, mut up) = (0usize, 0usize, 0usize);
    for tri in mesh.indices.chunks_exact(3) {
        let i = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let (p, uv): ([Vec3; 3], [Vec2; 3]) =
            (i.map(|k| mesh.positions[k]), i.map(|k| mesh.texcoords[k]));
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-8 {
            continue;
        }
        let dp_du = (e1 * d2.y - e2 * d1.y) / det;
        let dp_dv = (e2 * d1.x - e1 * d2.x) / det;
        faces += 1;
        let t = mesh.tangents[i[0]];
        let b = mesh.normals[i[0]].cross(t.truncate()) * t.w;
        along_u += usize::from(t.truncate().dot(dp_du) > 0.0);
        up += usize::from(b.dot(-dp_dv) > 0.0);
    }
    let (fu, fv) = (along_u as f64 / faces as f64, up as f64 / faces as f64);
    eprintln!("DamagedHelmet: {faces} faces; tangent along +u on {fu:.4}, bitangent up on {fv:.4}");
    assert!(faces > 10_000 && fu > 0.99 && fv > 0.99);
}

#[test]
fn suzanne_has_tangents_but_no_normal_map_until_one_is_added() {
    let path = shared_model("Suzanne/glTF/Suzanne.gltf");
    let (scene, _) = load(&path);
    assert!(scene.materials[0].normal_texture.is_none());
    assert!(scene.meshes[0].tangents.is_empty());
    assert!(!scene.plan().normal_maps);

    // A copy whose material uses its (linear) metallic-roughness texture as a normal map: the
    // file's TANGENT values arrive unchanged.
    let dir = temp_dir("suzanne");
    let src = path.parent().unwrap();
    for f in [
        "Suzanne.bin",
        "Suzanne_BaseColor.png",
        "Suzanne_MetallicRoughness.png",
    ] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let mr =
        json["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"].clone();
    json["materials"][0]["normalTexture"] = serde_json::json!({"index": mr});
    let copy = dir.join("Suzanne.gltf");
    std::fs::write(&copy, json.to_string()).unwrap();
    let (scene, _) = load(&copy);
    assert!(scene.plan().normal_maps);

    let doc = gltf::Gltf::open(&path).unwrap();
    let bin = std::fs::read(src.join("Suzanne.bin")).unwrap();
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|_| Some(&bin[..]));
    let file: Vec<[f32; 4]> = reader.read_tangents().unwrap().collect();
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.tangents.len(), file.len());
    let same = mesh
        .tangents
        .iter()
        .zip(&file)
        .filter(|(t, f)| t.to_array().map(f32::to_bits) == f.map(f32::to_bits))
        .count();
    eprintln!("Suzanne: {same} of {} tangents as in the file", file.len());
    assert_eq!(same, file.len());
}
