//! Adaptive shadows (docs/cache-frame.md §8.2) on lavapipe: after the first sub-frame the direct
//! pass casts no shadow ray where every 3×3 neighbour saw what the pixel saw, one emitter ray at
//! other pixels whose neighbourhood saw the emitters wholly visible or wholly hidden, a quarter
//! of the samples in penumbrae; its estimate stays the fixed pass's in expectation and exact
//! where there is no shadow; a point light's shadow is reused away from its boundary and traced
//! along it, and along an object thinner than a pixel that the first sub-frame missed.

use glam::{DVec3, Quat, Vec3};
use radcache_render::{
    passes::direct::DirectPass, passes::direct::DirectShadows, passes::direct::DirectVariant,
    EmitterLight, SkyLight,
};
use radcache_scene::writer::{GltfBuilder, MaterialDesc};
use radcache_scene::Scene;
use radcache_tests::direct_cpu::{agree, cpu_direct};
use radcache_tests::ic_fixture::*;
use radcache_tests::scenes::{load, meshes_camera_light_scene, plane_y, temp_dir};

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
    let variant = DirectVariant {
        shadows: pixels.map_or(DirectShadows::Fixed, |pixels| DirectShadows::Adaptive {
            pixels,
        }),
        ..DirectVariant::new(SkyLight::Direct, EmitterLight::Analytic)
    };
    DirectPass::new(&gpu.ctx, &gpu.shaders, &gpu.scene, &variant).unwrap()
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
    let camera = (Vec3::new(0.0, 2.0, 3.0), Quat::from_rotation_x(-0.6), 0.7);
    meshes_camera_light_scene(
        b,
        name,
        &[(mesh, Quat::IDENTITY)],
        camera,
        ([0.3, 1.8, 0.2], 5.0),
    )
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
    let (fixed, adaptive) = (analytic_pass(&gpu, None), analytic_pass(&gpu, Some(w * h)));
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

/// A wall facing away from a point light (hidden everywhere; the plane z = 0, y up to 1) and, in
/// front of it, a bar lying at y = 0 over `z` (its top faces the light over the wall's top edge
/// from z = 0.25 on, the wall shadows it nearer), seen from above at an angle.
fn bar_scene(name: &str, z: [f32; 2]) -> Scene {
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::diffuse("grey", [0.6, 0.6, 0.6]));
    // plane_y rotated +90° about x: the plane z = 0 facing +z, y in [-2, 1].
    let wall = b.add_mesh("wall", &[plane_y([-3.0, 3.0], [-1.0, 2.0], 0.0, mat)]);
    let bar = b.add_mesh("bar", &[plane_y([-3.0, 3.0], z, 0.0, mat)]);
    let q = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
    let meshes = [(wall, q), (bar, Quat::IDENTITY)];
    let camera = (Vec3::new(0.0, 1.0, 3.0), Quat::from_rotation_x(-0.38), 0.7);
    meshes_camera_light_scene(b, name, &meshes, camera, ([0.0, 3.0, -0.5], 5.0))
}

/// Sub-frame 0 at a G-buffer jitter where no sample of `scene` (a `bar_scene`) is lit, then ten
/// jitters: each later sub-frame's image must be the fixed pass's at every pixel (a punctual
/// light has no randomness), some of the bar lit, while the wall away from it still reuses its
/// answer (fewer rays than a quarter of the surface pixels).
fn reuse_is_exact_after_a_dark_first_sub_frame(scene: &Scene) {
    let (w, h) = (48, 36);
    let gpu = Gpu::new(scene, None, (w, h));
    let (fixed, adaptive) = (analytic_pass(&gpu, None), analytic_pass(&gpu, Some(w * h)));
    let (samples, seed) = (4, 9);
    let jitters: Vec<[f32; 2]> = (0..10).map(|i| [0.0, -0.45 + 0.1 * i as f32]).collect();
    let lit = |image: &[Px]| image.iter().filter(|d| d[0] > 0.0).count();
    let first = jitters
        .iter()
        .copied()
        .find(|&j| {
            gpu.render(j, None);
            lit(&gpu.direct(&fixed, samples, 0, seed).0) == 0
        })
        .expect("a sub-frame-0 jitter whose samples are all in shadow");
    gpu.render(first, None);
    let surfaces = gpu
        .read_gbuffer()
        .position
        .iter()
        .filter(|p| p[3] > 0.0)
        .count() as u64;
    assert!(surfaces > u64::from(w * h) / 2, "{surfaces} surface pixels");
    gpu.direct(&adaptive, samples, 0, seed);
    let mut bar_lit = 0;
    for (k, &jitter) in jitters.iter().enumerate() {
        gpu.render(jitter, None);
        let k = k as u32 + 1;
        let (expected, _) = gpu.direct(&fixed, samples, k, seed);
        let (got, rays) = gpu.direct(&adaptive, samples, k, seed);
        bar_lit += lit(&expected);
        assert!(
            rays * 4 < surfaces,
            "jitter {jitter:?}: {rays} rays for {surfaces} surface pixels"
        );
        for (i, (a, e)) in got.iter().zip(&expected).enumerate() {
            close(
                "bar pixel",
                i,
                xyz(*a),
                xyz(*e),
                1e-6 * xyz(*e).max_element() + 1e-9,
            );
        }
    }
    assert!(
        bar_lit >= w as usize,
        "{bar_lit} lit bar samples over the jitters"
    );
    drop((fixed, adaptive));
    gpu.end();
}

/// A lit bar a quarter of a pixel high that sub-frame 0's samples all missed: every pixel and
/// neighbour saw the wall, hidden; a later sample on the bar lies on another surface than its
/// pixel's first one (`same_surface_as_first`, docs/cache-frame.md §8.2) and casts its ray.
#[test]
fn adaptive_shadows_trace_a_sample_on_an_object_the_first_sub_frame_missed() {
    reuse_is_exact_after_a_dark_first_sub_frame(&bar_scene("ic-passes-thin-bar", [0.48, 0.52]));
}

/// A bar about a pixel high whose far half the wall shadows: sub-frame 0's samples on the bar
/// all fell in the shadow, like the wall around them, and a later sample on the lit half lies
/// on the same plane; the bar's neighbours above and below lie on the wall, so its pixels are
/// edges (SHADOW_EDGE) and reuse nothing.
#[test]
fn adaptive_shadows_reuse_nothing_where_the_neighbours_lie_on_other_surfaces() {
    reuse_is_exact_after_a_dark_first_sub_frame(&bar_scene("ic-passes-bar-edge", [0.15, 0.35]));
}
