//! Each class of bad input gives its specific error (or warning), naming file and element.

mod common;

use std::path::{Path, PathBuf};

use common::{temp_dir, triangle_scene, warnings_of, write};
use radcache_scene::writer::{write_files, GltfBuilder, IndexFormat, NodeDesc};
use radcache_scene::{Error, LoadOptions, Scene, WarningKind};
use serde_json::{json, Value};

/// Writes the triangle scene, lets `f` edit its JSON, and returns the `.gltf` path.
fn mutated(tag: &str, f: impl FnOnce(&mut Value)) -> PathBuf {
    let dir = temp_dir(tag);
    let b = triangle_scene(None, |_| {});
    let (mut root, bin) = b.to_json(Some("t.bin"));
    f(&mut root);
    let path = dir.join("t.gltf");
    write_files(&path, &root, Some(("t.bin", &bin))).unwrap();
    path
}

fn load_err(path: &Path) -> Error {
    match Scene::load(path, &LoadOptions::default()) {
        Ok(_) => panic!("{} loaded but should fail", path.display()),
        Err(e) => e,
    }
}

#[track_caller]
fn assert_mentions(e: &Error, needles: &[&str]) {
    let text = e.to_string();
    for n in needles {
        assert!(text.contains(n), "error {text:?} lacks {n:?}");
    }
}

#[test]
fn missing_file() {
    let path = temp_dir("missing").join("nope.gltf");
    let e = load_err(&path);
    assert!(matches!(e, Error::Io { .. }), "{e:?}");
    assert_mentions(&e, &["nope.gltf"]);
}

#[test]
fn invalid_json() {
    let path = temp_dir("json").join("bad.gltf");
    std::fs::write(&path, "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [").unwrap();
    let e = load_err(&path);
    assert!(matches!(e, Error::Parse { .. }), "{e:?}");
    assert_mentions(&e, &["bad.gltf", "invalid glTF"]);
    // Valid JSON that fails schema validation (bad index).
    let path = mutated("schema", |r| r["scenes"][0]["nodes"] = json!([7]));
    assert!(matches!(load_err(&path), Error::Parse { .. }));
}

#[test]
fn missing_buffer_file() {
    let path = mutated("nobin", |_| {});
    std::fs::remove_file(path.with_file_name("t.bin")).unwrap();
    let e = load_err(&path);
    assert!(matches!(e, Error::MissingBuffer { .. }), "{e:?}");
    assert_mentions(&e, &["t.gltf", "buffer 0", "t.bin"]);
}

#[test]
fn short_buffer() {
    let path = mutated("short", |_| {});
    let bin = path.with_file_name("t.bin");
    let data = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &data[..data.len() / 2]).unwrap();
    let e = load_err(&path);
    assert!(matches!(e, Error::ShortBuffer { .. }), "{e:?}");
    assert_mentions(&e, &["buffer 0", "byteLength"]);
}

#[test]
fn accessor_out_of_range() {
    let path = mutated("acc", |r| r["accessors"][0]["count"] = json!(1000));
    let e = load_err(&path);
    assert!(matches!(e, Error::Accessor { .. }), "{e:?}");
    assert_mentions(
        &e,
        &["mesh 0 \"tri\" primitive 0 POSITION accessor 0", "exceed"],
    );
    let path = mutated("acc-offset", |r| r["accessors"][1]["byteOffset"] = json!(4));
    assert_mentions(&load_err(&path), &["NORMAL accessor 1"]);
    let path = mutated("view", |r| {
        r["bufferViews"][0]["byteLength"] = json!(100_000)
    });
    let e = load_err(&path);
    assert!(matches!(e, Error::Accessor { .. }), "{e:?}");
    assert_mentions(&e, &["buffer view 0", "exceeds buffer 0"]);
    let path = mutated("type", |r| r["accessors"][0]["type"] = json!("VEC2"));
    assert_mentions(
        &load_err(&path),
        &["POSITION accessor 0", "expected 3 components"],
    );
}

