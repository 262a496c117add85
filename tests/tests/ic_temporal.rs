//! Records kept across frames (`IcRenderer`) on lavapipe: a static scene (with or without
//! radiance records for glossy lobes) renders identical frames without creating records; under camera motion, later frames create few records and
//! the kept ones keep their irradiance and gradients bit for bit (their radius takes the new
//! view's clamp); `forget` rebuilds.

use glam::{Quat, Vec3};
use radcache_cache::radius::{pixel_footprint, radius_bounds};
use radcache_cache::IcParams;
use radcache_render::{GpuScene, IcRenderer, IcSettings, IcStats};
use radcache_scene::writer::{ChannelDesc, GltfBuilder, MaterialDesc, NodeDesc};
use radcache_scene::{AnimationKind, Interpolation, Property, Scene};
use radcache_shared::gpu::GpuRecord;
use radcache_tests::ic_fixture::sequence_settings;
use radcache_tests::scenes::{camera_node, cube, load, plane_y, temp_dir, write_and_load};
use radcache_tests::{context, finish, shaders};
use radcache_vk::Context;

const SIZE: u32 = 48;

/// A floor, a box and an emissive panel above them, under a camera that pans sideways and turns
/// a little over one second, then much further by t = 4 (nothing else moves).
fn camera_only_scene() -> Scene {
    let mut b = GltfBuilder::new();
    let grey = b.add_material(&MaterialDesc::diffuse("grey", [0.6; 3]));
    let red = b.add_material(&MaterialDesc::diffuse("red", [0.7, 0.2, 0.2]));
    let mut light = MaterialDesc::diffuse("light", [0.0; 3]);
    light.emissive = [8.0; 3];
    let light = b.add_material(&light);
    let floor = b.add_mesh("floor", &[plane_y([-3.0, 3.0], [-3.0, 3.0], 0.0, grey)]);
    let boxy = b.add_mesh("box", &[cube(0.5, red)]);
    let panel = b.add_mesh("panel", &[plane_y([-0.8, 0.8], [-0.8, 0.8], 0.0, light)]);
    let floor = b.add_node(&NodeDesc {
        mesh: Some(floor),
        ..Default::default()
    });
    let boxy = b.add_node(&NodeDesc {
        mesh: Some(boxy),
        translation: Some([0.3, 0.5, -0.2]),
        ..Default::default()
    });
    // Upside down, 2.5 above the floor: the panel faces down.
    let panel = b.add_node(&NodeDesc {
        mesh: Some(panel),
        translation: Some([0.0, 2.5, 0.0]),
        rotation: Some(Quat::from_rotation_x(std::f32::consts::PI).to_array()),
        ..Default::default()
    });
    let look = Quat::from_rotation_x(-0.5);
    let camera = camera_node(&mut b, Vec3::new(0.0, 2.2, 4.0), look, 0.9);
    let turned = (Quat::from_rotation_y(0.08) * look).normalize();
    let away = (Quat::from_rotation_y(0.9) * look).normalize();
    b.add_animation(
        "pan",
        &[
            ChannelDesc {
                node: camera,
                property: Property::Translation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 1.0, 4.0],
                values: vec![0.0, 2.2, 4.0, 0.6, 2.2, 4.0, 3.0, 2.2, 3.0],
            },
            ChannelDesc {
                node: camera,
                property: Property::Rotation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 1.0, 4.0],
                values: [look, turned, away]
                    .iter()
                    .flat_map(|q| q.to_array())
                    .collect(),
            },
        ],
    );
    b.add_scene("pan", &[floor, boxy, panel, camera], None);
    write_and_load(&b, &temp_dir("ic-temporal"), "pan")
}

fn settings(time: f32, frame: u32) -> IcSettings {
    sequence_settings(SIZE, time, frame)
}

fn frame(
    ctx: &Context,
    scene: &Scene,
    gpu: &mut GpuScene,
    r: &mut IcRenderer,
    time: f32,
    n: u32,
) -> (Vec<[f32; 3]>, IcStats) {
    let (out, stats) = r
        .render(ctx, scene, gpu, &settings(time, n), &mut |_| {})
        .unwrap();
    assert_eq!(out.nonfinite_pixels, 0);
    (out.pixels, stats)
}

