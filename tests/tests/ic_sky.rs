//! The sky through the records (`SkyLight`, docs/cache-frame.md §8.3) on lavapipe: the Cornell box
//! opened to a constant sky renders the same with the sky's light gathered by the records as with
//! it sampled by the direct pass, and both match the path tracer; records made with the sky in
//! them are refused by a renderer that samples it directly.

use std::path::PathBuf;

use radcache_cache::IcParams;
use radcache_image::{compare, Image, Metrics};
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcRenderer, IcSettings};
use radcache_render::{PathSettings, SkyLight};
use radcache_scene::{EnvOverride, LoadOptions, Scene};
use radcache_tests::{context, finish, shaders};

const SIZE: u32 = 32;
const SKY: [f32; 3] = [0.6, 0.5, 0.4];

/// The Cornell box under a constant sky, which lights its inside through the open side.
fn open_box() -> Scene {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/cornell/cornell.gltf"
    ));
    let options = LoadOptions {
        env: EnvOverride {
            radiance: Some(SKY),
            ..EnvOverride::default()
        },
        ..LoadOptions::default()
    };
    Scene::load(&path, &options).unwrap().0
}

fn settings(sky: SkyLight) -> IcSettings {
    IcSettings {
        width: SIZE,
        height: SIZE,
        params: IcParams::draft(),
        sub_frames: 2,
        direct_samples: 8,
        sky,
        ..IcSettings::default()
    }
}

fn image(width: u32, height: u32, pixels: Vec<[f32; 3]>) -> Image {
    Image::from_pixels(width, height, pixels).unwrap()
}

#[test]
fn the_sky_through_the_records_matches_the_path_tracer() {
    let scene = open_box();
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    assert!(gpu.has_constant_environment());
    let path = PathSettings {
        width: SIZE,
        height: SIZE,
        budget: Budget::Samples(512),
        ..PathSettings::default()
    };
    let reference = render_path(&ctx, &shaders, &scene, &mut gpu, &path, &mut |_| {}).unwrap();
    let reference = image(SIZE, SIZE, reference.pixels);
    let mut metrics: Vec<(SkyLight, Metrics)> = Vec::new();
    for sky in [SkyLight::Direct, SkyLight::Records] {
        let (out, stats) = render_ic(
            &ctx,
            &shaders,
            &scene,
            &mut gpu,
            &settings(sky),
            &mut |_| {},
        )
        .unwrap();
        assert!(
            stats.records > 0 && stats.rejected_records == 0,
            "{stats:?}"
        );
        let m = compare(&reference, &image(out.width, out.height, out.pixels)).unwrap();
        eprintln!("sky {sky:?}: {m}");
        assert_eq!(m.nonfinite_candidate, 0);
        for (c, r) in m.mean_ratio.iter().enumerate() {
            assert!(
                (r - 1.0).abs() <= 0.03,
                "sky {sky:?}: channel {c} mean ratio {r}"
            );
        }
        metrics.push((sky, m));
    }
    // The records' interpolation of the sky's smooth irradiance costs no more than sampling it
    // at every pixel (the reference's own noise is in both figures).
    let (direct, records) = (&metrics[0].1, &metrics[1].1);
    assert!(
        records.relmse <= 1.5 * direct.relmse,
        "relMSE with the sky in the records {:e}, sampled directly {:e}",
        records.relmse,
        direct.relmse
    );
    drop(gpu);
    finish(ctx);
}

#[test]
fn records_holding_the_sky_are_refused_where_the_sky_is_sampled() {
    let scene = open_box();
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut with_sky = IcRenderer::new(&ctx, &shaders, &gpu, &settings(SkyLight::Records)).unwrap();
    with_sky
        .render(
            &ctx,
            &scene,
            &mut gpu,
            &settings(SkyLight::Records),
            &mut |_| {},
        )
        .unwrap();
    let cache = with_sky.export_cache(&ctx).unwrap();
    assert!(cache.sky && !cache.records.is_empty());
    let mut sampled = IcRenderer::new(&ctx, &shaders, &gpu, &settings(SkyLight::Direct)).unwrap();
    let err = sampled
        .import_cache(&ctx, &shaders, &gpu, &cache)
        .unwrap_err()
        .to_string();
    assert!(err.contains("sky"), "{err}");
    // A renderer that also takes the sky from the records accepts them.
    let mut same = IcRenderer::new(&ctx, &shaders, &gpu, &settings(SkyLight::Records)).unwrap();
    same.import_cache(&ctx, &shaders, &gpu, &cache).unwrap();
    drop((with_sky, sampled, same, gpu));
    finish(ctx);
}
