//! Radiance records for glossy lobes (issue 18, docs/radiance-caching.md §6), on lavapipe: a
//! closed room with a rough metal sphere, a rough plastic (dielectric) sphere and a glossy metal
//! floor, all at roughness ≥ `GLOSSY_ROUGHNESS_MIN`, rendered with the cache frame (the specular
//! lobes' indirect light from the radiance records) against the path tracer; and the same frame
//! with the per-pixel specular paths (`GlossyLight::Paths`) against it.

use glam::{Quat, Vec3};
use radcache_cache::IcParams;
use radcache_image::{compare, Image};
use radcache_render::{render_ic, FrameOutput, GlossyLight, GpuScene, IcSettings};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::Scene;
use radcache_shared::consts::GLOSSY_ROUGHNESS_MIN;
use radcache_tests::geometry::{room, uv_sphere};
use radcache_tests::scenes::{camera_node, plane_y, render, temp_dir, write_and_load};
use radcache_tests::{context, finish, shaders};

/// A closed 2 × 2 × 2 room lit by a square emitter under its ceiling, a red wall panel, a rough
/// gold-coloured metal sphere (0.7), a rough blue plastic sphere (0.8) and a glossy grey metal
/// floor (0.65) just above the room's own floor; the camera looks down a little.
fn glossy_room(tag: &str) -> Scene {
    let mut b = GltfBuilder::new();
    let white = b.add_material(&MaterialDesc::diffuse("white", [0.75, 0.75, 0.75]));
    let red = b.add_material(&MaterialDesc::diffuse("red", [0.7, 0.15, 0.1]));
    let light = b.add_material(&MaterialDesc {
        double_sided: true,
        ..MaterialDesc::emitter("light", [0.0; 3], [12.0; 3])
    });
    let gold = b.add_material(&MaterialDesc::metal_rough(
        "gold",
        [0.95, 0.7, 0.35],
        1.0,
        0.7,
    ));
    let plastic = b.add_material(&MaterialDesc::metal_rough(
        "plastic",
        [0.15, 0.3, 0.7],
        0.0,
        0.8,
    ));
    let floor = b.add_material(&MaterialDesc::metal_rough(
        "floor",
        [0.8, 0.8, 0.8],
        1.0,
        0.65,
    ));
    let tri = |m: &radcache_tests::geometry::Mesh, material: usize, smooth: Option<Vec3>| {
        PrimitiveDesc::triangles(
            m.positions.iter().map(|p| p.to_array()).collect(),
            smooth.map(|c| {
                m.positions
                    .iter()
                    .map(|p| (*p - c).normalize().to_array())
                    .collect()
            }),
            m.indices.clone(),
            Some(material),
        )
    };
    let walls = room(Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut prims = vec![
        tri(&walls, white, None),
        PrimitiveDesc::triangles(
            vec![
                [-0.999, -1.0, -1.0],
                [-0.999, -1.0, 1.0],
                [-0.999, 1.0, 1.0],
                [-0.999, 1.0, -1.0],
            ],
            Some(vec![[1.0, 0.0, 0.0]; 4]),
            vec![0, 1, 2, 0, 2, 3],
            Some(red),
        ),
        plane_y([-0.3, 0.3], [-0.3, 0.3], 0.99, light),
        plane_y([-0.999, 0.999], [-0.999, 0.999], -0.999, floor),
    ];
    let mut sphere = |centre: Vec3, r: f32, material: usize| {
        let mut m = uv_sphere(r, 24, 48);
        for p in &mut m.positions {
            *p += centre;
        }
        prims.push(tri(&m, material, Some(centre)));
    };
    sphere(Vec3::new(-0.45, -0.6, -0.2), 0.4, gold);
    sphere(Vec3::new(0.45, -0.6, 0.2), 0.4, plastic);
    let mesh = b.add_mesh("room", &prims);
    let roots = vec![
        b.add_node(&NodeDesc {
            name: Some("room".into()),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }),
        camera_node(
            &mut b,
            Vec3::new(0.0, 0.2, 0.99),
            Quat::from_rotation_x(-0.25),
            1.4,
        ),
    ];
    b.add_scene(tag, &roots, None);
    write_and_load(&b, &temp_dir(tag), tag)
}

fn image(o: &FrameOutput) -> Image {
    Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap()
}

#[test]
fn glossy_lobes_from_radiance_records_match_the_path_tracer() {
    let scene = glossy_room("glossy_room");
    let plan = scene.plan();
    assert_eq!(plan.glossy_materials, 3, "{plan}");
    assert!(plan.to_string().contains(&format!(
        "glossy lobes: radiance records for roughness ≥ {GLOSSY_ROUGHNESS_MIN} (3 materials"
    )));
    let size = (48u32, 48u32);
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let reference = render(&ctx, &shaders, &scene, &mut gpu, size, 4096, 1);
    let mut results = Vec::new();
    for glossy in [GlossyLight::Records, GlossyLight::Paths] {
        let settings = IcSettings {
            width: size.0,
            height: size.1,
            params: IcParams::default(),
            glossy,
            ..IcSettings::default()
        };
        let (ic, stats) =
            render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
        assert_eq!(ic.nonfinite_pixels, 0);
        let m = compare(&image(&reference), &image(&ic)).unwrap();
        eprintln!(
            "glossy room, cache frame ({glossy:?}) vs path tracer (4096 spp): {m}; records {}; {:.2} s",
            stats.records, ic.time_s
        );
        assert_eq!(m.nonfinite_candidate, 0);
        results.push(m);
    }
    drop(gpu);
    finish(ctx);
    for m in &results {
        assert!(m.relmse <= 0.01, "relMSE {}", m.relmse);
        for (c, r) in m.mean_ratio.iter().enumerate() {
            assert!((r - 1.0).abs() <= 0.02, "channel {c} mean ratio {r}");
        }
    }
}
