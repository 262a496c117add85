//! Texture coordinate sets and `KHR_texture_transform` in the loader (docs/materials.md §13):
//! transforms and `texCoord` overrides on every slot radcache samples (the normal texture's from
//! the JSON), per reference rather than per texture; TEXCOORD_1 kept only for the primitives
//! whose material samples it; sets above 1 and malformed transforms named in warnings; generated
//! tangents following the normal map's coordinates; the plan's flags and line; the content hash.

mod common;

use std::path::PathBuf;

use common::{load, temp_dir, warnings_of, write};
use glam::{Vec2, Vec4};
use radcache_scene::writer::{
    write_files, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc, TexCoordDesc,
};
use radcache_scene::{Scene, TextureTransform, WarningKind};
use serde_json::{json, Value};

/// The unit quad of the plane y = 0 facing +Y, TEXCOORD_0 = (x, z) and, when `set1`, TEXCOORD_1
/// = (1 − z, x / 2).
fn quad(material: usize, set1: bool) -> PrimitiveDesc {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ];
    PrimitiveDesc {
        texcoords: Some(positions.iter().map(|p| [p[0], p[2]]).collect()),
        texcoords1: set1.then(|| positions.iter().map(|p| [1.0 - p[2], p[0] / 2.0]).collect()),
        ..PrimitiveDesc::triangles(
            positions,
            Some(vec![[0.0, 1.0, 0.0]; 4]),
            vec![0, 1, 2, 0, 2, 3],
            Some(material),
        )
    }
}

/// One mesh per entry of `meshes` (each a list of primitives), a node each, and the scene.
fn scene_of(mut b: GltfBuilder, meshes: &[Vec<PrimitiveDesc>], tag: &str) -> GltfBuilder {
    let nodes: Vec<usize> = meshes
        .iter()
        .enumerate()
        .map(|(i, prims)| {
            let mesh = b.add_mesh(&format!("m{i}"), prims);
            b.add_node(&NodeDesc {
                mesh: Some(mesh),
                ..NodeDesc::default()
            })
        })
        .collect();
    b.add_scene(tag, &nodes, None);
    b
}

fn written(b: &GltfBuilder, tag: &str) -> PathBuf {
    write(b, &temp_dir(tag), tag)
}

fn edited(b: &GltfBuilder, tag: &str, f: impl FnOnce(&mut Value)) -> PathBuf {
    let dir = temp_dir(tag);
    let (mut root, bin) = b.to_json(Some("m.bin"));
    f(&mut root);
    let path = dir.join("m.gltf");
    write_files(&path, &root, Some(("m.bin", &bin))).unwrap();
    path
}

