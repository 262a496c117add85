//! `EXT_mesh_gpu_instancing` (forests, crowds, kitbashed cities): a node whose mesh is drawn once
//! per element of its TRANSLATION / ROTATION / SCALE attributes, each instance's transform under
//! the node's own. Rotations may be normalized integers (with `KHR_mesh_quantization`).

mod common;

use std::path::{Path, PathBuf};

use common::{load, temp_dir};
use glam::{Mat4, Quat, Vec3};
use radcache_scene::math::Aabb;
use radcache_scene::{Error, LoadOptions, Scene};
use serde_json::{json, Value};

const TRANSLATIONS: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [4.0, 1.0, 0.0]];
const SCALES: [[f32; 3]; 3] = [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [0.5, 1.0, 0.5]];

/// Instance `i`'s rotation: `i` quarter turns about +Y.
fn rotation(i: usize) -> Quat {
    Quat::from_rotation_y(i as f32 * std::f32::consts::FRAC_PI_2)
}

/// One triangle placed by a node at (0, 0, 5) with `EXT_mesh_gpu_instancing`: translations and
/// scales as floats, rotations as normalized `i16` (`scales` instances of the scales).
fn write_file(dir: &Path, scales: usize) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        bin.extend(p.iter().flat_map(|c| c.to_le_bytes()));
    }
    for t in TRANSLATIONS {
        bin.extend(t.iter().flat_map(|c| c.to_le_bytes()));
    }
    for s in &SCALES[..scales] {
        bin.extend(s.iter().flat_map(|c| c.to_le_bytes()));
    }
    let rotations = bin.len();
    for i in 0..3 {
        let q = rotation(i).to_array();
        bin.extend(
            q.iter()
                .flat_map(|c| ((c * 32767.0).round() as i16).to_le_bytes()),
        );
    }
    let scale_bytes = 12 * scales;
    let root: Value = json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": ["EXT_mesh_gpu_instancing", "KHR_mesh_quantization"],
        "extensionsRequired": ["EXT_mesh_gpu_instancing", "KHR_mesh_quantization"],
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{
            "name": "forest",
            "mesh": 0,
            "translation": [0.0, 0.0, 5.0],
            "extensions": { "EXT_mesh_gpu_instancing": { "attributes": {
                "TRANSLATION": 1, "SCALE": 2, "ROTATION": 3,
            } } },
        }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
        "buffers": [{ "uri": "forest.bin", "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 36 },
            { "buffer": 0, "byteOffset": 36, "byteLength": 36 },
            { "buffer": 0, "byteOffset": 72, "byteLength": scale_bytes },
            { "buffer": 0, "byteOffset": rotations, "byteLength": 24 },
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0] },
            { "bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3" },
            { "bufferView": 2, "componentType": 5126, "count": scales, "type": "VEC3" },
            { "bufferView": 3, "componentType": 5122, "normalized": true, "count": 3,
              "type": "VEC4" },
        ],
    });
    std::fs::write(dir.join("forest.bin"), &bin).unwrap();
    let path = dir.join("forest.gltf");
    std::fs::write(&path, serde_json::to_string_pretty(&root).unwrap()).unwrap();
    path
}

#[test]
fn each_instance_is_placed_under_its_node() {
    let dir = temp_dir("instancing");
    let (scene, _) = load(&write_file(&dir, 3));
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.instances.len(), 3);
    assert!(scene.instances.iter().all(|i| i.mesh == 0 && i.node == 0));
    let node = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0));
    for (i, m) in scene.instance_transforms(0.0).iter().enumerate() {
        let expected = node
            * Mat4::from_scale_rotation_translation(
                Vec3::from(SCALES[i]),
                rotation(i),
                Vec3::from(TRANSLATIONS[i]),
            );
        // The rotations are 16-bit: within 1e-4.
        assert!(
            m.abs_diff_eq(expected, 1e-4),
            "instance {i}: {m} expected {expected}"
        );
    }
    // The scene's bounds cover every instance (the third at x = 4, y = 1 .. 2).
    let b = scene.bounds_at(0.0);
    assert!(b.max.x >= 4.0 && b.max.y >= 1.5 - 1e-4, "{b:?}");
}

