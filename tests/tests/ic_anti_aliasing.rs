//! Adaptive anti-aliasing of cache frames (docs/cache-frame.md §7.1, §7.2) on lavapipe: the
//! estimate of the sub-frame sampling error against that error (an upper bound within 4×), the
//! frame going on until its target, and per pixel: converged pixels stop and the image still
//! meets the target.

use std::path::PathBuf;

use radcache_cache::IcParams;
use radcache_image::{compare, Image};
use radcache_render::{render_ic, AntiAliasing, FrameOutput, GpuScene, IcSettings, IcStats};
use radcache_scene::{LoadOptions, Scene};
use radcache_tests::{context, finish, shaders};

fn image(out: &FrameOutput) -> Image {
    Image::from_pixels(out.width, out.height, out.pixels.clone()).unwrap()
}

#[test]
fn the_estimate_bounds_the_sampling_error_and_the_frame_goes_on_to_its_target() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let path = root.join("assets/cornell/cornell.gltf");
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap().0;
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let render = |gpu: &mut GpuScene, aa: AntiAliasing| -> (FrameOutput, IcStats) {
        let settings = IcSettings {
            width: 48,
            height: 48,
            params: IcParams::draft(),
            sub_frames: 8,
            direct_samples: 4,
            anti_aliasing: Some(aa),
            ..IcSettings::default()
        };
        render_ic(&ctx, &shaders, &scene, gpu, &settings, &mut |_| {}).unwrap()
    };
    // A target no frame misses: the cache's 8 sub-frames, with the estimate.
    let stop = AntiAliasing {
        target: 1.0,
        max_sub_frames: 64,
        per_pixel: false,
    };
    let (out8, stats8) = render(&mut gpu, stop);
    assert_eq!((stats8.sub_frames_shaded, out8.spp), (8, 8));
    let est8 = stats8.aa_relmse_estimate.unwrap();
    // A target no frame reaches: all 64 sub-frames.
    let all = AntiAliasing {
        target: 1e-12,
        max_sub_frames: 64,
        per_pixel: false,
    };
    let (out64, stats64) = render(&mut gpu, all);
    assert_eq!((stats64.sub_frames_shaded, out64.spp), (64, 64));
    let est64 = stats64.aa_relmse_estimate.unwrap();
    // The same cache phase gives the same records; the 64 sub-frames include the 8 and, the
    // jitters being a low-discrepancy sequence, converge much faster, so the relMSE of the 8
    // against the 64 is about the 8's own sampling error. The estimate assumes independent
    // samples (σ²/n): it must not fall below that error (a frame would stop too early) and
    // overestimates the jitters' part (docs/cache-frame.md §7.1: 4.5× here, the antithetic pairs
    // of jitters cancelling what it counts as independent).
    assert_eq!(stats8.records, stats64.records);
    let m = compare(&image(&out64), &image(&out8)).unwrap();
    eprintln!(
        "estimate at 8: {est8:.3e}, at 64: {est64:.3e}; relMSE(8 vs 64) {:.3e}",
        m.relmse
    );
    assert!(est8 > 1e-4, "the box at 48² has edges: {est8}");
    let ratio = est8 / m.relmse;
    assert!((1.0..6.0).contains(&ratio), "estimate / error = {ratio}");
    // 1/n: eight times the sub-frames, about an eighth of the estimate.
    let fall = est8 / est64;
    assert!((5.0..11.0).contains(&fall), "estimate fell {fall}×");
    // A target between: more sub-frames than 8, stopping at or below the target.
    let target = est8 / 3.0;
    let (out, stats) = render(
        &mut gpu,
        AntiAliasing {
            target,
            max_sub_frames: 64,
            per_pixel: false,
        },
    );
    let n = stats.sub_frames_shaded;
    let est = stats.aa_relmse_estimate.unwrap();
    eprintln!("target {target:.3e}: {n} sub-frames, estimate {est:.3e}");
    assert!(
        n > 8 && n < 64 && est <= target,
        "{n} sub-frames, {est} against {target}"
    );
    assert_eq!(out.spp, n);
    assert!(out.pixels.iter().flatten().all(|c| c.is_finite()));
    // Per pixel (§7.2), the same target: the added sub-frames shade only the pixels that need
    // them. Flat pixels stop at 8, so the mean count stays well below the sub-frames shaded.
    let per_pixel = AntiAliasing {
        target,
        max_sub_frames: 64,
        per_pixel: true,
    };
    let (outp, statsp) = render(&mut gpu, per_pixel);
    let (np, estp) = (statsp.sub_frames_shaded, statsp.aa_relmse_estimate.unwrap());
    let mean = statsp.mean_pixel_sub_frames;
    eprintln!("per pixel: {np} sub-frames, {mean:.1} per pixel, estimate {estp:.3e}");
    assert!(
        np > 8 && estp <= target,
        "{np} sub-frames, {estp} against {target}"
    );
    assert!(
        mean > 8.0 && mean < 0.8 * f64::from(np),
        "{mean} sub-frames per pixel of {np}"
    );
    // Each pixel's mean is over its own sub-frames: against the 64 sub-frames the image's error
    // is within the target (the estimate overestimates the jitters' part).
    let m = compare(&image(&out64), &image(&outp)).unwrap();
    eprintln!("per pixel against 64 sub-frames: relMSE {:.3e}", m.relmse);
    assert!(m.relmse <= target, "relMSE {} against {target}", m.relmse);
    assert!(outp.pixels.iter().flatten().all(|c| c.is_finite()));
    drop(gpu);
    finish(ctx);
}

