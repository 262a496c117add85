//! The bundled assets load with the expected contents and plans, and the copies in the
//! repository's `assets/` are up to date with the generators.

mod common;

use std::path::PathBuf;

use common::{close, close3, load, temp_dir};
use glam::Vec3;
use radcache_scene::assets::{write_bundled_assets, CORNELL_YFOV, COURTYARD_DURATION};
use radcache_scene::{AnimationKind, Environment, EnvironmentKind, LightKind, Scene};

fn bundled() -> Vec<PathBuf> {
    write_bundled_assets(&temp_dir("assets")).unwrap()
}

fn mesh_named(s: &Scene, name: &str) -> usize {
    s.meshes
        .iter()
        .position(|m| m.name.as_deref() == Some(name))
        .unwrap()
}

#[test]
fn cornell_box() {
    let (s, warnings) = load(&bundled()[0]);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(s.meshes.len(), 4);
    assert_eq!(s.triangle_count(), 32);
    assert_eq!(s.materials.len(), 4);
    assert_eq!(s.instances.len(), 4);
    assert_eq!(s.light_instances.len(), 0);
    assert_eq!(s.camera_count, 1);
    assert_eq!(s.animations.len(), 0);
    assert_eq!(s.textures.len(), 0);

    close(CORNELL_YFOV, 2.0 * (0.0125f32 / 0.035).atan(), 1e-6);
    let view = s.camera_at(0.0);
    close3(view.position, Vec3::new(0.278, 0.273, -0.8), 1e-6);
    close3(view.forward, Vec3::Z, 1e-6);
    close3(view.up, Vec3::Y, 1e-6);
    close(view.perspective.yfov, CORNELL_YFOV, 1e-6);
    assert_eq!(view.perspective.aspect_ratio, Some(1.0));

    // Red wall on the left of the image, green on the right: project every vertex of each wall
    // through the camera (NDC x < 0 is the left half of the image).
    let room = &s.meshes[mesh_named(&s, "room")];
    let aspect = view.perspective.aspect_or(1.0);
    let ndc_x_of = |material: &str| -> Vec<f32> {
        let m = s
            .materials
            .iter()
            .position(|x| x.name.as_deref() == Some(material))
            .unwrap() as u32;
        let p = room.primitives.iter().find(|p| p.material == m).unwrap();
        let verts = p.first_vertex as usize..(p.first_vertex + p.vertex_count) as usize;
        assert_eq!(verts.len(), 4);
        verts
            .map(|v| {
                view.project(room.positions[v], aspect)
                    .expect("wall vertex behind the camera")
                    .x
            })
            .collect()
    };
    let red_x = ndc_x_of("red");
    let green_x = ndc_x_of("green");
    assert!(
        red_x.iter().all(|&x| x < 0.0),
        "red wall must be on the left: {red_x:?}"
    );
    assert!(
        green_x.iter().all(|&x| x > 0.0),
        "green wall must be on the right: {green_x:?}"
    );
    // The light is in the upper half of the image, centred horizontally.
    let light = &s.meshes[mesh_named(&s, "light")];
    for &p in &light.positions {
        let ndc = view.project(p, aspect).unwrap();
        assert!(
            ndc.y > 0.5 && ndc.y < 1.0 && ndc.x.abs() < 0.2,
            "light vertex at {ndc}"
        );
    }
    let red = s
        .materials
        .iter()
        .find(|m| m.name.as_deref() == Some("red"))
        .unwrap();
    close3(red.diffuse_albedo(), Vec3::new(0.63, 0.065, 0.05), 1e-6);

    // Walls face the inside of the box.
    let inside = Vec3::new(0.278, 0.274, 0.28);
    for t in 0..room.triangle_count() {
        let p = room.triangle(t);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        assert!(
            n.dot(inside - p[0]) > 0.0,
            "room triangle {t} faces outward"
        );
    }
    // Blocks face outward; every vertex normal agrees with its triangle's winding.
    for name in ["tall_block", "short_block"] {
        let m = &s.meshes[mesh_named(&s, name)];
        let center = m.bounds.center();
        for t in 0..m.triangle_count() {
            let p = m.triangle(t);
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            assert!(n.dot(c - center) > 0.0, "{name} triangle {t} faces inward");
        }
    }
    for m in &s.meshes {
        for t in 0..m.triangle_count() {
            let p = m.triangle(t);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            for k in 0..3 {
                let vn = m.normals[m.indices[3 * t + k] as usize];
                assert!(
                    vn.dot(n) > 0.99,
                    "{:?} triangle {t}: normal {vn} vs winding {n}",
                    m.name
                );
            }
        }
    }
    // The light: 2 triangles facing down, 130 mm x 105 mm, emitting (17, 12, 4).
    let emitters = s.emitters_at(0.0);
    assert_eq!(emitters.triangles.len(), 2);
    let area: f32 = emitters.triangles.iter().map(|t| t.area).sum();
    close(area, 0.130 * 0.105, 1e-6);
    for t in &emitters.triangles {
        close3(t.normal, -Vec3::Y, 1e-6);
        close3(t.radiance, Vec3::new(17.0, 12.0, 4.0), 1e-4);
        assert!(t.positions.iter().all(|p| (p.y - 0.5458).abs() < 1e-6));
    }
    let b = s.bounds_at(0.0);
    close3(b.min, Vec3::ZERO, 1e-6);
    close3(b.max, Vec3::new(0.556, 0.5488, 0.5592), 1e-6);

    let plan = s.plan();
    assert_eq!(plan.emissive_triangles, 2);
    assert!(!plan.has_punctual_lights());
    assert_eq!(plan.environment, EnvironmentKind::None);
    assert_eq!(plan.textures, 0);
    assert_eq!(plan.animation.kind, AnimationKind::None);
    assert_eq!(plan.animation.time_range, None);
    let text = s.summary();
    for needle in [
        "triangles: 32",
        "materials: 4 (1 emissive)",
        "plan:",
        "animation: none",
        "emissive triangles: 2",
        "cache across frames: records kept",
    ] {
        assert!(text.contains(needle), "summary lacks {needle:?}:\n{text}");
    }
}