fn t(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> TextureTransform {
    TextureTransform {
        offset: Vec2::from(offset),
        rotation,
        scale: Vec2::from(scale),
    }
}

fn uv(tex_coord: u32, transform: Option<TextureTransform>, over: Option<u32>) -> TexCoordDesc {
    TexCoordDesc {
        tex_coord,
        transform,
        transform_tex_coord: over,
    }
}

#[test]
fn transforms_and_overrides_are_read_on_every_slot_per_reference() {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
    let (t_base, t_emit, t_normal) = (
        t([0.5, -0.25], 0.3, [2.0, 3.0]),
        t([0.0, 1.0], std::f32::consts::FRAC_PI_2, [0.5, 0.5]),
        t([0.1, 0.2], -1.0, [1.0, -1.0]),
    );
    let first = MaterialDesc {
        base_color_texture: Some(tex),
        // The transform's texCoord overrides the reference's.
        base_color_uv: uv(0, Some(t_base), Some(1)),
        metallic_roughness_texture: Some(tex),
        metallic_roughness_uv: uv(1, None, None),
        emissive: [1.0; 3],
        emissive_texture: Some(tex),
        emissive_uv: uv(1, Some(t_emit), Some(0)),
        normal_texture: Some((tex, 0.5)),
        normal_uv: uv(0, Some(t_normal), Some(1)),
        ..MaterialDesc::diffuse("first", [0.5; 3])
    };
    // The same texture, another transform.
    let second = MaterialDesc {
        base_color_texture: Some(tex),
        base_color_uv: uv(0, Some(t([0.0, 0.0], 0.0, [4.0, 4.0])), None),
        ..MaterialDesc::diffuse("second", [0.5; 3])
    };
    let (m0, m1) = (b.add_material(&first), b.add_material(&second));
    let b = scene_of(b, &[vec![quad(m0, true), quad(m1, false)]], "slots");
    let (scene, warnings) = load(&written(&b, "slots"));
    assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (0, 0));
    assert_eq!(
        warnings_of(&warnings, WarningKind::MaterialExtensionIgnored),
        (0, 0),
        "KHR_texture_transform is implemented: {warnings:?}"
    );
    assert!(scene.material_notes.unsupported_extensions.is_empty());
    assert_eq!(scene.textures.len(), 1, "one texture, four references");
    let m = &scene.materials[0];
    let base = m.base_color_texture.unwrap();
    assert_eq!(
        (base.texture, base.tex_coord, base.transform),
        (0, 1, t_base)
    );
    let mr = m.metallic_roughness_texture.unwrap();
    assert_eq!(
        (mr.tex_coord, mr.transform),
        (1, TextureTransform::IDENTITY)
    );
    let emit = m.emissive_texture.unwrap();
    assert_eq!((emit.tex_coord, emit.transform), (0, t_emit));
    // The gltf crate has no texture_transform() on normalTexture: read from the JSON.
    let normal = m.normal_texture.unwrap();
    assert_eq!((normal.tex_coord, normal.transform), (1, t_normal));
    assert_eq!(m.normal_scale, 0.5);
    assert!(m.uses_texcoord1() && m.has_uv_transform());
    let other = scene.materials[1].base_color_texture.unwrap();
    assert_eq!(other.texture, base.texture);
    assert_eq!(other.transform.scale, Vec2::splat(4.0));
    assert_eq!(other.tex_coord, 0);
    assert!(!scene.materials[1].uses_texcoord1());
}

#[test]
fn texcoord1_is_kept_only_where_a_material_samples_it() {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
    let set1 = b.add_material(&MaterialDesc {
        base_color_texture: Some(tex),
        base_color_uv: uv(1, None, None),
        ..MaterialDesc::diffuse("set1", [0.5; 3])
    });
    let set0 = b.add_material(&MaterialDesc {
        base_color_texture: Some(tex),
        ..MaterialDesc::diffuse("set0", [0.5; 3])
    });
    // Mesh 0: a set-1 primitive after a set-0 one (both have TEXCOORD_1); mesh 1: set 0 only.
    let b = scene_of(
        b,
        &[
            vec![quad(set0, true), quad(set1, true)],
            vec![quad(set0, true)],
        ],
        "kept",
    );
    let (scene, warnings) = load(&written(&b, "kept"));
    assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (0, 0));
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.texcoords1.len(), mesh.positions.len());
    assert_eq!(mesh.positions.len(), 8);
    // The set-0 primitive's vertices: zero (not read); the set-1 primitive's: the file's.
    assert!(mesh.texcoords1[..4].iter().all(|&t| t == Vec2::ZERO));
    let expected: Vec<Vec2> = mesh.positions[4..]
        .iter()
        .map(|p| Vec2::new(1.0 - p.z, p.x / 2.0))
        .collect();
    assert_eq!(&mesh.texcoords1[4..], &expected[..]);
    assert!(scene.meshes[1].texcoords1.is_empty());
    assert!(scene.plan().texcoord1);

    // The same files with every reference on set 0: no second set anywhere.
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
    let set0 = b.add_material(&MaterialDesc {
        base_color_texture: Some(tex),
        ..MaterialDesc::diffuse("set0", [0.5; 3])
    });
    let b = scene_of(b, &[vec![quad(set0, true)]], "unused");
    let (scene, _) = load(&written(&b, "unused"));
    assert!(scene.meshes[0].texcoords1.is_empty());
    assert!(!scene.plan().texcoord1);

    // A material sampling set 1 on a primitive without it: zeros, and a warning.
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
    let set1 = b.add_material(&MaterialDesc {
        emissive: [1.0; 3],
        emissive_texture: Some(tex),
        emissive_uv: uv(0, None, Some(1)),
        ..MaterialDesc::diffuse("set1", [0.5; 3])
    });
    let b = scene_of(b, &[vec![quad(set1, false)]], "missing");
    let (scene, warnings) = load(&written(&b, "missing"));
    assert_eq!(scene.meshes[0].texcoords1, vec![Vec2::ZERO; 4]);
    let w: Vec<&str> = warnings
        .iter()
        .filter(|w| w.kind == WarningKind::TextureIgnored)
        .map(|w| w.message.as_str())
        .collect();
    assert!(
        w.len() == 1 && w[0].contains("no TEXCOORD_1") && w[0].contains("missing.gltf"),
        "{w:?}"
    );
}