/// Per pixel with the ray-traced G-buffer (`metal_spheres`: enough triangles for the plan to
/// trace it; its stopped pixels skip their camera ray) and specular lobes, whose path-traced
/// light is what keeps some pixels going: the mean count stays below the sub-frames shaded,
/// the estimate meets the target, and the image is within the target of 64 sub-frames.
#[test]
fn per_pixel_anti_aliasing_with_a_traced_g_buffer_meets_its_target() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let path = root.join("assets/metal_spheres/metal_spheres.gltf");
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap().0;
    assert!(scene.plan().traced_gbuffer, "{:?}", scene.plan());
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut render = |target: f64, per_pixel: bool| -> (FrameOutput, IcStats) {
        let settings = IcSettings {
            width: 48,
            height: 48,
            params: IcParams::draft(),
            sub_frames: 8,
            direct_samples: 4,
            anti_aliasing: Some(AntiAliasing {
                target,
                max_sub_frames: 64,
                per_pixel,
            }),
            ..IcSettings::default()
        };
        render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap()
    };
    let (_, stats8) = render(1.0, true);
    let est8 = stats8.aa_relmse_estimate.unwrap();
    let (out64, stats64) = render(1e-12, false);
    assert_eq!(stats64.sub_frames_shaded, 64);
    let target = est8 / 3.0;
    let (out, stats) = render(target, true);
    let (n, est, mean) = (
        stats.sub_frames_shaded,
        stats.aa_relmse_estimate.unwrap(),
        stats.mean_pixel_sub_frames,
    );
    let m = compare(&image(&out64), &image(&out)).unwrap();
    eprintln!(
        "estimate at 8: {est8:.3e}; target {target:.3e}: {n} sub-frames, {mean:.1} per pixel, \
         estimate {est:.3e}, relMSE against 64: {:.3e}",
        m.relmse
    );
    assert!(
        n > 8 && est <= target,
        "{n} sub-frames, {est} against {target}"
    );
    assert!(
        mean > 8.0 && mean < 0.8 * f64::from(n),
        "{mean} per pixel of {n}"
    );
    assert!(m.relmse <= target, "relMSE {} against {target}", m.relmse);
    assert!(out.pixels.iter().flatten().all(|c| c.is_finite()));
    drop(gpu);
    finish(ctx);
}
