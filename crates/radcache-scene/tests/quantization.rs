//! `KHR_mesh_quantization`, which gltfpack and gltf-transform write by default: integer
//! attributes (normalized or not), dequantized by the node's transform. A quad stored once in
//! floats and once quantized as gltfpack does (POSITION as plain `u16` with the dequantizing
//! scale and offset on the node, NORMAL as normalized `i8` padded to 4 bytes, TEXCOORD_0 as
//! normalized `u16`) loads to the same world-space points, normals and texture coordinates,
//! within the quantization's step.

mod common;

use std::path::{Path, PathBuf};

use common::{load, temp_dir};
use glam::{Vec2, Vec3};
use radcache_scene::Scene;
use serde_json::{json, Value};

const POSITIONS: [[f32; 3]; 4] = [
    [-1.0, 0.0, -1.0],
    [1.0, 0.25, -1.0],
    [1.0, 0.0, 1.0],
    [-1.0, -0.5, 1.0],
];
const NORMALS: [[f32; 3]; 4] = [
    [0.0, 1.0, 0.0],
    [0.6, 0.8, 0.0],
    [0.0, 0.8, 0.6],
    [-0.48, 0.8, 0.36],
];
const UVS: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [0.75, 1.0], [0.125, 0.5]];
const INDICES: [u16; 6] = [0, 1, 2, 0, 2, 3];
/// Quantized positions are `(p + 1) · STEPS`: the node maps them back with scale `1 / STEPS`
/// and translation −1.
const STEPS: f32 = 1000.0;

/// A glTF file `name.gltf` with `name.bin` in `dir`: one mesh of one primitive whose
/// accessors are `accessors` (POSITION, NORMAL, TEXCOORD_0, indices) over `views`, on a node
/// with `node`'s transform.
fn write_file(
    dir: &Path,
    name: &str,
    bin: &[u8],
    views: Value,
    accessors: Value,
    node: Value,
    required: &[&str],
) -> PathBuf {
    let root = json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": required,
        "extensionsRequired": required,
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [node],
        "meshes": [{ "primitives": [{
            "attributes": { "POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2 },
            "indices": 3,
        }] }],
        "buffers": [{ "uri": format!("{name}.bin"), "byteLength": bin.len() }],
        "bufferViews": views,
        "accessors": accessors,
    });
    std::fs::write(dir.join(format!("{name}.bin")), bin).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_string_pretty(&root).unwrap()).unwrap();
    path
}

fn push_indices(bin: &mut Vec<u8>) {
    for i in INDICES {
        bin.extend(i.to_le_bytes());
    }
}

