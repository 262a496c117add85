//! Loader features and fallbacks: buffer layouts (external, data URI, GLB), skipped primitive
//! modes, generated normals, default material, alpha modes and cutoffs, textures, camera
//! selection, default camera, environment sources, ignored weights channels.

mod common;

use common::{close, close3, load, temp_dir, triangle_scene, warnings_of, write};
use glam::{Vec3, Vec4};
use radcache_scene::writer::{
    write_files, BufferLayout, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc,
};
use radcache_scene::{
    AlphaMode, EnvOverride, Environment, EnvironmentKind, LoadOptions, Scene, WarningKind, WrapMode,
};
use serde_json::json;

#[test]
fn embedded_and_glb_buffers() {
    let b = triangle_scene(None, |_| {});
    let dir = temp_dir("layouts");
    let path = dir.join("e.gltf");
    b.write(&path, BufferLayout::Embedded).unwrap();
    assert!(!dir.join("e.bin").exists());
    assert_eq!(load(&path).0.triangle_count(), 1);

    let (root, bin) = b.to_json(None);
    let glb = common::glb_bytes(&root, &bin);
    let glb_path = dir.join("g.glb");
    std::fs::write(&glb_path, glb).unwrap();
    let (s, _) = load(&glb_path);
    assert_eq!(s.triangle_count(), 1);
    close3(s.meshes[0].positions[1], Vec3::X, 0.0);
}

#[test]
fn non_triangle_modes_are_skipped_with_a_warning() {
    let mut b = GltfBuilder::new();
    let tri = PrimitiveDesc::triangles(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        vec![0, 1, 2],
        None,
    );
    let mut lines = tri.clone();
    lines.mode = 1;
    let mesh = b.add_mesh("mixed", &[lines, tri]);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    let (s, w) = load(&write(&b, &temp_dir("modes"), "m"));
    assert_eq!(warnings_of(&w, WarningKind::UnsupportedPrimitiveMode).0, 1);
    assert!(w
        .iter()
        .any(|w| w.message.contains("mesh 0 \"mixed\" primitive 0")));
    assert_eq!(s.triangle_count(), 1);
    assert_eq!(s.meshes[0].primitives[0].gltf_primitive, 1);
    // No normals: flat normals generated; no material: the default material is appended.
    assert_eq!(warnings_of(&w, WarningKind::GeneratedNormals).0, 1);
    assert_eq!(s.meshes[0].normals, vec![Vec3::Z; 3]);
    assert_eq!(s.materials.len(), 1);
    assert_eq!(s.materials[0].name.as_deref(), Some("default"));
    assert_eq!(s.meshes[0].triangle_materials, vec![0]);
    assert_eq!(s.meshes[0].texcoords, vec![glam::Vec2::ZERO; 3]);
    assert_eq!(warnings_of(&w, WarningKind::DefaultCamera).0, 1);
    // The default camera looks at the geometry.
    let view = s.camera_at(0.0);
    assert!(view.position.z > 0.5 && view.forward.dot(-Vec3::Z) > 0.99);
}

#[test]
fn merged_primitives_keep_per_triangle_materials() {
    let mut b = GltfBuilder::new();
    let m0 = b.add_material(&MaterialDesc::diffuse("a", [0.1; 3]));
    let m1 = b.add_material(&MaterialDesc::diffuse("b", [0.9; 3]));
    let quad = |z: f32, m| {
        PrimitiveDesc::triangles(
            vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
            Some(vec![[0.0, 0.0, 1.0]; 4]),
            vec![0, 1, 2, 0, 2, 3],
            Some(m),
        )
    };
    let mesh = b.add_mesh("two", &[quad(0.0, m1), quad(1.0, m0)]);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    let (s, _) = load(&write(&b, &temp_dir("merge"), "m"));
    let m = &s.meshes[0];
    assert_eq!(m.triangle_materials, vec![1, 1, 0, 0]);
    assert_eq!(m.indices, vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7]);
    assert_eq!(
        (m.primitives[1].first_triangle, m.primitives[1].first_vertex),
        (2, 4)
    );
    close(m.triangle(2)[0].z, 1.0, 0.0);
    close3(m.bounds.max, Vec3::ONE, 0.0);
}

