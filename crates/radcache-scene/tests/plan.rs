//! The scene plan's animation classification (none / camera only / lights only / geometry), its
//! time range, and its `Display` text; the bundled scenes' materials and what the plan compiles
//! for them (specular code, radiance records, the gathers' radiance grid).

mod common;

use std::path::PathBuf;

use common::{close3, load, temp_dir, triangle_scene};
use glam::Vec3;
use radcache_scene::assets::write_bundled_assets;
use radcache_scene::writer::{ChannelDesc, LightDesc, NodeDesc};
use radcache_scene::{AnimationKind, EnvironmentKind, Interpolation, LightKind, Property, Scene};

/// The triangle scene (node 0 = triangle, node 1 = camera) plus a spot light on node 2, with
/// translation channels on the listed nodes (`moving`: keys differ; otherwise constant).
fn scene_with_channels(tag: &str, channels: &[(usize, bool)]) -> Scene {
    let mut b = triangle_scene(None, |_| {});
    let light = b.add_light(&LightDesc {
        name: Some("spot".into()),
        kind: LightKind::Spot {
            inner_cone_angle: 0.1,
            outer_cone_angle: 0.3,
        },
        color: [1.0; 3],
        intensity: 2.0,
        range: None,
    });
    let node = b.add_node(&NodeDesc {
        light: Some(light),
        ..NodeDesc::default()
    });
    assert_eq!(node, 2);
    let channels: Vec<ChannelDesc> = channels
        .iter()
        .map(|&(node, moving)| ChannelDesc {
            node,
            property: Property::Translation,
            interpolation: Interpolation::Linear,
            times: vec![0.5, 2.5],
            values: vec![0.0, 0.0, 2.0, 0.0, if moving { 1.0 } else { 0.0 }, 2.0],
        })
        .collect();
    if !channels.is_empty() {
        b.add_animation("a", &channels);
    }
    // Put the light node into the scene.
    let (mut root, bin) = b.to_json(Some("p.bin"));
    root["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!(node));
    let dir = temp_dir(tag);
    let path = dir.join("p.gltf");
    radcache_scene::writer::write_files(&path, &root, Some(("p.bin", &bin))).unwrap();
    load(&path).0
}

#[test]
fn animation_classification() {
    // (channels, kind, camera, lights, geometry)
    type Case<'a> = (&'a [(usize, bool)], AnimationKind, bool, bool, bool);
    let cases: [Case; 6] = [
        (&[], AnimationKind::None, false, false, false),
        (
            &[(0, false), (1, false)],
            AnimationKind::None,
            false,
            false,
            false,
        ),
        (&[(1, true)], AnimationKind::CameraOnly, true, false, false),
        (&[(2, true)], AnimationKind::LightsOnly, false, true, false),
        (
            &[(1, true), (2, true)],
            AnimationKind::LightsOnly,
            true,
            true,
            false,
        ),
        (
            &[(0, true), (1, true)],
            AnimationKind::Geometry,
            true,
            false,
            true,
        ),
    ];
    for (i, (channels, kind, camera, lights, geometry)) in cases.into_iter().enumerate() {
        let s = scene_with_channels(&format!("plan{i}"), channels);
        let plan = s.plan();
        let a = plan.animation;
        assert_eq!(
            (a.kind, a.camera, a.lights, a.geometry),
            (kind, camera, lights, geometry),
            "case {i}"
        );
        let range = (!channels.is_empty()).then_some((0.5, 2.5));
        assert_eq!(a.time_range, range, "case {i}");
        assert_eq!(
            (plan.lights.point, plan.lights.spot, plan.lights.directional),
            (0, 1, 0)
        );
        assert_eq!(plan.emissive_triangles, 0);
        assert_eq!(plan.environment, EnvironmentKind::None);
        assert_eq!(plan.textures, 0);
    }
}