/// Equal up to float round-off.
fn assert_close(a: &[[f32; 3]], b: &[[f32; 3]]) {
    assert_eq!(a.len(), b.len());
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        for c in 0..3 {
            let tol = 1e-5 * x[c].abs().max(1e-3);
            assert!((x[c] - y[c]).abs() <= tol, "pixel {k}: {x:?} vs {y:?}");
        }
    }
}

fn created(s: &IcStats) -> u64 {
    s.records_per_level.iter().sum()
}

fn records(ctx: &Context, r: &IcRenderer, n: u64) -> Vec<GpuRecord> {
    ctx.read_buffer(&r.state().records, n as usize).unwrap()
}

/// A bundled scene by name (`assets/<name>/<name>.gltf`).
fn bundled(name: &str) -> Scene {
    load(
        &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join(format!("../assets/{name}/{name}.gltf")),
    )
}

/// Frames 2 and 3 of static `scene` create no record and equal frame 1 bit for bit; after
/// `forget` the rebuilt cache gives frame 1 again up to round-off. Returns the records.
fn static_frames_are_identical(scene: &Scene) -> u64 {
    assert_eq!(scene.plan().animation.kind, AnimationKind::None);
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, scene, None).unwrap();
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &settings(0.0, 1)).unwrap();
    let (first, s1) = frame(&ctx, scene, &mut gpu, &mut r, 0.0, 1);
    assert!(created(&s1) > 50 && s1.records_kept == 0, "{s1:?}");
    for n in 2..=3 {
        let (image, s) = frame(&ctx, scene, &mut gpu, &mut r, 0.0, n);
        assert_eq!(created(&s), 0, "frame {n}: {s:?}");
        assert_eq!(s.records_kept, s1.records);
        assert!(image == first, "frame {n} differs from frame 1");
    }
    // Without the kept records the cache is rebuilt from scratch, to the same image up to float
    // round-off (records are created in the order GPU atomics hand out, which sets the order of
    // the splat's additions).
    r.forget();
    let (rebuilt, s) = frame(&ctx, scene, &mut gpu, &mut r, 0.0, 4);
    assert_eq!((s.records_kept, created(&s)), (0, s1.records));
    assert_close(&rebuilt, &first);
    drop((r, gpu));
    finish(ctx);
    s1.records
}

#[test]
fn a_static_scene_renders_identical_frames_from_kept_records() {
    static_frames_are_identical(&bundled("cornell"));
}

/// The glossy lobes of kept radiance records (docs/radiance-caching.md §8): their blocks stay
/// with the records, so the frames of a static glossy scene are identical too.
#[test]
fn a_static_glossy_scene_renders_identical_frames_from_kept_radiance_records() {
    let scene = bundled("glossy_room");
    assert!(scene.plan().radiance_cache(), "{}", scene.plan());
    static_frames_are_identical(&scene);
}