/// The quad in floats.
fn float_file(dir: &Path) -> PathBuf {
    let mut bin = Vec::new();
    for v in POSITIONS.iter().chain(&NORMALS) {
        bin.extend(v.iter().flat_map(|c| c.to_le_bytes()));
    }
    for v in UVS {
        bin.extend(v.iter().flat_map(|c| c.to_le_bytes()));
    }
    push_indices(&mut bin);
    let views = json!([
        { "buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962 },
        { "buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962 },
        { "buffer": 0, "byteOffset": 96, "byteLength": 32, "target": 34962 },
        { "buffer": 0, "byteOffset": 128, "byteLength": 12, "target": 34963 },
    ]);
    let accessors = json!([
        { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
          "min": [-1.0, -0.5, -1.0], "max": [1.0, 0.25, 1.0] },
        { "bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3" },
        { "bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2" },
        { "bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR" },
    ]);
    write_file(
        dir,
        "float",
        &bin,
        views,
        accessors,
        json!({ "mesh": 0 }),
        &[],
    )
}

/// The quad quantized as gltfpack writes it.
fn quantized_file(dir: &Path) -> PathBuf {
    let mut bin = Vec::new();
    // POSITION: plain u16 VEC3, each element padded to 8 bytes (the 4-byte stride rule).
    let mut lo = [u16::MAX; 3];
    let mut hi = [0u16; 3];
    for p in POSITIONS {
        for (c, v) in p.iter().enumerate() {
            let q = ((v + 1.0) * STEPS).round() as u16;
            lo[c] = lo[c].min(q);
            hi[c] = hi[c].max(q);
            bin.extend(q.to_le_bytes());
        }
        bin.extend([0, 0]);
    }
    // NORMAL: normalized i8 VEC3, padded to 4 bytes.
    for n in NORMALS {
        bin.extend(n.iter().map(|c| ((c * 127.0).round() as i8) as u8));
        bin.push(0);
    }
    // TEXCOORD_0: normalized u16 VEC2.
    for uv in UVS {
        for c in uv {
            bin.extend(((c * 65535.0).round() as u16).to_le_bytes());
        }
    }
    push_indices(&mut bin);
    let views = json!([
        { "buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8, "target": 34962 },
        { "buffer": 0, "byteOffset": 32, "byteLength": 16, "byteStride": 4, "target": 34962 },
        { "buffer": 0, "byteOffset": 48, "byteLength": 16, "target": 34962 },
        { "buffer": 0, "byteOffset": 64, "byteLength": 12, "target": 34963 },
    ]);
    let accessors = json!([
        { "bufferView": 0, "componentType": 5123, "count": 4, "type": "VEC3",
          "min": lo, "max": hi },
        { "bufferView": 1, "componentType": 5120, "normalized": true, "count": 4, "type": "VEC3" },
        { "bufferView": 2, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2" },
        { "bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR" },
    ]);
    let s = 1.0 / STEPS;
    let node = json!({ "mesh": 0, "translation": [-1.0, -1.0, -1.0], "scale": [s, s, s] });
    write_file(
        dir,
        "quantized",
        &bin,
        views,
        accessors,
        node,
        &["KHR_mesh_quantization"],
    )
}

/// Each triangle corner's world-space point, unit normal and texture coordinate.
fn corners(scene: &Scene) -> Vec<(Vec3, Vec3, Vec2)> {
    assert_eq!(scene.instances.len(), 1);
    let m = scene.instance_transforms(0.0)[0];
    let mesh = &scene.meshes[scene.instances[0].mesh];
    mesh.indices
        .iter()
        .map(|&i| {
            let i = i as usize;
            let n = m.transform_vector3(mesh.normals[i]).normalize();
            (m.transform_point3(mesh.positions[i]), n, mesh.texcoords[i])
        })
        .collect()
}

#[test]
fn quantized_attributes_load_as_their_floats() {
    let dir = temp_dir("quantization");
    let (float, float_warnings) = load(&float_file(&dir));
    let (quantized, warnings) = load(&quantized_file(&dir));
    assert_eq!(warnings.len(), float_warnings.len(), "{warnings:?}");
    let (a, b) = (corners(&float), corners(&quantized));
    assert_eq!(a.len(), 6);
    assert_eq!(a.len(), b.len());
    for (k, ((pa, na, ta), (pb, nb, tb))) in a.iter().zip(&b).enumerate() {
        // Half a quantization step each: 0.5 / STEPS, 1/127 of a unit vector, 0.5 / 65535.
        assert!(
            (*pa - *pb).abs().max_element() <= 0.5 / STEPS + 1e-6,
            "corner {k}: {pa} {pb}"
        );
        assert!(
            na.dot(*nb) > (1.0f32 / 127.0).cos(),
            "corner {k}: {na} {nb}"
        );
        assert!(
            (*ta - *tb).abs().max_element() <= 1e-5,
            "corner {k}: {ta} {tb}"
        );
    }
    // The scene's bounds are the dequantized ones.
    let (ba, bb) = (float.bounds_at(0.0), quantized.bounds_at(0.0));
    assert!(
        (ba.min - bb.min).abs().max_element() <= 1e-3,
        "{ba:?} {bb:?}"
    );
    assert!(
        (ba.max - bb.max).abs().max_element() <= 1e-3,
        "{ba:?} {bb:?}"
    );
}