#[test]
fn furnace() {
    let (s, warnings) = load(&bundled()[1]);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(
        (
            s.meshes.len(),
            s.triangle_count(),
            s.materials.len(),
            s.nodes.len()
        ),
        (1, 12, 1, 2)
    );
    let m = &s.materials[0];
    close3(m.diffuse_albedo(), Vec3::splat(0.5), 1e-6);
    close3(m.emissive, Vec3::ONE, 1e-6);
    let view = s.camera_at(0.0);
    close3(view.position, Vec3::ZERO, 1e-6);
    // Every face emits towards the camera at the centre: normals point inward.
    let emitters = s.emitters_at(0.0);
    assert_eq!(emitters.triangles.len(), 12);
    close(emitters.triangles.iter().map(|t| t.area).sum(), 24.0, 1e-4);
    for t in &emitters.triangles {
        let c = t.positions.iter().sum::<Vec3>() / 3.0;
        close3(
            t.emitted_radiance((view.position - c).normalize()),
            Vec3::ONE,
            1e-6,
        );
        assert_eq!(
            t.emitted_radiance((c - view.position).normalize()),
            Vec3::ZERO
        );
    }
    let plan = s.plan();
    assert_eq!(plan.emissive_triangles, 12);
    close(plan.emissive_power, 24.0 * std::f32::consts::PI, 1e-3);
    assert_eq!(plan.animation.kind, AnimationKind::None);
    assert_eq!(plan.environment, EnvironmentKind::None);
}