#[test]
fn sets_above_one_and_malformed_transforms_are_named() {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
    let m = b.add_material(&MaterialDesc {
        base_color_texture: Some(tex),
        base_color_uv: uv(2, None, None),
        emissive: [1.0; 3],
        emissive_texture: Some(tex),
        emissive_uv: uv(0, Some(t([0.0; 2], 0.0, [1e30, 1.0])), None),
        normal_texture: Some((tex, 1.0)),
        ..MaterialDesc::diffuse("bad", [0.5; 3])
    });
    let b = scene_of(b, &[vec![quad(m, false)]], "bad");
    let path = edited(&b, "bad", |r| {
        r["materials"][0]["normalTexture"]["extensions"] =
            json!({"KHR_texture_transform": {"offset": "far"}});
        // f32 overflow: infinite after the matrix's product.
        r["materials"][0]["emissiveTexture"]["extensions"]["KHR_texture_transform"]["scale"] =
            json!([1e39, 1.0]);
    });
    let (scene, warnings) = load(&path);
    let m = &scene.materials[0];
    assert!(m.base_color_texture.is_none(), "texCoord 2 is dropped");
    assert_eq!(
        m.emissive_texture.unwrap().transform,
        TextureTransform::IDENTITY
    );
    assert_eq!(
        m.normal_texture.unwrap().transform,
        TextureTransform::IDENTITY
    );
    let w: Vec<&str> = warnings
        .iter()
        .filter(|w| w.kind == WarningKind::TextureIgnored)
        .map(|w| w.message.as_str())
        .collect();
    assert_eq!(w.len(), 3, "{w:?}");
    assert!(w.iter().all(|m| m.contains("m.gltf")), "{w:?}");
    assert!(
        w.iter().any(|m| m.contains("texCoord 2 unsupported")),
        "{w:?}"
    );
    assert!(w.iter().any(|m| m.contains("non-finite")), "{w:?}");
    assert!(
        w.iter()
            .any(|m| m.contains("offset is not an array of two numbers")),
        "{w:?}"
    );
}

#[test]
fn a_file_requiring_the_extension_loads() {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
    let m = b.add_material(&MaterialDesc {
        base_color_texture: Some(tex),
        base_color_uv: uv(0, Some(t([0.5, 0.0], 0.0, [1.0, 1.0])), None),
        ..MaterialDesc::diffuse("req", [0.5; 3])
    });
    let b = scene_of(b, &[vec![quad(m, false)]], "req");
    let path = edited(&b, "req", |r| {
        r["extensionsRequired"] = json!(["KHR_texture_transform"]);
    });
    let (scene, _) = load(&path);
    let base = scene.materials[0].base_color_texture.unwrap();
    assert_eq!(base.transform.offset, Vec2::new(0.5, 0.0));
}

