//! The specular lobe's paths pooled over a pixel's neighbourhood (docs/materials.md §10,
//! `shaders/passes/direct.comp` `specular_pooled`), on lavapipe, against the path tracer.
//!
//! A rough metal plate (roughness 0.5) fills the view of a closed room with a red and a green
//! wall and a square emitter under the ceiling: its specular indirect light varies across the
//! lobe (walls of three colours, the lit ceiling), so each path carries noise. Pooled, a pixel
//! averages the estimates of the neighbours whose lobes overlap its own; per pixel, its own
//! alone. Both must agree with a long path-traced reference on the plate's mean (the pooled
//! estimator is unbiased but for the radiance being seen a pixel away, which on a plate in a
//! room is far below the tolerance), and the pooled frame's error against it must be well below
//! the per-pixel frame's: the records, the direct light and the Lambertian pixels are the same
//! in both (the same seeds), so only the plate's specular paths differ.

use glam::{Quat, Vec3};
use radcache_cache::IcParams;
use radcache_image::{compare, Image};
use radcache_render::{render_ic, FrameOutput, GpuScene, IcSettings, SpecularPaths};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, PrimitiveDesc};
use radcache_scene::Scene;
use radcache_tests::geometry::room;
use radcache_tests::scenes::{lit_room_materials, mesh_camera_scene, plane_x, plane_y, render};
use radcache_tests::{context, finish, shaders};

/// The room (2 × 2 × 2, white), a red and a green panel on the side walls, a square emitter under
/// the ceiling and a rough white metal plate on the floor, seen from the back wall looking down.
fn plate_room(tag: &str) -> Scene {
    let mut b = GltfBuilder::new();
    let [white, red, light] = lit_room_materials(&mut b);
    let green = b.add_material(&MaterialDesc::diffuse("green", [0.1, 0.6, 0.15]));
    let metal = b.add_material(&MaterialDesc::metal_rough(
        "metal",
        [0.9, 0.9, 0.9],
        1.0,
        0.5,
    ));
    let walls = room(Vec3::splat(-1.0), Vec3::splat(1.0));
    let prims = vec![
        PrimitiveDesc::triangles(
            walls.positions.iter().map(|p| p.to_array()).collect(),
            None,
            walls.indices.clone(),
            Some(white),
        ),
        plane_x([-1.0, 1.0], [-1.0, 1.0], -0.999, 1.0, red),
        plane_x([-1.0, 1.0], [-1.0, 1.0], 0.999, -1.0, green),
        plane_y([-0.3, 0.3], [-0.3, 0.3], 0.99, light),
        plane_y([-0.999, 0.999], [-0.999, 0.999], -0.999, metal),
    ];
    let mesh = b.add_mesh("room", &prims);
    let camera = (Vec3::new(0.0, 0.3, 0.99), Quat::from_rotation_x(-0.7), 1.0);
    mesh_camera_scene(b, tag, ("room", mesh), camera, None)
}

fn image(o: &FrameOutput) -> Image {
    Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap()
}

/// The mean of the pixels where `mask` is set (RGB summed).
fn masked_mean(o: &FrameOutput, mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (p, &m) in o.pixels.iter().zip(mask) {
        if m {
            sum += f64::from(p[0] + p[1] + p[2]);
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

#[test]
fn pooled_specular_paths_agree_with_the_path_tracer_at_a_fraction_of_the_noise() {
    let scene = plate_room("specular_pool_plate");
    assert!(scene.plan().specular);
    let size = (32u32, 32u32);
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let reference = render(&ctx, &shaders, &scene, &mut gpu, size, 4096, 1);
    let mut frame = |specular_paths| {
        let settings = IcSettings {
            width: size.0,
            height: size.1,
            params: IcParams::default(),
            specular_paths,
            ..IcSettings::default()
        };
        let (out, _) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
        assert_eq!(out.nonfinite_pixels, 0);
        out
    };
    let pooled = frame(SpecularPaths::Pooled);
    let per_pixel = frame(SpecularPaths::PerPixel);
    drop(gpu);
    finish(ctx);

    // The pixels the two frames disagree on are the plate's (every other estimate is the same).
    let mask: Vec<bool> = pooled
        .pixels
        .iter()
        .zip(&per_pixel.pixels)
        .map(|(a, b)| a != b)
        .collect();
    let plate = mask.iter().filter(|&&m| m).count();
    assert!(
        plate >= (size.0 * size.1) as usize / 2,
        "the plate should fill most of the view: {plate} pixels differ"
    );
    let reference_mean = masked_mean(&reference, &mask);
    for (what, out) in [("pooled", &pooled), ("per pixel", &per_pixel)] {
        let ratio = masked_mean(out, &mask) / reference_mean;
        eprintln!("{what}: the plate's mean over the reference's {ratio:.4}");
        assert!(
            (ratio - 1.0).abs() <= 0.02,
            "{what}: plate mean ratio {ratio}"
        );
    }
    let m_pooled = compare(&image(&reference), &image(&pooled)).unwrap();
    let m_per_pixel = compare(&image(&reference), &image(&per_pixel)).unwrap();
    eprintln!("pooled: {m_pooled}\nper pixel: {m_per_pixel}");
    assert!(
        m_pooled.relmse <= 0.5 * m_per_pixel.relmse,
        "pooled relMSE {} against per-pixel {}",
        m_pooled.relmse,
        m_per_pixel.relmse
    );
}
