//! Radiance records for glossy lobes (issue 18, docs/radiance-caching.md §6), on lavapipe: the
//! bundled `glossy_room` (the Cornell room with a rough gold metal sphere of roughness 0.7, a
//! blue plastic sphere of 0.8, a white metal sphere of 0.4 — below the records' threshold, so
//! path traced per pixel — and a glossy metal floor plate of 0.65), rendered with the cache frame
//! (the rough lobes' indirect light from the radiance records) against the path tracer; and the
//! same frame with the records' coefficients held constant over their zones
//! (`GlossyLight::RecordsWithoutGradients`) and with the per-pixel specular paths
//! (`GlossyLight::Paths`) against it.

use radcache_cache::IcParams;
use radcache_image::{compare, Image};
use radcache_render::{render_ic, FrameOutput, GlossyLight, GpuScene, IcSettings};
use radcache_scene::Scene;
use radcache_shared::consts::GLOSSY_ROUGHNESS_MIN;
use radcache_tests::scenes::{load, render};
use radcache_tests::{context, finish, shaders};

fn glossy_room() -> Scene {
    load(
        &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/glossy_room/glossy_room.gltf"),
    )
}

fn image(o: &FrameOutput) -> Image {
    Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap()
}

#[test]
fn glossy_lobes_from_radiance_records_match_the_path_tracer() {
    let scene = glossy_room();
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
    let methods = [
        GlossyLight::Records,
        GlossyLight::RecordsWithoutGradients,
        GlossyLight::Paths,
    ];
    for glossy in methods {
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