#[test]
fn animated_scene() {
    let (s, warnings) = load(&bundled()[2]);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(
        (s.meshes.len(), s.triangle_count(), s.materials.len()),
        (5, 46, 6)
    );
    assert_eq!(s.light_instances.len(), 1);
    assert_eq!(s.lights[0].kind, LightKind::Point);
    assert_eq!(s.camera_count, 1);
    assert_eq!(s.animations.len(), 1);
    assert_eq!(s.animations[0].channels.len(), 6);
    assert_eq!(s.time_range(), Some((0.0, 5.0)));
    assert_eq!(
        s.environment,
        Environment::Constant(Vec3::new(0.05, 0.05, 0.08))
    );

    let dynamic: Vec<(String, bool)> = s
        .instances
        .iter()
        .map(|i| (s.meshes[i.mesh].name.clone().unwrap(), i.dynamic))
        .collect();
    for (name, dynamic) in &dynamic {
        assert_eq!(*dynamic, name == "mover" || name == "bouncer", "{name}");
    }
    close3(
        s.camera_at(0.0).position,
        Vec3::new(0.278, 0.273, -0.8),
        1e-6,
    );
    close3(
        s.camera_at(1.25).position,
        Vec3::new(0.278, 0.2865, -0.5),
        1e-5,
    );
    close3(s.camera_at(5.0).position, Vec3::new(0.35, 0.3, 0.1), 1e-6);
    close3(s.camera_at(99.0).position, Vec3::new(0.35, 0.3, 0.1), 1e-6);
    let yaw195 = glam::Quat::from_rotation_y(195f32.to_radians());
    close3(s.camera_at(5.0).forward, yaw195 * -Vec3::Z, 1e-5);
    let lights = s.lights_at(3.0);
    close3(lights[0].position, Vec3::new(0.45, 0.45, 0.12), 1e-6);

    let plan = s.plan();
    assert_eq!(plan.animation.kind, AnimationKind::Geometry);
    assert!(plan.animation.camera && plan.animation.geometry && !plan.animation.lights);
    assert_eq!(plan.animation.time_range, Some((0.0, 5.0)));
    assert_eq!(
        (plan.lights.point, plan.lights.spot, plan.lights.directional),
        (1, 0, 0)
    );
    assert_eq!(plan.environment, EnvironmentKind::Constant);
    assert_eq!(plan.emissive_triangles, 2);
    let range = s.bounds_over_range();
    let start = s.bounds_at(0.0);
    assert!(range.max.y >= start.max.y && range.min.x <= start.min.x);
    let text = s.to_string();
    assert!(text.contains("time range [0.000, 5.000] s"), "{text}");
    assert!(
        text.contains("geometry (camera yes, lights no, geometry yes)"),
        "{text}"
    );
    assert!(
        text.contains("cache across frames: records kept with lifespans"),
        "{text}"
    );
    assert!(
        text.contains("radiance grid across frames: kept with the records"),
        "{text}"
    );
}

#[test]
fn cornell_fly_through_moves_only_the_camera() {
    let paths = bundled();
    let (s, warnings) = load(&paths[3]);
    assert!(warnings.is_empty(), "{warnings:?}");
    let (cornell, _) = load(&paths[0]);
    assert_eq!(s.triangle_count(), cornell.triangle_count());
    assert_eq!(s.time_range(), Some((0.0, 2.0)));
    close3(
        s.camera_at(0.0).position,
        Vec3::new(0.278, 0.273, -0.8),
        1e-6,
    );
    close3(s.camera_at(2.0).position, Vec3::new(0.2, 0.26, -0.35), 1e-6);
    let plan = s.plan();
    assert_eq!(plan.animation.kind, AnimationKind::CameraOnly);
    assert!(plan.keeps_records());
    assert!(!s.to_string().contains("radiance grid across frames"));
    // The same room under another camera: the same content (a cache file of one serves the
    // other); the animated room is other content.
    assert_eq!(s.content_hash(), cornell.content_hash());
    let (animated, _) = load(&paths[2]);
    assert_ne!(s.content_hash(), animated.content_hash());
    assert_eq!(s.content_hash(), load(&paths[3]).0.content_hash());
}