#[test]
fn alpha_modes_load_and_textures_decode_srgb() {
    let mut b = GltfBuilder::new();
    // sRGB 188 ≈ linear 0.5029; alpha 128 stays linear.
    let tex = b
        .add_texture_rgba8(1, 2, &[188, 0, 255, 128, 0, 0, 0, 255], 33648)
        .unwrap();
    let mut m = MaterialDesc::diffuse("glass", [1.0, 1.0, 1.0]);
    m.alpha_mode = Some("BLEND".into());
    m.base_color_texture = Some(tex);
    let mat = b.add_material(&m);
    let mut mask = MaterialDesc::diffuse("leaf", [1.0, 1.0, 1.0]);
    mask.alpha_mode = Some("MASK".into());
    mask.alpha_cutoff = Some(0.25);
    mask.base_color[3] = 0.2;
    b.add_material(&mask);
    // MASK with the default cutoff 0.5 and an untextured alpha that passes it: opaque.
    let mut solid = MaterialDesc::diffuse("solid", [1.0, 1.0, 1.0]);
    solid.alpha_mode = Some("MASK".into());
    solid.base_color[3] = 0.6;
    b.add_material(&solid);
    let b = {
        let mut b = b;
        let mut prim = PrimitiveDesc::triangles(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            None,
            vec![0, 1, 2],
            Some(mat),
        );
        prim.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let mesh = b.add_mesh("m", &[prim]);
        let node = b.add_node(&NodeDesc {
            mesh: Some(mesh),
            ..NodeDesc::default()
        });
        b.add_scene("s", &[node], None);
        b
    };
    let (s, w) = load(&write(&b, &temp_dir("tex"), "t"));
    assert!(!w.iter().any(|w| w.message.contains("alpha")), "{w:?}");
    let modes: Vec<_> = s.materials[..3]
        .iter()
        .map(|m| (m.alpha_mode, m.alpha_cutoff, m.has_alpha()))
        .collect();
    assert_eq!(
        modes,
        [
            (AlphaMode::Blend, 0.5, true),
            (AlphaMode::Mask, 0.25, true),
            (AlphaMode::Mask, 0.5, false),
        ]
    );
    assert!(s.plan().alpha);
    assert_eq!(s.textures.len(), 1);
    assert_eq!(s.textures[0].wrap_s, WrapMode::MirroredRepeat);
    let img = &s.images[s.textures[0].image];
    assert_eq!((img.width, img.height, img.srgb), (1, 2, true));
    let t = img.texel_linear(0, 0);
    close(t.x, 0.5029, 1e-3);
    close(t.z, 1.0, 1e-6);
    close(t.w, 128.0 / 255.0, 1e-6);
    assert_eq!(img.texel_linear(0, 1), Vec4::new(0.0, 0.0, 0.0, 1.0));
    let f = img.to_linear_f32();
    assert_eq!(f.len(), 8);
    assert_eq!(Vec4::from_slice(&f[..4]), t);
    assert_eq!(f[4..], [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(s.meshes[0].texcoords[1], glam::Vec2::X);
    assert_eq!(s.plan().textures, 1);
}

#[test]
fn camera_selection_by_name_and_traversal_order() {
    let mut b = triangle_scene(None, |_| {});
    let cam = b.add_perspective_camera("second", 0.5, Some(2.0), 0.05, Some(50.0));
    let node = b.add_node(&NodeDesc {
        name: Some("overview".into()),
        translation: Some([0.0, 5.0, 0.0]),
        camera: Some(cam),
        ..NodeDesc::default()
    });
    let (mut root, bin) = b.to_json(Some("c.bin"));
    root["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!(node));
    let dir = temp_dir("cams");
    let path = dir.join("c.gltf");
    write_files(&path, &root, Some(("c.bin", &bin))).unwrap();
    let (s, _) = load(&path);
    assert_eq!(s.camera_count, 2);
    assert_eq!(s.camera.name, "cam");
    for name in ["overview", "second"] {
        let opts = LoadOptions {
            camera_name: Some(name.into()),
            ..LoadOptions::default()
        };
        let (s, _) = Scene::load(&path, &opts).unwrap();
        assert_eq!(s.camera.name, "overview");
        let v = s.camera_at(0.0);
        close3(v.position, Vec3::new(0.0, 5.0, 0.0), 1e-6);
        assert_eq!(v.perspective.aspect_ratio, Some(2.0));
        assert_eq!(v.perspective.zfar, Some(50.0));
    }
}

#[test]
fn environment_from_extras_and_overrides() {
    let b = triangle_scene(None, |_| {});
    let (mut root, bin) = b.to_json(Some("e.bin"));
    root["scenes"][0]["extras"] = json!({"environment": {"radiance": [0.5, 1.0, 2.0]}});
    let dir = temp_dir("env");
    let path = dir.join("e.gltf");
    write_files(&path, &root, Some(("e.bin", &bin))).unwrap();
    let (s, _) = load(&path);
    assert_eq!(
        s.environment,
        Environment::Constant(Vec3::new(0.5, 1.0, 2.0))
    );
    let opts = |env| LoadOptions {
        camera_name: None,
        env,
    };
    let scaled = EnvOverride {
        scale: 2.0,
        ..EnvOverride::default()
    };
    let (s, _) = Scene::load(&path, &opts(scaled)).unwrap();
    assert_eq!(
        s.environment,
        Environment::Constant(Vec3::new(1.0, 2.0, 4.0))
    );
    let map = EnvOverride {
        map: Some("sky.exr".into()),
        radiance: Some([1.0; 3]),
        scale: 0.5,
    };
    let (s, _) = Scene::load(&path, &opts(map)).unwrap();
    assert_eq!(
        s.environment,
        Environment::Map {
            path: "sky.exr".into(),
            scale: 0.5
        }
    );
    assert_eq!(s.plan().environment, EnvironmentKind::Map);
    // Malformed extras: warning, no environment.
    root["scenes"][0]["extras"] = json!({"environment": {"radiance": "bright"}});
    write_files(&path, &root, Some(("e.bin", &bin))).unwrap();
    let (s, w) = load(&path);
    assert_eq!(s.environment, Environment::None);
    assert!(w
        .iter()
        .any(|w| w.message.contains("extras.environment ignored")));
}

#[test]
fn weights_channels_are_ignored_with_a_warning() {
    let mut b = triangle_scene(None, |_| {});
    b.add_animation(
        "w",
        &[radcache_scene::writer::ChannelDesc {
            node: 0,
            property: radcache_scene::Property::Scale,
            interpolation: radcache_scene::Interpolation::Linear,
            times: vec![0.0, 1.0],
            values: vec![1.0; 6],
        }],
    );
    let (mut root, bin) = b.to_json(Some("w.bin"));
    root["animations"][0]["channels"][0]["target"]["path"] = json!("weights");
    let dir = temp_dir("weights");
    let path = dir.join("w.gltf");
    write_files(&path, &root, Some(("w.bin", &bin))).unwrap();
    let (s, w) = load(&path);
    assert_eq!(warnings_of(&w, WarningKind::WeightsChannelIgnored).0, 1);
    assert!(s.animations[0].channels.is_empty());
    assert_eq!(s.time_range(), None);
}

#[test]
fn sparse_and_normalized_accessors() {
    let b = triangle_scene(None, |_| {});
    let (mut root, mut bin) = b.to_json(Some("s.bin"));
    // Sparse POSITION: vertex 2 becomes (0.5, 2, 0) (indices u8 [2], values VEC3 f32), appended
    // to the buffer in two new views.
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let idx_at = bin.len();
    bin.extend_from_slice(&[2, 0, 0, 0]);
    let val_at = bin.len();
    for v in [0.5f32, 2.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    // Normalized u16 TEXCOORD_0: (0, 0), (65535, 0), (0, 32768).
    let uv_at = bin.len();
    for v in [0u16, 0, 65535, 0, 0, 32768] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    root["buffers"][0]["byteLength"] = json!(bin.len());
    let views = root["bufferViews"].as_array_mut().unwrap();
    let first = views.len();
    views.push(json!({"buffer": 0, "byteOffset": idx_at, "byteLength": 1}));
    views.push(json!({"buffer": 0, "byteOffset": val_at, "byteLength": 12}));
    views.push(json!({"buffer": 0, "byteOffset": uv_at, "byteLength": 12}));
    root["accessors"][0]["sparse"] = json!({
        "count": 1,
        "indices": {"bufferView": first, "componentType": 5121},
        "values": {"bufferView": first + 1}
    });
    let accessors = root["accessors"].as_array_mut().unwrap();
    accessors.push(json!({"bufferView": first + 2, "componentType": 5123, "normalized": true, "count": 3, "type": "VEC2"}));
    let uv = accessors.len() - 1;
    root["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
    let dir = temp_dir("sparse");
    let path = dir.join("s.gltf");
    write_files(&path, &root, Some(("s.bin", &bin))).unwrap();
    let (s, _) = load(&path);
    let m = &s.meshes[0];
    assert_eq!(
        m.positions,
        vec![Vec3::ZERO, Vec3::X, Vec3::new(0.5, 2.0, 0.0)]
    );
    assert_eq!(m.texcoords[1], glam::Vec2::X);
    close(m.texcoords[2].y, 32768.0 / 65535.0, 1e-7);
    // A sparse index beyond the accessor's count is an error naming the accessor.
    bin[idx_at] = 3;
    write_files(&path, &root, Some(("s.bin", &bin))).unwrap();
    let e = Scene::load(&path, &LoadOptions::default()).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("POSITION accessor 0") && text.contains("sparse index 3"),
        "{text}"
    );
}

#[test]
fn skins_and_morph_targets_use_the_rest_pose_with_warnings() {
    let b = triangle_scene(None, |_| {});
    let (mut root, bin) = b.to_json(Some("k.bin"));
    // A morph target reusing the NORMAL accessor as a position displacement, and a skin.
    root["meshes"][0]["primitives"][0]["targets"] = json!([{"POSITION": 1}]);
    root["meshes"][0]["weights"] = json!([1.0]);
    root["skins"] = json!([{"joints": [1]}]);
    root["nodes"][0]["skin"] = json!(0);
    let dir = temp_dir("skin");
    let path = dir.join("k.gltf");
    write_files(&path, &root, Some(("k.bin", &bin))).unwrap();
    let (s, w) = load(&path);
    assert_eq!(warnings_of(&w, WarningKind::SkinOrMorphIgnored).0, 2);
    assert!(w.iter().any(|w| w
        .message
        .contains("mesh 0 \"tri\" primitive 0: morph targets")));
    assert!(w
        .iter()
        .any(|w| w.message.contains("node 0 \"tri\": skin ignored")));
    // Rest pose: the morph target is not applied.
    assert_eq!(s.meshes[0].positions[0], Vec3::ZERO);
}

/// A scene with nothing that emits (no emissive material, no punctual light, no environment)
/// renders black: the loader says so once, and says how to add light; light from any source,
/// the command line's environment included, silences it.
#[test]
fn a_scene_without_light_gets_one_warning_naming_the_fix() {
    let dir = temp_dir("unlit");
    let path = write(&triangle_scene(None, |_| {}), &dir, "unlit");
    let (_, warnings) = load(&path);
    assert_eq!(
        warnings_of(&warnings, WarningKind::NoLight),
        (1, 1),
        "{warnings:?}"
    );
    let w = warnings
        .iter()
        .find(|w| w.kind == WarningKind::NoLight)
        .unwrap();
    assert!(w.message.contains("unlit.gltf"), "{}", w.message);
    assert!(w.message.contains("--env-radiance"), "{}", w.message);

    let lit = LoadOptions {
        env: EnvOverride {
            radiance: Some([0.5, 0.5, 0.5]),
            ..Default::default()
        },
        ..LoadOptions::default()
    };
    let (_, warnings) = Scene::load(&path, &lit).unwrap();
    assert_eq!(warnings_of(&warnings, WarningKind::NoLight), (0, 0));

    let emissive = MaterialDesc {
        emissive: [1.0, 1.0, 1.0],
        ..MaterialDesc::diffuse("light", [0.5; 3])
    };
    let path = write(&triangle_scene(Some(emissive), |_| {}), &dir, "emissive");
    let (_, warnings) = load(&path);
    assert_eq!(warnings_of(&warnings, WarningKind::NoLight), (0, 0));
}
