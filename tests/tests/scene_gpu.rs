//! The TLAS built from `GpuScene` places every instance where the CPU's animation evaluation
//! (`Scene::instance_transforms(t)`) puts it, at the first build, after refits and after the
//! periodic rebuild.
//!
//! The scene: black cubes (one animated in translation and rotation with a child cube riding on
//! it, one static) in front of a constant white sky. With the path tracer, a camera sample that
//! hits a cube returns exactly 0 (black, no light source other than the sky) and one that misses
//! returns exactly 1. The CPU projects each cube's transformed vertices into the image (convex
//! hull = silhouette) and predicts every pixel: fully covered → 0, fully uncovered → 1, on the
//! outline → 1 − covered area fraction, up to the binomial noise of the jittered samples.

use glam::{Quat, Vec3};
use radcache_render::{render_path, scene::REFITS_PER_REBUILD, Budget, GpuScene, PathSettings};
use radcache_scene::writer::{ChannelDesc, GltfBuilder, MaterialDesc, NodeDesc};
use radcache_scene::{Interpolation, Property, Scene};
use radcache_tests::scenes::{
    camera_node, clip_convex, convex_hull, cube, inside_margin, ndc_to_pixel, pixel_square,
    separation, signed_area, temp_dir, write_and_load, Polygon,
};
use radcache_tests::{context, finish, shaders};

const SIZE: (u32, u32) = (32, 32);
const SPP: u32 = 8;
/// Margin (pixels) for the exact inside/outside classes: far above f32 round-off of projected
/// vertices (~1e-5 px here), far below a pixel.
const EPS: f64 = 1e-3;

fn animated_scene() -> Scene {
    let mut b = GltfBuilder::new();
    let black = b.add_material(&MaterialDesc::diffuse("black", [0.0; 3]));
    let mover_mesh = b.add_mesh("mover", &[cube(0.5, black)]);
    let rider_mesh = b.add_mesh("rider", &[cube(0.2, black)]);
    let post_mesh = b.add_mesh("post", &[cube(0.3, black)]);
    let rider = b.add_node(&NodeDesc {
        name: Some("rider".into()),
        translation: Some([0.0, 0.0, 1.1]),
        mesh: Some(rider_mesh),
        ..NodeDesc::default()
    });
    let mover = b.add_node(&NodeDesc {
        name: Some("mover".into()),
        translation: Some([-1.2, -0.6, 0.0]),
        mesh: Some(mover_mesh),
        children: vec![rider],
        ..NodeDesc::default()
    });
    let post = b.add_node(&NodeDesc {
        name: Some("post".into()),
        translation: Some([-1.6, 1.5, -1.0]),
        mesh: Some(post_mesh),
        ..NodeDesc::default()
    });
    let camera = camera_node(&mut b, Vec3::new(0.0, 0.0, 6.0), Quat::IDENTITY, 0.9);
    let rotations = [
        Quat::IDENTITY,
        Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 100f32.to_radians()),
        Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), 200f32.to_radians()),
    ];
    b.add_animation(
        "move",
        &[
            ChannelDesc {
                node: mover,
                property: Property::Translation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 2.0, 4.0],
                values: vec![-1.2, -0.6, 0.0, 0.3, 0.5, -1.0, 1.2, -0.3, 0.5],
            },
            ChannelDesc {
                node: mover,
                property: Property::Rotation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 2.0, 4.0],
                values: rotations.iter().flat_map(|q| q.to_array()).collect(),
            },
        ],
    );
    let extras = serde_json::json!({"environment": {"radiance": [1.0, 1.0, 1.0]}});
    b.add_scene("animated", &[mover, post, camera], Some(extras));
    write_and_load(&b, &temp_dir("scene-gpu"), "animated")
}

/// Image-space silhouettes (convex hulls of the projected, CPU-transformed vertices) of every
/// instance at time `t`.
fn silhouettes(scene: &Scene, t: f32) -> Vec<Polygon> {
    let view = scene.camera_at(t);
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let transforms = scene.instance_transforms(t);
    scene
        .instances
        .iter()
        .zip(&transforms)
        .map(|(inst, m)| {
            let points: Vec<(f64, f64)> = scene.meshes[inst.mesh]
                .positions
                .iter()
                .map(|&p| {
                    let ndc = view
                        .project(m.transform_point3(p), aspect)
                        .expect("vertex in front of the camera");
                    ndc_to_pixel(ndc.x, ndc.y, SIZE.0, SIZE.1)
                })
                .collect();
            convex_hull(&points)
        })
        .collect()
}

/// What the CPU predicts for one pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    /// Every sample hits a cube: exactly 0.
    Covered,
    /// Every sample sees the sky: exactly 1.
    Sky,
    /// This fraction of the pixel's area is covered.
    Edge(f64),
}

