//! The path tracer's float accumulation stays exact over 10⁵ samples per pixel.
//!
//! The camera sees only a constant sky of radiance 0.1 (not representable in binary floating
//! point), so every sample returns the same f32 value. A naive f32 running sum of 10⁵ such values
//! drifts by ~10⁻⁴ relative; the Kahan-compensated accumulator must give 0.1 to within a few ulps.

use radcache_render::{render_path, Budget, GpuScene, PathSettings};
use radcache_scene::writer::{BufferLayout, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{LoadOptions, Scene};
use radcache_tests::{context, finish, shaders};

const SKY: f32 = 0.1;
const SPP: u32 = 100_000;

fn sky_scene(dir: &std::path::Path) -> std::path::PathBuf {
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::diffuse("grey", [0.5; 3]));
    // One small triangle behind the camera: the TLAS is not empty, the view sees only sky.
    let mesh = b.add_mesh(
        "behind",
        &[PrimitiveDesc::triangles(
            vec![[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]],
            None,
            vec![0, 1, 2],
            Some(mat),
        )],
    );
    let cam = b.add_perspective_camera("cam", 0.5, Some(1.0), 0.1, None);
    let mesh_node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let cam_node = b.add_node(&NodeDesc {
        camera: Some(cam),
        ..NodeDesc::default()
    });
    let extras = serde_json::json!({"environment": {"radiance": [SKY, SKY, SKY]}});
    b.add_scene("sky", &[mesh_node, cam_node], Some(extras));
    let path = dir.join("sky.gltf");
    b.write(&path, BufferLayout::Embedded).unwrap();
    path
}

#[test]
fn hundred_thousand_samples_accumulate_exactly() {
    let dir = std::env::temp_dir().join(format!("radcache-accum-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (scene, _) = Scene::load(&sky_scene(&dir), &LoadOptions::default()).unwrap();
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let settings = PathSettings {
        width: 8,
        height: 8,
        budget: Budget::Samples(SPP),
        chunk_target_ms: 1000.0,
        ..PathSettings::default()
    };
    let out = render_path(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(out.spp, SPP);
    // Every pixel sample is one camera ray that misses.
    assert_eq!(out.rays["path_trace"], 64 * u64::from(SPP));
    for (i, p) in out.pixels.iter().enumerate() {
        for c in p {
            let rel = (f64::from(*c) - f64::from(SKY)).abs() / f64::from(SKY);
            assert!(
                rel < 1e-6,
                "pixel {i}: {c} after {SPP} samples (relative error {rel:e})"
            );
        }
    }
    // The naive sum would not pass: show the test can fail.
    let mut naive = 0.0f32;
    for _ in 0..SPP {
        naive += SKY;
    }
    let naive_rel = (f64::from(naive / SPP as f32) - f64::from(SKY)).abs() / f64::from(SKY);
    assert!(naive_rel > 1e-5, "{naive_rel:e}");
    drop(gpu);
    finish(ctx);
}