#[test]
fn instance_attributes_of_different_lengths_are_refused_naming_the_node() {
    let dir = temp_dir("instancing-short");
    let path = write_file(&dir, 2);
    let e = match Scene::load(&path, &LoadOptions::default()) {
        Ok(_) => panic!("a node with 3 translations and 2 scales loaded"),
        Err(e) => e,
    };
    assert!(matches!(&e, Error::Invalid { .. }), "{e:?}");
    let text = e.to_string();
    assert!(
        text.starts_with(&format!("{}: ", path.display()))
            && text.contains("node 0 \"forest\"")
            && text.contains("EXT_mesh_gpu_instancing")
            && text.contains("SCALE has 2 elements but TRANSLATION has 3"),
        "{text}"
    );
}

/// The bundled Cornell box with six more copies of its short block (nodes sharing mesh 3, each
/// turned about +Y, scaled and moved), written to `dir`.
fn cornell_with_copies(dir: &Path) -> PathBuf {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/cornell");
    let text = std::fs::read_to_string(assets.join("cornell.gltf")).unwrap();
    let mut root: Value = serde_json::from_str(&text).unwrap();
    for k in 0..6 {
        let a = k as f32 * 0.5;
        let node = json!({
            "mesh": 3,
            "name": format!("copy{k}"),
            "translation": [-0.20 + 0.07 * k as f32, 0.33 + 0.012 * k as f32, 0.05 * k as f32 - 0.1],
            "rotation": [0.0, (a / 2.0).sin(), 0.0, (a / 2.0).cos()],
            "scale": [0.25, 0.25 + 0.05 * k as f32, 0.25],
        });
        let nodes = root["nodes"].as_array_mut().unwrap();
        nodes.push(node);
        let index = nodes.len() - 1;
        root["scenes"][0]["nodes"]
            .as_array_mut()
            .unwrap()
            .push(index.into());
    }
    std::fs::copy(assets.join("cornell.bin"), dir.join("cornell.bin")).unwrap();
    let path = dir.join("copies.gltf");
    std::fs::write(&path, serde_json::to_string(&root).unwrap()).unwrap();
    path
}

/// The world-space bounds of each instance of `mesh` in `scene`, ordered by their centres' x.
fn placed_bounds(scene: &Scene, mesh: usize) -> Vec<Aabb> {
    let transforms = scene.instance_transforms(0.0);
    let mut boxes: Vec<Aabb> = scene
        .instances
        .iter()
        .zip(&transforms)
        .filter(|(i, _)| i.mesh == mesh)
        .map(|(_, m)| {
            let mut b = Aabb::EMPTY;
            for p in &scene.meshes[mesh].positions {
                b.extend(m.transform_point3(*p));
            }
            b
        })
        .collect();
    boxes.sort_by(|a, b| a.center().x.total_cmp(&b.center().x));
    boxes
}

/// `gltfpack -i copies.gltf -o cornell-instanced-cc.glb -mi -cc` (gltfpack 1.3) turned the seven
/// short blocks into one mesh placed by `EXT_mesh_gpu_instancing`, its TRANSLATION and SCALE
/// compressed with the exponential filter and its ROTATION with the quaternion filter, and
/// merged the rest of the room: each block lands where the plain file's node puts it.
#[test]
fn gltfpack_instancing_places_each_copy_where_its_node_did() {
    let dir = temp_dir("instancing-cornell");
    let (plain, _) = load(&cornell_with_copies(&dir));
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/cornell-instanced-cc.glb");
    let (packed, _) = load(&path);
    let block = plain
        .meshes
        .iter()
        .position(|m| m.name.as_deref() == Some("short_block"));
    let expected = placed_bounds(&plain, block.expect("the Cornell box has a short block"));
    assert_eq!(expected.len(), 7);
    // The instanced mesh is the one placed seven times.
    let instanced = (0..packed.meshes.len())
        .find(|&m| packed.instances.iter().filter(|i| i.mesh == m).count() == 7)
        .expect("one mesh placed seven times");
    let nodes: Vec<usize> = packed
        .instances
        .iter()
        .filter(|i| i.mesh == instanced)
        .map(|i| i.node)
        .collect();
    assert!(nodes.iter().all(|&n| n == nodes[0]), "one node places them");
    let got = placed_bounds(&packed, instanced);
    for (k, (a, b)) in expected.iter().zip(&got).enumerate() {
        // 14-bit positions over the block, 16-bit mantissas, 12-bit quaternions: within 2 mm.
        assert!(
            a.min.distance(b.min) < 2e-3 && a.max.distance(b.max) < 2e-3,
            "copy {k}: {a:?} against {b:?}"
        );
    }
}