#[test]
fn camera_motion_reuses_records_unchanged() {
    let scene = camera_only_scene();
    assert_eq!(scene.plan().animation.kind, AnimationKind::CameraOnly);
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &settings(0.0, 1)).unwrap();
    let (_, s1) = frame(&ctx, &scene, &mut gpu, &mut r, 0.0, 1);
    let before = records(&ctx, &r, s1.records);
    let (_, s2) = frame(&ctx, &scene, &mut gpu, &mut r, 1.0 / 24.0, 2);
    let after = records(&ctx, &r, s2.records);
    eprintln!(
        "frame 1: {} records; frame 2: {} kept, {} created",
        s1.records,
        s2.records_kept,
        created(&s2)
    );
    assert!(s1.records > 100, "{s1:?}");
    assert_eq!(s2.records_kept, s1.records);
    // One frame of a slow pan uncovers a thin strip: a small fraction of frame 1's records.
    assert!(
        created(&s2) * 5 <= s1.records,
        "frame 2 created {} records, frame 1 {}",
        created(&s2),
        s1.records
    );
    for (k, (a, b)) in before.iter().zip(&after).enumerate() {
        let same = a.position_radius[..3] == b.position_radius[..3]
            && a.normal_rorig[..3] == b.normal_rorig[..3]
            && a.irradiance[..3] == b.irradiance[..3]
            && [a.grad_r_red, a.grad_r_green, a.grad_r_blue]
                == [b.grad_r_red, b.grad_r_green, b.grad_r_blue]
            && [a.grad_t_red, a.grad_t_green, a.grad_t_blue]
                == [b.grad_t_red, b.grad_t_green, b.grad_t_blue];
        assert!(same, "record {k} changed: {a:?} -> {b:?}");
        // Only a new neighbour may shrink a kept record's unclamped radius; the radius used
        // takes the [R⁻, R⁺] clamp of the new view (the gradient attenuation in irradiance.w
        // follows it).
        assert!(b.normal_rorig[3] <= a.normal_rorig[3]);
        let (lo, hi, used) = (b.bounds[0], b.bounds[1], b.position_radius[3]);
        assert!(
            lo <= used && used <= hi,
            "record {k}: {used} outside [{lo}, {hi}]"
        );
        // The clamp is the one of the pixel footprint at the record's point in frame 2's view
        // (radcache_cache::radius, the CPU twin of the shader's functions).
        let view = scene.camera_at(1.0 / 24.0);
        let p = Vec3::from_slice(&b.position_radius[..3]);
        let depth = view.view_from_world().transform_point3(p).z.abs();
        let ng = Vec3::new(b.grad_r_red[3], b.grad_r_green[3], b.grad_r_blue[3]);
        let cos_view = ng.dot((view.position - p).normalize());
        let tan = (view.perspective.yfov * 0.5).tan();
        let f = pixel_footprint(depth, tan, SIZE as f32, cos_view);
        let p = IcParams::draft();
        let (lo_cpu, hi_cpu) =
            radius_bounds(f, p.min_spacing_px, p.max_spacing_px, p.validity_scale());
        assert!(
            (lo - lo_cpu).abs() <= 1e-4 * lo_cpu,
            "record {k}: R⁻ {lo} vs {lo_cpu}"
        );
        assert!(
            (hi - hi_cpu).abs() <= 1e-4 * hi_cpu,
            "record {k}: R⁺ {hi} vs {hi_cpu}"
        );
    }
    drop((r, gpu));
    finish(ctx);
}

#[test]
fn records_out_of_use_are_evicted() {
    let scene = camera_only_scene();
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let evicting = |time, n| IcSettings {
        evict_after_frames: 1,
        ..settings(time, n)
    };
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &evicting(0.0, 1)).unwrap();
    let render = |r: &mut IcRenderer, gpu: &mut GpuScene, time, n| {
        let (out, stats) = r
            .render(&ctx, &scene, gpu, &evicting(time, n), &mut |_| {})
            .unwrap();
        assert_eq!(
            (out.nonfinite_pixels, stats.holes_left),
            (0, 0),
            "{stats:?}"
        );
        (out.pixels, stats)
    };
    let (_, s1) = render(&mut r, &mut gpu, 0.0, 1);
    // The end of the pan: much of the first view is out of sight, its records unused.
    let (second, s2) = render(&mut r, &mut gpu, 4.0, 2);
    assert_eq!(s2.records_evicted, 0, "used in frame 1");
    let (third, s3) = render(&mut r, &mut gpu, 4.0, 3);
    eprintln!(
        "records: {} → {} (+{}), evicted {} → {}",
        s1.records,
        s2.records,
        created(&s2),
        s3.records_evicted,
        s3.records
    );
    assert!(s3.records_evicted * 10 > s1.records, "{s3:?}");
    assert_eq!(s3.records, s2.records - s3.records_evicted);
    assert_eq!(
        created(&s3),
        0,
        "evicted records weighed nowhere in this view"
    );
    // Same records in the view (in another order, so sums may differ in the last bits).
    assert_close(&second, &third);
    drop((r, gpu));
    finish(ctx);
}
