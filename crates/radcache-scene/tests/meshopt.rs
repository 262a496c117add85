//! `EXT_meshopt_compression`, as gltfpack 1.3 writes it, on the bundled animated scene (three
//! meshes, six materials, an animated node) and metal spheres scene: the files in `tests/data/` were made with
//!
//! ```text
//! gltfpack -i assets/animated/animated.gltf -o animated.glb       # quantized, not compressed
//! gltfpack -i assets/animated/animated.gltf -o animated-c.glb -c  # ATTRIBUTES + TRIANGLES
//! gltfpack -i assets/animated/animated.gltf -o animated-cc.glb -cc  # + OCTAHEDRAL normals,
//!                                       # EXPONENTIAL translations / scales, QUATERNION rotations
//! gltfpack -i assets/animated/animated.gltf -o animated-cf.glb -cf  # tagged fallback with a URI
//! gltfpack -i assets/metal_spheres/metal_spheres.gltf -o metal_spheres.glb     # 8k triangles,
//! gltfpack -i assets/metal_spheres/metal_spheres.gltf -o metal_spheres-c.glb -c  # every code
//! ```
//!
//! (`animated-cf.fallback.bin` is left out: a loader that decodes skips a tagged fallback.) The
//! codecs without filters are lossless, so `-c` and `-cf` must load to exactly the scene of the
//! uncompressed file; the filters re-quantize, so `-cc` must load within their steps.

mod common;

use std::path::{Path, PathBuf};

use common::{load, temp_dir};
use radcache_scene::{Error, LoadOptions, Scene};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// `path` loaded, with the file name cleared so that scenes from different files compare.
fn scene(name: &str) -> Scene {
    let (mut s, _) = load(&data(name));
    s.path = PathBuf::new();
    s
}

/// `scene` with each triangle's indices rotated to start at the smallest: the triangle codec may
/// store a triangle from another of its vertices (the winding kept), gltfpack's encoder does.
fn rotations_undone(mut scene: Scene) -> Scene {
    for mesh in &mut scene.meshes {
        for t in mesh.indices.chunks_exact_mut(3) {
            let first = (0..3).min_by_key(|&i| t[i]).unwrap();
            t.rotate_left(first);
        }
    }
    scene
}

#[test]
fn lossless_compression_loads_to_the_uncompressed_scene() {
    for (plain, packed) in [
        ("animated.glb", "animated-c.glb"),
        ("animated.glb", "animated-cf.glb"),
        ("metal_spheres.glb", "metal_spheres-c.glb"),
    ] {
        let a = rotations_undone(scene(plain));
        let b = rotations_undone(scene(packed));
        assert!(a.meshes.iter().map(|m| m.triangle_count()).sum::<usize>() >= 24);
        assert!(a == b, "{packed} loads to another scene than {plain}");
    }
}

#[test]
fn filtered_compression_loads_within_the_filters_steps() {
    let plain = scene("animated.glb");
    let packed = scene("animated-cc.glb");
    assert_eq!(packed.meshes.len(), plain.meshes.len());
    for (m, (a, b)) in plain.meshes.iter().zip(&packed.meshes).enumerate() {
        // Positions and indices are not filtered: exact.
        assert_eq!(a.positions, b.positions, "mesh {m}");
        assert_eq!(a.indices, b.indices, "mesh {m}");
        // Normals: 8-bit components against 8-bit octahedral coordinates.
        assert_eq!(a.normals.len(), b.normals.len());
        for (v, (na, nb)) in a.normals.iter().zip(&b.normals).enumerate() {
            assert!(
                na.distance(*nb) < 0.02 && (nb.length() - 1.0).abs() < 0.01,
                "mesh {m} vertex {v}: normal {na} against {nb}"
            );
        }
    }
    // The animation: 16-bit mantissas for translations and scales, 12-bit quaternions.
    let (t0, t1) = plain.time_range().expect("the scene is animated");
    assert!(t1 > t0);
    for k in 0..=8 {
        let t = t0 + (t1 - t0) * k as f32 / 8.0;
        let a = plain.instance_transforms(t);
        let b = packed.instance_transforms(t);
        for (i, (ma, mb)) in a.iter().zip(&b).enumerate() {
            assert!(
                ma.abs_diff_eq(*mb, 2e-3),
                "instance {i} at t = {t}: {ma} against {mb}"
            );
        }
    }
}

/// A copy of `animated-c.glb` in a fresh directory with its JSON chunk edited by `f` (the JSON
/// is padded back to a multiple of 4 bytes; the BIN chunk is kept).
fn edited(f: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let bytes = std::fs::read(data("animated-c.glb")).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut root: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    f(&mut root);
    let mut json = serde_json::to_vec(&root).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin = &bytes[20 + json_len..];
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend(bin);
    let path = temp_dir("meshopt").join("edited.glb");
    std::fs::write(&path, out).unwrap();
    path
}

/// The error of loading `path`, as text, after checking it is `Error::Invalid` naming the file.
fn refusal(path: &Path) -> String {
    let e = match Scene::load(path, &LoadOptions::default()) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => e,
    };
    assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
    let text = e.to_string();
    assert!(text.starts_with(&format!("{}: ", path.display())), "{text}");
    text
}

#[test]
fn damaged_compressed_views_are_refused_naming_the_view() {
    // The first compressed view's bytes cut short by one: its tail is no longer where it was.
    let path = edited(|root| {
        let ext = &mut root["bufferViews"][0]["extensions"]["EXT_meshopt_compression"];
        let len = ext["byteLength"].as_u64().unwrap();
        ext["byteLength"] = (len - 1).into();
    });
    let text = refusal(&path);
    assert!(
        text.contains("buffer view 0") && text.contains("EXT_meshopt_compression"),
        "{text}"
    );
    // A count that does not match the view's length.
    let path = edited(|root| {
        let ext = &mut root["bufferViews"][0]["extensions"]["EXT_meshopt_compression"];
        let count = ext["count"].as_u64().unwrap();
        ext["count"] = (count + 1).into();
    });
    let text = refusal(&path);
    assert!(
        text.contains("buffer view 0") && text.contains("is not the view's byteLength"),
        "{text}"
    );
    // An unknown mode.
    let path = edited(|root| {
        root["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["mode"] = "STRIPS".into();
    });
    let text = refusal(&path);
    assert!(
        text.contains("buffer view 1") && text.contains("mode \"STRIPS\""),
        "{text}"
    );
}

#[test]
fn the_khr_version_is_refused_by_name() {
    let path = edited(|root| {
        root["extensionsRequired"]
            .as_array_mut()
            .unwrap()
            .push("KHR_meshopt_compression".into());
    });
    let e = match Scene::load(&path, &LoadOptions::default()) {
        Ok(_) => panic!("a file requiring KHR_meshopt_compression loaded"),
        Err(e) => e,
    };
    let text = e.to_string();
    assert!(
        text.contains("KHR_meshopt_compression") && text.contains("vertex codec 1"),
        "{text}"
    );
}