#[test]
fn index_out_of_range() {
    let b = triangle_scene(None, |p| p.indices = Some(vec![0, 1, 5]));
    let e = load_err(&write(&b, &temp_dir("idx"), "i"));
    assert!(
        matches!(
            e,
            Error::IndexOutOfRange {
                index: 5,
                vertex_count: 3,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&e, &["mesh 0 \"tri\" primitive 0 indices accessor"]);
}

#[test]
fn non_finite_positions() {
    for (tag, bad) in [("nan", f32::NAN), ("inf", f32::INFINITY)] {
        // POSITION is the first buffer view; vertex 1's z is at byte 20. (min/max stay valid.)
        let path = mutated(tag, |_| {});
        let bin_path = path.with_file_name("t.bin");
        let mut bin = std::fs::read(&bin_path).unwrap();
        bin[20..24].copy_from_slice(&bad.to_le_bytes());
        std::fs::write(&bin_path, bin).unwrap();
        let e = load_err(&path);
        assert!(matches!(e, Error::NonFinite { position: 1, .. }), "{e:?}");
        assert_mentions(&e, &["mesh 0 \"tri\" primitive 0 POSITION accessor 0"]);
    }
}

#[test]
fn degenerate_triangles_warn_with_count() {
    let b = triangle_scene(None, |p| {
        p.positions.push([2.0, 0.0, 0.0]);
        p.normals = None;
        // good, repeated index, collinear (0, 1, 3 on the x axis)
        p.indices = Some(vec![0, 1, 2, 0, 0, 1, 0, 1, 3]);
    });
    let (s, w) = common::load(&write(&b, &temp_dir("degen"), "d"));
    assert_eq!(warnings_of(&w, WarningKind::DegenerateTriangles), (1, 2));
    assert!(w.iter().any(|w| w.message.contains("dropped 2 degenerate")
        && w.message.contains("mesh 0 \"tri\" primitive 0")));
    assert_eq!(s.triangle_count(), 1);
}

#[test]
fn unsupported_required_extension() {
    let path = mutated("ext", |r| {
        r["extensionsUsed"] = json!(["EXT_made_up"]);
        r["extensionsRequired"] = json!(["EXT_made_up"]);
    });
    let e = load_err(&path);
    assert!(
        matches!(&e, Error::UnsupportedExtension { name, .. } if name == "EXT_made_up"),
        "{e:?}"
    );
    // Supported required extensions are fine.
    let path = mutated("ext-ok", |r| {
        r["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        r["extensionsRequired"] = json!(["KHR_lights_punctual"]);
    });
    assert!(Scene::load(&path, &LoadOptions::default()).is_ok());
}

#[test]
fn orthographic_camera() {
    let mut b = GltfBuilder::new();
    let cam = b.add_orthographic_camera("ortho", 1.0, 1.0);
    let node = b.add_node(&NodeDesc {
        camera: Some(cam),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    let e = load_err(&write(&b, &temp_dir("ortho"), "o"));
    assert!(matches!(e, Error::OrthographicCamera { .. }), "{e:?}");
    assert_mentions(
        &e,
        &[
            "orthographic cameras are not supported yet",
            "camera 0 \"ortho\"",
        ],
    );
}

#[test]
fn unknown_camera_name_lists_the_available_ones() {
    let path = mutated("camname", |_| {});
    let opts = LoadOptions {
        camera_name: Some("nope".into()),
        ..LoadOptions::default()
    };
    let e = Scene::load(&path, &opts).unwrap_err();
    assert!(
        matches!(&e, Error::CameraNotFound { available, .. } if available == &["cam".to_string()]),
        "{e:?}"
    );
    assert_mentions(&e, &["\"nope\"", "\"cam\""]);
}

#[test]
fn hierarchy_errors() {
    let path = mutated("twoparents", |r| {
        r["nodes"][1]["children"] = json!([0]);
        r["nodes"]
            .as_array_mut()
            .unwrap()
            .push(json!({"children": [0]}));
    });
    assert_mentions(&load_err(&path), &["node 0 \"tri\"", "two parents"]);
    let path = mutated("selfchild", |r| r["nodes"][0]["children"] = json!([0]));
    assert_mentions(&load_err(&path), &["node 0 \"tri\"", "its own child"]);
    let path = mutated("rootchild", |r| r["nodes"][1]["children"] = json!([0]));
    assert_mentions(&load_err(&path), &["scene root but also a child"]);
}

#[test]
fn bad_animation_data() {
    let dir = temp_dir("anim-bad");
    let mut b = triangle_scene(None, |_| {});
    b.add_animation(
        "a",
        &[radcache_scene::writer::ChannelDesc {
            node: 0,
            property: radcache_scene::Property::Translation,
            interpolation: radcache_scene::Interpolation::Linear,
            times: vec![0.0, 1.0, 1.0],
            values: vec![0.0; 9],
        }],
    );
    let e = load_err(&write(&b, &dir, "a"));
    assert_mentions(
        &e,
        &[
            "animation 0 \"a\" channel 0 sampler 0 input",
            "strictly increasing",
        ],
    );
    let (mut root, bin) = b.to_json(Some("a.bin"));
    root["animations"][0]["samplers"][0]["interpolation"] = json!("CUBICSPLINE");
    let path = dir.join("c.gltf");
    write_files(&path, &root, Some(("a.bin", &bin))).unwrap();
    assert!(matches!(load_err(&path), Error::Invalid { .. }));
}

#[test]
fn index_formats_and_non_indexed_primitives_load() {
    for format in [IndexFormat::U8, IndexFormat::U16, IndexFormat::U32] {
        let b = triangle_scene(None, |p| p.index_format = format);
        let (s, _) = common::load(&write(&b, &temp_dir("fmt"), "f"));
        assert_eq!(s.meshes[0].indices, vec![0, 1, 2]);
    }
    let b = triangle_scene(None, |p| p.indices = None);
    let (s, _) = common::load(&write(&b, &temp_dir("noidx"), "f"));
    assert_eq!(s.triangle_count(), 1);
}

#[test]
fn malformed_glb_headers() {
    let b = triangle_scene(None, |_| {});
    let (root, bin) = b.to_json(None);
    let good = common::glb_bytes(&root, &bin);
    let dir = temp_dir("glb");
    let path = dir.join("g.glb");
    std::fs::write(&path, &good).unwrap();
    assert!(Scene::load(&path, &LoadOptions::default()).is_ok());
    // Declared total length below the 12-byte header, beyond the file, and a truncated header.
    for (tag, bytes) in [
        (
            "tiny length",
            [&good[..8], &4u32.to_le_bytes(), &good[12..]].concat(),
        ),
        (
            "long length",
            [&good[..8], &u32::MAX.to_le_bytes(), &good[12..]].concat(),
        ),
        ("truncated", good[..10].to_vec()),
        ("short JSON chunk", good[..40].to_vec()),
    ] {
        std::fs::write(&path, bytes).unwrap();
        let e = load_err(&path);
        assert!(matches!(e, Error::Parse { .. }), "{tag}: {e:?}");
        assert_mentions(&e, &["g.glb", "invalid glTF"]);
    }
}

#[test]
fn invalid_punctual_lights() {
    let light = |kind: &str, extra: Value| {
        let mut l = json!({"type": kind, "intensity": 1.0});
        for (k, v) in extra.as_object().unwrap() {
            l[k] = v.clone();
        }
        l
    };
    let cases = [
        (
            light("point", json!({"intensity": -2.0})),
            "intensity -2 must be finite and non-negative",
        ),
        (light("point", json!({"color": [1.0, -0.5, 0.0]})), "colour"),
        (
            light(
                "spot",
                json!({"spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.3}}),
            ),
            "spot cone angles",
        ),
        (
            light("spot", json!({"spot": {"outerConeAngle": 2.0}})),
            "spot cone angles",
        ),
    ];
    for (i, (l, needle)) in cases.into_iter().enumerate() {
        let path = mutated(&format!("light{i}"), |r| {
            r["extensionsUsed"] = json!(["KHR_lights_punctual"]);
            r["extensions"] = json!({"KHR_lights_punctual": {"lights": [{"type": "point"}, l]}});
            r["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 1}});
        });
        let e = load_err(&path);
        assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
        assert_mentions(&e, &["t.gltf", "KHR_lights_punctual light 1", needle]);
    }
}

/// The full error chain, cause by cause, as anyhow's `{:#}` prints it.
fn chain(e: &dyn std::error::Error) -> String {
    let mut parts = vec![e.to_string()];
    let mut cause = e.source();
    while let Some(c) = cause {
        parts.push(c.to_string());
        cause = c.source();
    }
    parts.join(": ")
}

#[test]
fn error_chains_name_each_cause_once() {
    let path = temp_dir("chain").join("nope.gltf");
    let os = std::fs::read(&path).unwrap_err().to_string();
    let text = chain(&load_err(&path));
    assert_eq!(text.matches(&os).count(), 1, "{text}");
    assert!(text.contains("nope.gltf: cannot read glTF file"), "{text}");

    let b = triangle_scene(None, |_| {});
    let path = temp_dir("chain-write").join("no/such/dir/w.gltf");
    let e = b.write(&path, radcache_scene::writer::BufferLayout::External);
    let text = chain(&e.unwrap_err());
    assert_eq!(text.matches(&os).count(), 1, "{text}");
    assert!(text.contains("w.gltf: cannot write"), "{text}");
}

/// The triangle scene with a material whose base colour texture is the image `uri`.
fn textured(tag: &str, uri: &str) -> PathBuf {
    mutated(tag, |r| {
        r["images"] = json!([{"uri": uri, "name": "albedo"}]);
        r["textures"] = json!([{"source": 0}]);
        r["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        r["meshes"][0]["primitives"][0]["material"] = json!(0);
    })
}

#[test]
fn missing_and_corrupt_image_files_are_named() {
    let path = textured("noimage", "tex/missing%20file.png");
    let e = load_err(&path);
    assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
    let file = path.with_file_name("tex/missing file.png");
    assert_mentions(
        &e,
        &[
            "t.gltf",
            "image 0 \"albedo\"",
            "cannot read image file",
            &file.display().to_string(),
        ],
    );

    let path = textured("badimage", "bad.png");
    let file = path.with_file_name("bad.png");
    std::fs::write(&file, b"\x89PNG\r\n\x1a\nthis is no PNG data").unwrap();
    let e = load_err(&path);
    assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
    assert_mentions(
        &e,
        &[
            "image 0 \"albedo\"",
            "cannot decode image file",
            &file.display().to_string(),
        ],
    );
}

#[test]
fn negative_emissive_strength_warns() {
    let path = mutated("negstrength", |r| {
        r["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
        r["materials"] = json!([{
            "name": "lamp",
            "emissiveFactor": [1.0, 1.0, 1.0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": -2.0}},
        }]);
        r["meshes"][0]["primitives"][0]["material"] = json!(0);
    });
    let (s, w) = common::load(&path);
    assert!(!s.materials[0].is_emissive());
    let hits: Vec<_> = w
        .iter()
        .filter(|w| {
            w.message.contains("material 0 \"lamp\"") && w.message.contains("emissiveStrength -2")
        })
        .collect();
    assert_eq!(hits.len(), 1, "{w:?}");
    assert_eq!(hits[0].kind, WarningKind::Other);
}

#[test]
fn gltf_versions_other_than_2_are_refused() {
    fn set(version: Value, min: Option<&'static str>) -> impl FnOnce(&mut Value) {
        move |r: &mut Value| {
            r["asset"]["version"] = version;
            if let Some(min) = min {
                r["asset"]["minVersion"] = json!(min);
            }
        }
    }
    for (tag, version, min, field, value) in [
        ("v3", json!("3.0"), None, "version", "\"3.0\""),
        ("v1", json!("1.0"), None, "version", "\"1.0\""),
        ("v2bare", json!("2"), None, "version", "\"2\""),
        ("v2x", json!("2.x"), None, "version", "\"2.x\""),
        ("min21", json!("2.1"), Some("2.1"), "minVersion", "\"2.1\""),
        ("min3", json!("2.0"), Some("3.0"), "minVersion", "\"3.0\""),
    ] {
        let e = load_err(&mutated(tag, set(version, min)));
        assert!(
            matches!(&e, Error::UnsupportedVersion { field: f, .. } if *f == field),
            "{tag}: {e:?}"
        );
        assert_mentions(&e, &["t.gltf", "unsupported glTF version", field, value]);
    }
    // Later 2.x versions load, and so does minVersion 2.0.
    for (tag, version, min) in [("v21", "2.1", None), ("min20", "2.1", Some("2.0"))] {
        let path = mutated(tag, set(json!(version), min));
        assert!(Scene::load(&path, &LoadOptions::default()).is_ok(), "{tag}");
    }
}