#[test]
fn generated_tangents_follow_the_coordinates_the_map_samples() {
    // The quad's TEXCOORD_0 is (x, z): tangent +x, w = +1 without a transform
    // (tests/normal_maps.rs). Turned by π/2, u' = v = z and v' = −u = −x: the tangent (along
    // increasing u') is +z, the bitangent (up the image: decreasing v', +x) is +y × +z = +x, w = +1.
    // Through TEXCOORD_1 = (1 − z, x/2): u' increases along −z, v' decreases along −x: the
    // bitangent −x is +y × −z, w = +1.
    let cases = [
        (
            uv(
                0,
                Some(t([0.3, 0.1], std::f32::consts::FRAC_PI_2, [1.0, 1.0])),
                None,
            ),
            Vec4::new(0.0, 0.0, 1.0, 1.0),
        ),
        (uv(1, None, None), Vec4::new(0.0, 0.0, -1.0, 1.0)),
    ];
    for (k, (normal_uv, expected)) in cases.into_iter().enumerate() {
        let mut b = GltfBuilder::new();
        let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
        let m = b.add_material(&MaterialDesc {
            normal_texture: Some((tex, 1.0)),
            normal_uv,
            ..MaterialDesc::diffuse("bumpy", [0.5; 3])
        });
        let tag = format!("tangents{k}");
        let b = scene_of(b, &[vec![quad(m, true)]], &tag);
        let (scene, warnings) = load(&written(&b, &tag));
        assert_eq!(warnings_of(&warnings, WarningKind::TextureIgnored), (0, 0));
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.tangents.len(), 4, "case {k}: no split");
        for &tangent in &mesh.tangents {
            assert!(
                (tangent - expected).abs().max_element() < 1e-5,
                "case {k}: {tangent} against {expected}"
            );
        }
    }
}

#[test]
fn the_plan_says_which_coordinates_the_shaders_need() {
    let build = |desc: TexCoordDesc, set1: bool, tag: &str| -> Scene {
        let mut b = GltfBuilder::new();
        let tex = b.add_texture_rgba8(2, 2, &[128; 16], 10497).unwrap();
        let m = b.add_material(&MaterialDesc {
            base_color_texture: Some(tex),
            base_color_uv: desc,
            ..MaterialDesc::diffuse("m", [0.5; 3])
        });
        let b = scene_of(b, &[vec![quad(m, set1)]], tag);
        load(&written(&b, tag)).0
    };
    let plain = build(uv(0, None, None), false, "plain");
    let plan = plain.plan();
    assert!(!plan.uv_transform && !plan.texcoord1);
    assert!(
        plan.to_string()
            .contains("texture coordinates: TEXCOORD_0, no transforms"),
        "{plan}"
    );
    // An explicit identity transform changes nothing, not even the content hash.
    let identity = build(
        uv(0, Some(TextureTransform::IDENTITY), None),
        false,
        "identity",
    );
    assert!(!identity.plan().uv_transform);
    assert_eq!(identity.content_hash(), plain.content_hash());

    let moved = build(
        uv(0, Some(t([0.25, 0.0], 0.0, [1.0, 1.0])), None),
        false,
        "moved",
    );
    assert!(moved.plan().uv_transform && !moved.plan().texcoord1);
    assert_ne!(moved.content_hash(), plain.content_hash(), "a transform");
    let turned = build(
        uv(0, Some(t([0.25, 0.0], 0.5, [1.0, 1.0])), None),
        false,
        "turned",
    );
    assert_ne!(turned.content_hash(), moved.content_hash(), "a rotation");

    let second = build(
        uv(1, Some(t([0.25, 0.0], 0.0, [1.0, 1.0])), None),
        true,
        "second",
    );
    let plan = second.plan();
    assert!(plan.uv_transform && plan.texcoord1);
    assert!(
        plan.to_string().contains(
            "texture coordinates: TEXCOORD_0 and TEXCOORD_1 (a second set per vertex), \
             KHR_texture_transform applied"
        ),
        "{plan}"
    );
    assert_ne!(second.content_hash(), moved.content_hash(), "the set");
    let mut edited = second.clone();
    edited.meshes[0].texcoords1[2].x += 0.5;
    assert_ne!(edited.content_hash(), second.content_hash(), "TEXCOORD_1");
}