fn predict(sils: &[Polygon], x: u32, y: u32) -> Expect {
    let square = pixel_square(x, y);
    if sils
        .iter()
        .any(|s| square.iter().all(|&c| inside_margin(s, c) > EPS))
    {
        return Expect::Covered;
    }
    if sils.iter().all(|s| separation(s, &square) > EPS) {
        return Expect::Sky;
    }
    // Area of square ∩ (union of silhouettes), by inclusion–exclusion over the (convex)
    // intersections.
    let n = sils.len();
    let mut area = 0.0;
    for subset in 1u32..(1 << n) {
        let mut region = square.clone();
        for (i, s) in sils.iter().enumerate() {
            if subset & (1 << i) != 0 {
                region = clip_convex(&region, s);
            }
        }
        let sign = if subset.count_ones() % 2 == 1 {
            1.0
        } else {
            -1.0
        };
        area += sign * signed_area(&region).max(0.0);
    }
    Expect::Edge(area.clamp(0.0, 1.0))
}

#[test]
fn tlas_follows_the_cpu_transforms_through_refits_and_rebuilds() {
    let scene = animated_scene();
    assert_eq!(scene.instances.len(), 3);
    assert_eq!(
        scene.instances.iter().filter(|i| i.dynamic).count(),
        2,
        "the mover and its rider move, the post does not"
    );
    // Distinct times in the animation's range, far apart from one render to the next (golden-ratio
    // steps modulo 4 s). The first render builds the TLAS; the next REFITS_PER_REBUILD refit it,
    // the one after rebuilds, and the rest refit again.
    let renders = REFITS_PER_REBUILD as usize + 4;
    let times: Vec<f32> = (0..renders)
        .map(|k| (0.1 + k as f32 * 1.618_034) % 4.0)
        .collect();

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut images = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let settings = PathSettings {
            width: SIZE.0,
            height: SIZE.1,
            budget: Budget::Samples(SPP),
            seed: k as u32,
            time: t,
            ..PathSettings::default()
        };
        let out = render_path(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
        assert!(
            out.passes_ms.contains_key("accel.tlas_build"),
            "render {k} at t = {t} did not update the TLAS"
        );
        images.push(out.pixels);
    }
    drop(gpu);
    finish(ctx);

    let mut previous: Option<Vec<Expect>> = None;
    for (k, (&t, pixels)) in times.iter().zip(&images).enumerate() {
        let sils = silhouettes(&scene, t);
        let expect: Vec<Expect> = (0..SIZE.1)
            .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
            .map(|(x, y)| predict(&sils, x, y))
            .collect();
        let (mut covered, mut sky, mut edge) = (0, 0, 0);
        for (i, (e, p)) in expect.iter().zip(pixels).enumerate() {
            let (x, y) = (i as u32 % SIZE.0, i as u32 / SIZE.0);
            let what = format!("render {k} (t = {t}), pixel ({x}, {y})");
            assert!(
                p[0] == p[1] && p[1] == p[2],
                "{what}: grey scene gave {p:?}"
            );
            let v = f64::from(p[0]);
            match *e {
                Expect::Covered => {
                    covered += 1;
                    assert!(v == 0.0, "{what}: covered by a cube but {v}");
                }
                Expect::Sky => {
                    sky += 1;
                    assert!((v - 1.0).abs() < 1e-6, "{what}: sky only but {v}");
                }
                Expect::Edge(f) => {
                    edge += 1;
                    // Each sample is 0 or 1; the fraction of hits is binomial with mean f. Allow
                    // 5σ plus one sample (discreteness).
                    let tol = 5.0 * (f * (1.0 - f) / f64::from(SPP)).sqrt() + 1.0 / f64::from(SPP);
                    assert!(
                        ((1.0 - v) - f).abs() <= tol,
                        "{what}: covered fraction {} but the outline covers {f}",
                        1.0 - v
                    );
                }
            }
        }
        assert!(
            covered >= 20 && sky >= 200,
            "render {k}: the view shows too little ({covered} covered, {sky} sky, {edge} edge)"
        );
        eprintln!("render {k} (t = {t:.3}): {covered} covered, {sky} sky, {edge} edge pixels");
        // A TLAS left at the previous time would fail here: enough pixels swap between covered
        // and sky from one render to the next.
        if let Some(prev) = &previous {
            let swapped = expect
                .iter()
                .zip(prev)
                .filter(|(a, b)| {
                    matches!(
                        (a, b),
                        (Expect::Covered, Expect::Sky) | (Expect::Sky, Expect::Covered)
                    )
                })
                .count();
            assert!(
                swapped >= 10,
                "render {k}: only {swapped} pixels change between t = {} and t = {t}",
                times[k - 1]
            );
        }
        previous = Some(expect);
    }
}