#[test]
fn animated_camera_and_plan_text() {
    let s = scene_with_channels("plantext", &[(1, true)]);
    // The camera node starts at (0, 0, 2) and rises by 1 over [0.5, 2.5].
    close3(s.camera_at(0.0).position, Vec3::new(0.0, 0.0, 2.0), 1e-6);
    close3(s.camera_at(1.5).position, Vec3::new(0.0, 0.5, 2.0), 1e-6);
    close3(s.camera_at(3.0).position, Vec3::new(0.0, 1.0, 2.0), 1e-6);
    let text = s.plan().to_string();
    for needle in [
        "emissive triangles: none",
        "punctual lights: 0 point, 1 spot, 0 directional",
        "environment: none",
        "normal maps: none",
        "textures: no",
        "alpha: none (opaque ray queries)",
        "animation: camera only (camera yes, lights no, geometry no), time range [0.500, 2.500] s",
        "cache across frames: records kept",
    ] {
        assert!(text.contains(needle), "plan text lacks {needle:?}:\n{text}");
    }
    let summary = s.to_string();
    for needle in [
        "nodes: 3 (3 in scene)",
        "meshes: 1, instances: 1, triangles: 1",
        "lights: 0 point, 1 spot, 0 directional",
        "animations: 1 (1 channels), time range [0.500, 2.500] s",
        "camera: \"cam\"",
        "plan:",
    ] {
        assert!(
            summary.contains(needle),
            "summary lacks {needle:?}:\n{summary}"
        );
    }
}

#[test]
fn bundled_scenes_are_lambertian() {
    let files = write_bundled_assets(&temp_dir("lambert")).unwrap();
    assert!(files.len() >= 5);
    let specular =
        |p: &std::path::Path| p.ends_with("metal_spheres.gltf") || p.ends_with("glossy_room.gltf");
    for path in files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "gltf") && !specular(p))
    {
        let (s, _) = load(path);
        for m in &s.materials {
            assert!(m.is_lambertian(), "{}: {m:?}", path.display());
            assert_eq!(
                (m.metallic, m.roughness, m.specular_factor),
                (0.0, 1.0, 0.0)
            );
        }
        let plan = s.plan();
        assert!(!plan.specular, "{}", path.display());
        assert!(plan
            .to_string()
            .contains("materials: lambertian only (no specular code compiled)"));
        assert!(plan.path_grid(), "{}", path.display());
        assert!(plan.to_string().contains("gather paths: radiance grid"));
    }
    // The bundled scenes with specular materials.
    let spheres = files.iter().find(|p| p.ends_with("metal_spheres.gltf"));
    let (s, _) = load(spheres.expect("metal_spheres is bundled"));
    assert!(s.plan().specular);
    assert_eq!(s.materials.iter().filter(|m| m.metallic == 1.0).count(), 2);
    assert_eq!(s.plan().glossy_materials, 1, "the 0.6 sphere");
    let glossy = files.iter().find(|p| p.ends_with("glossy_room.gltf"));
    let (s, _) = load(glossy.expect("glossy_room is bundled"));
    let plan = s.plan();
    assert!(plan.specular && plan.radiance_cache());
    assert!(plan.path_grid(), "its walls are Lambertian");
    assert!(plan
        .to_string()
        .contains("gather paths: radiance grid at Lambertian vertices"));
    // Gold 0.7, plastic 0.8 and the floor plate 0.65; the 0.4 sphere stays below the threshold.
    assert_eq!(plan.glossy_materials, 3);
    assert!(plan
        .to_string()
        .contains("glossy lobes: radiance records for roughness ≥ 0.6 (3 materials"));
    // Cornell box, as bundled in the repository.
    let cornell =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/cornell/cornell.gltf");
    let (s, w) = load(&cornell);
    assert!(w.is_empty(), "{w:?}");
    assert!(s.materials.iter().all(|m| m.is_lambertian()));
    assert!(!s.plan().specular);
}