#[test]
fn the_content_hash_follows_materials_geometry_and_lights() {
    let (base, _) = load(&bundled()[0]);
    let hash = base.content_hash();
    let mut s = base.clone();
    s.materials[1].base_color.x += 1e-3;
    assert_ne!(s.content_hash(), hash, "a material's colour");
    let mut s = base.clone();
    s.materials[1].specular_factor = 1.0;
    assert_ne!(s.content_hash(), hash, "a material's specular layer");
    let mut s = base.clone();
    s.materials[1].ior = 1.6;
    assert_ne!(s.content_hash(), hash, "a material's index of refraction");
    let mut s = base.clone();
    s.meshes[0].positions[0].y += 1e-4;
    assert_ne!(s.content_hash(), hash, "a vertex");
    let mut s = base.clone();
    s.environment = Environment::Constant(Vec3::splat(0.1));
    assert_ne!(s.content_hash(), hash, "the environment");
    let mut s = base.clone();
    s.path = PathBuf::from("elsewhere/copy.gltf");
    s.meshes[0].name = Some("renamed".into());
    assert_eq!(s.content_hash(), hash, "names and the path are not content");
}

/// Generate-and-check: the committed `assets/` must match the generators' output.
#[test]
fn repository_assets_are_up_to_date() {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let fresh = temp_dir("fresh");
    write_bundled_assets(&fresh).unwrap();
    for name in [
        "cornell",
        "furnace",
        "animated",
        "cornell_fly",
        "courtyard",
        "metal_spheres",
        "glossy_room",
    ] {
        for ext in ["gltf", "bin"] {
            let rel = format!("{name}/{name}.{ext}");
            let committed = std::fs::read(repo.join(&rel)).unwrap_or_else(|e| {
                panic!("assets/{rel} is missing ({e}): run `cargo xtask assets`")
            });
            let generated = std::fs::read(fresh.join(&rel)).unwrap();
            assert!(
                committed == generated,
                "assets/{rel} is stale: regenerate with `cargo xtask assets`"
            );
        }
    }
}

/// The Sponza-class courtyard: over 100k triangles in many meshes and materials, fine foliage,
/// a directional sun, a constant sky, and a 5 s camera path over static geometry.
#[test]
fn courtyard_is_sponza_class() {
    let (s, warnings) = load(&bundled()[4]);
    assert!(warnings.is_empty(), "{warnings:?}");
    let triangles = s.triangle_count();
    assert!(
        (100_000..200_000).contains(&triangles),
        "{triangles} triangles"
    );
    assert!(s.meshes.len() >= 50, "{} meshes", s.meshes.len());
    assert!(s.materials.len() >= 8, "{} materials", s.materials.len());
    let bushes = s
        .meshes
        .iter()
        .filter(|m| m.name.as_deref().is_some_and(|n| n.starts_with("bush_")))
        .count();
    assert_eq!(bushes, 20);
    assert_eq!(s.lights.len(), 1);
    assert!(matches!(s.lights[0].kind, LightKind::Directional));
    match &s.environment {
        Environment::Constant(c) => assert!(c.min_element() > 0.0, "{c}"),
        other => panic!("expected a constant sky, got {other:?}"),
    }
    let plan = s.plan();
    assert!(!plan.has_emissive() && plan.has_punctual_lights());
    // The camera moves over 5 s (120 frames at 24 fps); nothing else does.
    let (a, b) = (s.camera_at(0.0), s.camera_at(COURTYARD_DURATION));
    assert!((a.position - b.position).length() > 10.0, "{a:?} {b:?}");
    // Only the camera node moves: no mesh instance and no light is dynamic.
    let moving: Vec<&str> = (0..s.nodes.len())
        .filter(|&n| s.dynamic[n])
        .filter_map(|n| s.nodes[n].name.as_deref())
        .collect();
    assert_eq!(moving, ["camera"]);
}
