//! Adaptive shadows (docs/cache-frame.md §8.2) on lavapipe: after the first sub-frame the direct
//! pass casts no shadow ray where every 3×3 neighbour saw what the pixel saw, one emitter ray at
//! other pixels whose neighbourhood saw the emitters wholly visible or wholly hidden, a quarter
//! of the samples in penumbrae; its estimate stays the fixed pass's in expectation and exact
//! where there is no shadow; a point light's shadow is reused away from its boundary and traced
//! along it.

use glam::{DVec3, Quat, Vec3};
use radcache_render::{DirectPass, EmitterLight, SkyLight};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc};
use radcache_scene::Scene;
use radcache_tests::direct_cpu::{agree, cpu_direct};
use radcache_tests::ic_fixture::*;
use radcache_tests::scenes::{camera_node, load, plane_y, temp_dir, write_and_load};

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
    // Later ones: none where the 3×3 neighbourhood saw the same, one where it saw light or
    // shadow alone, a quarter of the samples in (dilated) penumbrae; never nothing (the box
    // has penumbrae at this size).
    for &rays in &adaptive_rays[1..] {
        assert!(
            rays > 0 && rays * 10 < fixed_rays[0] * 6,
            "{rays} rays against {} in sub-frame 0",
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

/// In the furnace every light sample is visible: after sub-frame 0, where every neighbourhood saw
/// the emitters wholly visible, adaptive shadows cast no ray and every pixel stays exact.
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
    // Four samples a pixel at sub-frame 0 (those below the receiver's horizon cast none), none
    // later.
    let pixels = u64::from(w * h);
    assert!(rays[0] > 2 * pixels && rays[0] <= 4 * pixels, "{rays:?}");
    assert!(rays[1..].iter().all(|&r| r == 0), "{rays:?}");
    drop(adaptive);
    gpu.end();
}

/// A diffuse floor under a point light, with a square slab between them casting a hard shadow,
/// seen from above at an angle.
fn slab_scene() -> Scene {
    let name = "ic-passes-slab-shadow";
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::diffuse("grey", [0.6, 0.6, 0.6]));
    let floor = plane_y([-4.0, 4.0], [-3.0, 3.0], 0.0, mat);
    let slab = plane_y([-0.4, 0.4], [-0.4, 0.4], 0.6, mat);
    let mesh = b.add_mesh("floor+slab", &[floor, slab]);
    let light = b.add_light(&LightDesc {
        name: None,
        kind: LightKind::Point,
        color: [1.0; 3],
        intensity: 5.0,
        range: None,
    });
    let roots = vec![
        b.add_node(&NodeDesc {
            mesh: Some(mesh),
            ..NodeDesc::default()
        }),
        camera_node(
            &mut b,
            Vec3::new(0.0, 2.0, 3.0),
            Quat::from_rotation_x(-0.6),
            0.7,
        ),
        b.add_node(&NodeDesc {
            translation: Some([0.3, 1.8, 0.2]),
            light: Some(light),
            ..NodeDesc::default()
        }),
    ];
    b.add_scene(name, &roots, None);
    write_and_load(&b, &temp_dir(name), name)
}

/// A point light's shadow with adaptive shadows: sub-frame 0 casts a ray at every lit-facing
/// pixel; a later sub-frame, its G-buffer jittered off the pixel centres, casts rays only along
/// the shadow's boundary and the slab's silhouette, and its image is the fixed pass's on the same
/// G-buffer at every pixel (a punctual light has no randomness: reused and traced visibility
/// must agree exactly where the reuse applies).
#[test]
fn adaptive_shadows_reuse_a_point_lights_visibility_away_from_its_boundary() {
    let scene = slab_scene();
    let (w, h) = (48, 36);
    let gpu = Gpu::new(&scene, None, (w, h));
    let pass = |pixels| {
        DirectPass::new(
            &gpu.ctx,
            &gpu.shaders,
            &gpu.scene,
            SkyLight::Direct,
            EmitterLight::Analytic,
        )
        .unwrap()
        .with_adaptive_shadows(&gpu.ctx, pixels)
        .unwrap()
    };
    let (fixed, adaptive) = (pass(None), pass(Some(w * h)));
    let (samples, seed) = (4, 9);
    gpu.render([0.0; 2], None);
    let g = gpu.read_gbuffer();
    let surfaces = g.position.iter().filter(|p| p[3] > 0.0).count() as u64;
    let (fixed0, fixed_rays0) = gpu.direct(&fixed, samples, 0, seed);
    let (adaptive0, rays0) = gpu.direct(&adaptive, samples, 0, seed);
    assert_eq!(adaptive0, fixed0, "sub-frame 0 is the fixed pass's");
    assert_eq!(rays0, fixed_rays0);
    assert_eq!(
        rays0, surfaces,
        "one ray a pixel: every surface faces the light"
    );
    let dark = fixed0
        .iter()
        .zip(&g.position)
        .filter(|(d, p)| p[3] > 0.0 && d[0] == 0.0)
        .count();
    assert!(dark > 20, "{dark} pixels in the slab's shadow");
    for (k, jitter) in [(1, [0.3, -0.2]), (2, [-0.45, 0.4])] {
        gpu.render(jitter, None);
        let (expected, _) = gpu.direct(&fixed, samples, k, seed);
        let (got, rays) = gpu.direct(&adaptive, samples, k, seed);
        assert!(
            rays > 0 && rays * 4 < surfaces,
            "sub-frame {k}: {rays} rays for {surfaces} surface pixels"
        );
        for (i, (a, e)) in got.iter().zip(&expected).enumerate() {
            close(
                "reused shadow",
                i,
                xyz(*a),
                xyz(*e),
                1e-6 * xyz(*e).max_element() + 1e-9,
            );
        }
    }
    drop((fixed, adaptive));
    gpu.end();
}
