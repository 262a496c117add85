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
use radcache_render::{
    passes::record::RECORD_FLAG_GLOSSY, passes::record::RECORD_FLAG_NO_SURFACE, render_ic,
    state::RadianceBlock, FrameOutput, GlossyLight, GlossySpacing, GpuScene, IcRenderer,
    IcSettings,
};
use radcache_scene::Scene;
use radcache_shared::consts::{GLOSSY_ROUGHNESS_MIN, RECORD_RADIANCE_VEC4S};
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

/// Records and their radiance blocks after one frame of `scene` at 96² with `spacing` (at 48²
/// the default preset's zones, with κ = 0.75 since 2026-12-05, sit so near their floor R⁻ that
/// a binding glossy limit added no record: 690 records either way).
fn records_with(
    scene: &Scene,
    spacing: GlossySpacing,
) -> (Vec<radcache_shared::gpu::GpuRecord>, Vec<RadianceBlock>) {
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, scene, None).unwrap();
    let settings = IcSettings {
        width: 96,
        height: 96,
        params: IcParams::default(),
        glossy_spacing: spacing,
        ..IcSettings::default()
    };
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &settings).unwrap();
    let (out, _) = r
        .render(&ctx, scene, &mut gpu, &settings, &mut |_| {})
        .unwrap();
    assert_eq!(out.nonfinite_pixels, 0);
    let (records, _, _) = r.state().download(&ctx).unwrap();
    let blocks = r.state().download_radiance(&ctx).unwrap();
    drop((r, gpu));
    finish(ctx);
    (records, blocks)
}

/// Records for glossy lobes (docs/radiance-caching.md §9), flagged `RECORD_FLAG_GLOSSY` (made
/// on a non-Lambertian pixel of roughness ≥ `GLOSSY_ROUGHNESS_MIN`): with `GlossySpacing::Lobe`
/// their radius stays within their glossy gradient limit (which binds on some), there are more of
/// them, and the other records hardly change in number; with `GlossySpacing::Irradiance` the
/// limit is ignored (some exceed it).
#[test]
fn records_for_glossy_lobes_obey_the_glossy_gradient_limit_and_only_they_multiply() {
    let scene = glossy_room();
    let flagged = |r: &radcache_shared::gpu::GpuRecord| r.info[3] & RECORD_FLAG_GLOSSY != 0;
    let valid = |r: &&radcache_shared::gpu::GpuRecord| r.info[3] & RECORD_FLAG_NO_SURFACE == 0;
    let (plain, plain_blocks) = records_with(&scene, GlossySpacing::Irradiance);
    let (lobe, blocks) = records_with(&scene, GlossySpacing::Lobe);
    // Spaced by the irradiance, the glossy limit binds on none of them.
    let stride = RECORD_RADIANCE_VEC4S as usize;
    let below = plain
        .iter()
        .zip(&plain_blocks)
        .filter(|(r, b)| flagged(r) && r.normal_rorig[3] > f32::from_bits(b[stride - 1][0]))
        .count();
    let (mut glossy, mut binding) = (0usize, 0usize);
    for (i, (r, b)) in lobe.iter().zip(&blocks).enumerate() {
        if !flagged(r) {
            continue;
        }
        glossy += 1;
        let limit = f32::from_bits(b[stride - 1][0]);
        let r_orig = r.normal_rorig[3];
        assert!(
            r_orig <= limit * (1.0 + 1e-6),
            "record {i}: R {r_orig} above its glossy limit {limit}"
        );
        binding += usize::from(r_orig >= limit * (1.0 - 1e-6));
    }
    let others = |v: &[radcache_shared::gpu::GpuRecord]| {
        v.iter().filter(valid).filter(|r| !flagged(r)).count()
    };
    eprintln!(
        "records: {} by the irradiance, {} by the lobe ({glossy} for glossy lobes, the limit \
         binding on {binding}; {below} above it by the irradiance); others {} and {}",
        plain.len(),
        lobe.len(),
        others(&plain),
        others(&lobe)
    );
    assert!(
        glossy > 50 && binding > 0,
        "{glossy} glossy, {binding} binding"
    );
    assert!(
        below > 0,
        "the limit would bind on no record spaced by the irradiance"
    );
    assert!(
        lobe.len() > plain.len(),
        "{} vs {}",
        lobe.len(),
        plain.len()
    );
    let (a, b) = (others(&lobe) as f64, others(&plain) as f64);
    assert!((a - b).abs() <= 0.1 * b, "other records: {a} vs {b}");
}
