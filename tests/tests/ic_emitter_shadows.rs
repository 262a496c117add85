//! Adaptive emitter shadows (docs/cache-frame.md §8.2) on lavapipe: after the first sub-frame
//! the direct pass casts one emitter shadow ray where a pixel's neighbourhood saw the emitters
//! wholly visible or wholly hidden, a quarter of the samples in penumbrae; its estimate stays
//! the fixed pass's in expectation and exact where there is no shadow.

use glam::DVec3;
use radcache_render::{DirectPass, EmitterLight, SkyLight};
use radcache_tests::direct_cpu::{agree, cpu_direct};
use radcache_tests::ic_fixture::*;
use radcache_tests::scenes::{load, temp_dir};

/// The mean of sub-frames `images` per pixel.
fn mean_image(images: &[Vec<Px>]) -> Vec<DVec3> {
    let n = images.len() as f64;
    (0..images[0].len())
        .map(|i| images.iter().map(|im| xyz(im[i])).sum::<DVec3>() / n)
        .collect()
}

/// The emitters' light in closed form, with adaptive shadows for `pixels` pixels (`None`: a
/// quarter of the samples at every pixel and sub-frame).
fn analytic_pass(gpu: &Gpu, pixels: Option<u32>) -> DirectPass {
    let direct = DirectPass::new(
        &gpu.ctx,
        &gpu.shaders,
        &gpu.scene,
        SkyLight::Direct,
        EmitterLight::Analytic,
    );
    direct
        .unwrap()
        .with_adaptive_shadows(&gpu.ctx, pixels)
        .unwrap()
}

/// Adaptive emitter shadows (docs/cache-frame.md §8.2) on the Cornell box: sub-frame 0 is the
/// fixed pass's, bit for bit; later sub-frames cast far fewer shadow rays, and their mean agrees
/// with the fixed pass's, with the CPU's estimate, and with the first sub-frame's mean.
#[test]
fn adaptive_emitter_shadows_spend_rays_in_penumbrae_alone() {
    let scene = cornell();
    let (w, h) = (32, 32);
    let gpu = Gpu::new(&scene, None, (w, h));
    gpu.render([0.0; 2], None);
    let g = gpu.read_gbuffer();
    let cpu = cpu_direct(&scene, &g, 256);
    let fixed = analytic_pass(&gpu, None);
    let adaptive = analytic_pass(&gpu, Some(w * h));
    let (samples, seed, sub_frames) = (16, 5, 8);
    let mut runs = Vec::new();
    for direct in [&fixed, &adaptive] {
        let (images, rays): (Vec<_>, Vec<_>) = (0..sub_frames)
            .map(|k| gpu.direct(direct, samples, k, seed))
            .unzip();
        eprintln!("rays per sub-frame: {rays:?}");
        runs.push((images, rays));
    }
    let ((fixed_images, fixed_rays), (adaptive_images, adaptive_rays)) = (&runs[0], &runs[1]);
    let pixels: Vec<usize> = (0..(w * h) as usize)
        .filter(|&i| g.position[i][3] > 0.0)
        .collect();
    assert!(pixels.len() > 900, "{} surface pixels", pixels.len());
    // Sub-frame 0 classifies; it casts a quarter of the samples everywhere, as the fixed pass.
    assert_eq!(adaptive_rays[0], fixed_rays[0]);
    assert_eq!(adaptive_images[0], fixed_images[0]);
    // Later ones: one ray where the neighbourhood saw light or shadow alone, a quarter of the
    // samples in (dilated) penumbrae. Every lit pixel casts one (unless its sample falls where
    // the emitter faces away or below the horizon, which a quarter of the samples shows).
    let lit = fixed_rays[0] / u64::from(samples / 4);
    for &rays in &adaptive_rays[1..] {
        assert!(
            rays * 10 >= lit * 9 && rays * 10 < fixed_rays[0] * 6,
            "{rays} rays against {} in sub-frame 0 ({lit} lit pixels)",
            fixed_rays[0]
        );
    }
    let fixed_mean = mean_image(&fixed_images[1..]);
    let adaptive_mean = mean_image(&adaptive_images[1..]);
    agree("adaptive vs CPU", &adaptive_mean, &cpu, &pixels);
    agree("adaptive vs fixed", &adaptive_mean, &fixed_mean, &pixels);
    agree(
        "adaptive vs its sub-frame 0",
        &adaptive_mean,
        &mean_image(&adaptive_images[..1]),
        &pixels,
    );
    drop((fixed, adaptive));
    gpu.end();
}

/// In the furnace every light sample is visible: after sub-frame 0, adaptive emitter shadows
/// cast at most one ray a pixel and every pixel stays exact.
#[test]
fn adaptive_emitter_shadows_are_exact_in_the_furnace() {
    let (albedo, le) = (0.5, 1.0);
    let dir = temp_dir("ic-passes-furnace-adaptive");
    let scene = load(&radcache_scene::assets::write_furnace(&dir, albedo, le).unwrap());
    let (w, h) = (16, 16);
    let gpu = Gpu::new(&scene, None, (w, h));
    gpu.render([0.0; 2], None);
    let expected = DVec3::splat(f64::from(albedo * le));
    let adaptive = analytic_pass(&gpu, Some(w * h));
    let mut rays = Vec::new();
    for k in 0..4 {
        let (out, r) = gpu.direct(&adaptive, 16, k, 3);
        for (i, d) in out.iter().enumerate() {
            close("adaptive direct", i, xyz(*d), expected, 1e-4 * expected.x);
        }
        rays.push(r);
    }
    // Four samples a pixel at sub-frame 0 (those below the receiver's horizon cast none), at
    // most one later.
    let pixels = u64::from(w * h);
    assert!(rays[0] > 2 * pixels && rays[0] <= 4 * pixels, "{rays:?}");
    assert!(
        rays[1..].iter().all(|&r| r > pixels / 2 && r <= pixels),
        "{rays:?}"
    );
    drop(adaptive);
    gpu.end();
}
