//! The cache's box-filtered emission (`shaders/passes/emission.comp`) against exact pixel
//! coverage: a black emitting rectangle seen straight from above, alone in an empty scene, so a
//! pixel's value is exactly (covered fraction) × Le. The rectangle's edges are axis-aligned and
//! placed at known sub-pixel positions; a pixel's 64 rays must resolve its coverage to 1/64 (a
//! plain 8 × 8 grid of rays resolves an axis-aligned edge only to 1/8, and was 0.06 off here).

use glam::{Quat, Vec3};
use radcache_cache::IcParams;
use radcache_render::{render_ic, GpuScene, IcSettings};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc};
use radcache_tests::scenes::{
    camera_node, convex_hull, ndc_to_pixel, pixel_coverage, pixel_to_ndc, plane_y, temp_dir,
    write_and_load, Coverage,
};
use radcache_tests::{context, finish, shaders};

const SIZE: u32 = 48;
const HEIGHT: f32 = 3.0;
const YFOV: f32 = 0.8;
const LE: [f32; 3] = [3.0, 2.0, 1.0];
/// Left, right, top and bottom edges of the emitter in the image, in pixels (fractions where an
/// 8 × 8 grid of rays is far off: 0.19 and 0.81 read as 0.25 and 0.75).
const EDGES_PX: [f64; 4] = [10.19, 37.69, 8.31, 39.81];

/// The scene: the black emitter `[x0, x1] × [z0, z1]` on the plane y = 0 and a camera at height
/// `HEIGHT` looking straight down.
fn emitter_scene(x: [f32; 2], z: [f32; 2]) -> radcache_scene::Scene {
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::emitter("light", [0.0; 3], LE));
    let mesh = b.add_mesh("light", &[plane_y(x, z, 0.0, mat)]);
    let light = b.add_node(&NodeDesc {
        name: Some("light".into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let look_down = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    let camera = camera_node(&mut b, Vec3::new(0.0, HEIGHT, 0.0), look_down, YFOV);
    b.add_scene("scene", &[light, camera], None);
    write_and_load(&b, &temp_dir("ic-emission"), "emitter")
}

#[test]
fn emitter_edges_are_box_filtered_to_a_sixty_fourth_of_a_pixel() {
    // Place the rectangle (through the camera of a first scene) where its edges land on EDGES_PX.
    let view = emitter_scene([-1.0, 1.0], [-1.0, 1.0]).camera_at(0.0);
    let ground = |px: f64, py: f64| {
        let (x, y) = pixel_to_ndc(px, py, SIZE, SIZE);
        let dir = view.ray_direction(x, y, 1.0);
        view.position + dir * (-view.position.y / dir.y)
    };
    let [left, right, top, bottom] = EDGES_PX;
    let (a, c) = (ground(left, top), ground(right, bottom));
    let scene = emitter_scene([a.x.min(c.x), a.x.max(c.x)], [a.z.min(c.z), a.z.max(c.z)]);

    // The outline as the renderer's camera projects it: the edges are where they were asked for.
    let view = scene.camera_at(0.0);
    let outline: Vec<(f64, f64)> = [(a.x, a.z), (a.x, c.z), (c.x, c.z), (c.x, a.z)]
        .iter()
        .map(|&(x, z)| {
            let ndc = view.project(Vec3::new(x, 0.0, z), 1.0).unwrap();
            ndc_to_pixel(ndc.x, ndc.y, SIZE, SIZE)
        })
        .collect();
    let outline = convex_hull(&outline);
    for &(x, y) in &outline {
        let near = |v: f64, edges: [f64; 2]| edges.iter().any(|e| (v - e).abs() < 1e-3);
        assert!(
            near(x, [left, right]) && near(y, [top, bottom]),
            "corner ({x}, {y}) is not on the edges {EDGES_PX:?}"
        );
    }

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let settings = IcSettings {
        width: SIZE,
        height: SIZE,
        params: IcParams::draft(),
        sub_frames: 2,
        direct_samples: 1,
        ..IcSettings::default()
    };
    let (out, _) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    drop(gpu);
    finish(ctx);

    let (mut inside, mut partial, mut worst) = (0, 0, 0.0f64);
    for py in 0..SIZE {
        for px in 0..SIZE {
            let got = out.pixels[(py * SIZE + px) as usize];
            let expected = match pixel_coverage(&outline, px, py, 1e-3) {
                Coverage::Inside => {
                    inside += 1;
                    1.0
                }
                Coverage::Outside => 0.0,
                Coverage::Partial(f) => {
                    partial += 1;
                    f
                }
            };
            for c in 0..3 {
                let fraction = f64::from(got[c]) / f64::from(LE[c]);
                let error = (fraction - expected).abs();
                worst = worst.max(error);
                assert!(
                    error <= 1.0 / 64.0 + 1e-3,
                    "pixel ({px}, {py}) channel {c}: {} = {fraction} × Le, covered {expected}",
                    got[c]
                );
            }
        }
    }
    eprintln!("{inside} inside, {partial} edge pixels; largest coverage error {worst:.4}");
    assert!(
        inside > 500 && partial > 100,
        "{inside} inside, {partial} partial"
    );
}
