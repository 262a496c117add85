//! The metallic-roughness BRDF in the passes (issue 17), on lavapipe, against closed forms and
//! quadrature of the CPU twin (`radcache-material`):
//!
//! - White furnace of a plane: a metal (base colour 1) under a uniform sky reflects the sky times
//!   its directional albedo, the integral of `f·cos` over the hemisphere computed here by
//!   quadrature of `brdf_eval`; never more than it receives. Checked at three roughnesses and two
//!   view elevations, per pixel, for the path tracer and for the cache's frame.
//! - A mirror (roughness 0, metallic 1) reflects a known emitter: Schlick's `F(n·v)` times the
//!   emitted radiance (docs/materials.md §4.2).
//!
//! Every sample of a plane pixel is camera → plane → one BRDF sample → sky (a convex scene: the
//! reflected ray always escapes), so the only noise is the BRDF sampling's; the tolerances are
//! five standard errors of the pixel's estimate, bounded from the sample weight's range.

use glam::{Quat, Vec3};
use radcache_cache::IcParams;
use radcache_image::{compare, Image};
use radcache_material::{brdf_eval, Material};
use radcache_render::{render_ic, FrameOutput, GpuScene, IcSettings};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::Scene;
use radcache_tests::scenes::{
    camera_node, lit_room_materials, mesh_camera_scene, pixel_to_ndc, plane_x, plane_y, render,
    temp_dir, write_and_load,
};
use radcache_tests::{context, finish, shaders};

/// Directional albedo `∫ f(v, l) (n·l) dl` of `m` at `n·v = mu`, by the midpoint rule in
/// (cos θ_l, φ) (cos θ_l steps concentrated near the lobe by a square map).
fn directional_albedo(m: &Material, mu: f32) -> f64 {
    let v = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (nt, np) = (400usize, 256usize);
    let mut sum = 0.0f64;
    for i in 0..nt {
        // z = cos θ_l = 1 − s², s uniform: dz = 2s ds.
        let s = (i as f64 + 0.5) / nt as f64;
        let z = 1.0 - s * s;
        let dz = 2.0 * s / nt as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..np {
            let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
            let l = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            let f = brdf_eval(m, v, l);
            sum += f64::from(f.x) * z * dz * std::f64::consts::TAU / np as f64;
        }
    }
    sum
}

fn white_metal(roughness: f32) -> Material {
    Material {
        base_colour: Vec3::ONE,
        metallic: 1.0,
        roughness,
        ior: 1.5,
        specular_factor: 1.0,
        specular_colour: Vec3::ONE,
    }
}

/// A large plane of material `mat` at y = 0 under a uniform sky of radiance 1, seen from a
/// camera at height 1.5 pitched down by `pitch`.
fn sky_plane(tag: &str, mat: &MaterialDesc, pitch: f32, yfov: f32) -> Scene {
    let mut b = GltfBuilder::new();
    let m = b.add_material(mat);
    let mesh = b.add_mesh("plane", &[plane_y([-40.0, 40.0], [-40.0, 40.0], 0.0, m)]);
    let camera = (
        Vec3::new(0.0, 1.5, 3.0),
        Quat::from_rotation_x(-pitch),
        yfov,
    );
    let extras = serde_json::json!({"environment": {"radiance": [1.0, 1.0, 1.0]}});
    mesh_camera_scene(b, tag, ("plane", mesh), camera, Some(extras))
}

/// `n·v` of the camera ray through the centre of pixel (px, py) on the plane y = 0 (normal +Y).
fn pixel_cos(scene: &Scene, size: (u32, u32), px: u32, py: u32) -> f32 {
    let view = scene.camera_at(0.0);
    let (x, y) = pixel_to_ndc(f64::from(px) + 0.5, f64::from(py) + 0.5, size.0, size.1);
    let d = view.ray_direction(x, y, size.0 as f32 / size.1 as f32);
    assert!(d.y < -0.05, "pixel ({px}, {py}) does not see the plane");
    -d.y
}

/// Checks every pixel of `out` against the plane's directional albedo (the sky is 1); returns
/// the largest deviation in standard errors. `spp` samples per pixel, each a BRDF-sample weight
/// in [0, 1] (a white metal: F = 1, weight G2/G1), so a pixel's standard error is at most
/// ½/√spp; the pixel's own spread of n·v adds the albedo's change across it.
fn check_furnace(
    what: &str,
    scene: &Scene,
    out: &FrameOutput,
    size: (u32, u32),
    m: &Material,
    se_bound: f64,
) {
    let mut worst = 0.0f64;
    let mut sum_err = 0.0f64;
    for py in 0..size.1 {
        // The albedo at the row's centre and its change across the row's pixel height.
        let mu = pixel_cos(scene, size, size.0 / 2, py);
        let mu_lo = pixel_cos(scene, size, size.0 / 2, (py + 1).min(size.1 - 1));
        let expected = directional_albedo(m, mu);
        let spread = (directional_albedo(m, mu_lo) - expected).abs();
        for px in 0..size.0 {
            let mu_px = pixel_cos(scene, size, px, py);
            let expected_px = directional_albedo(m, mu_px);
            let got = out.pixels[(py * size.0 + px) as usize];
            for (c, &value) in got.iter().enumerate().take(3) {
                let g = f64::from(value);
                assert!(
                    g <= 1.0 + 5.0 * se_bound,
                    "{what}: pixel ({px}, {py}) reflects {g} > the sky's 1"
                );
                let err = g - expected_px;
                let tol = 5.0 * se_bound + spread + 2e-3 * expected_px;
                assert!(
                    err.abs() <= tol,
                    "{what}: pixel ({px}, {py}) channel {c}: {g}, expected {expected_px:.5} \
                     (n·v {mu_px:.4}), tolerance {tol:.5}"
                );
                worst = worst.max(err.abs() / se_bound);
                sum_err += err;
            }
        }
    }
    let n = f64::from(size.0 * size.1 * 3);
    let mean_err = sum_err / n;
    eprintln!(
        "{what}: albedo at the centre row {:.4} (n·v {:.3}); worst |error| {worst:.2} SE bounds, \
         mean error {mean_err:+.5}",
        directional_albedo(m, pixel_cos(scene, size, size.0 / 2, size.1 / 2)),
        pixel_cos(scene, size, size.0 / 2, size.1 / 2)
    );
    // The mean over the image: its standard error is at most se_bound/√n; a bias would show.
    assert!(
        mean_err.abs() <= 5.0 * se_bound / n.sqrt() + 1e-3,
        "{what}: mean error {mean_err} over {n} pixel channels"
    );
}

#[test]
fn metal_plane_under_a_uniform_sky_reflects_its_directional_albedo() {
    let ctx = context();
    let shaders = shaders();
    let size = (24u32, 24u32);
    let spp = 256u32;
    for roughness in [0.25f32, 0.6, 1.0] {
        // Views between 35° and 50° from the plane, and near the normal.
        for (pitch, yfov) in [(0.75f32, 0.4f32), (1.35, 0.3)] {
            let desc = MaterialDesc::metal_rough("metal", [1.0, 1.0, 1.0], 1.0, roughness);
            let tag = format!("metal-furnace-{roughness}-{pitch}");
            let scene = sky_plane(&tag, &desc, pitch, yfov);
            assert!(scene.plan().specular, "a metal needs the specular code");
            let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
            let out = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 3);
            let m = white_metal(roughness);
            let se_bound = 0.5 / f64::from(spp).sqrt();
            check_furnace(
                &format!("path tracer, {tag}"),
                &scene,
                &out,
                size,
                &m,
                se_bound,
            );

            // The cache's frame: no diffuse lobe, so the records carry nothing this plane uses;
            // the sky reaches its specular lobe through the direct pass's BRDF samples (the
            // specular path, which leaves out its first segment's sky, finds nothing).
            let settings = IcSettings {
                width: size.0,
                height: size.1,
                params: IcParams::default(),
                ..IcSettings::default()
            };
            let (ic, _) =
                render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
            assert_eq!(ic.nonfinite_pixels, 0);
            let samples = f64::from(settings.direct_samples * settings.sub_frames);
            check_furnace(
                &format!("cache frame, {tag}"),
                &scene,
                &ic,
                size,
                &m,
                0.5 / samples.sqrt(),
            );
            drop(gpu);
        }
    }
    finish(ctx);
}

/// Where the camera ray through image position (sx, sy), mirrored at the plane y = 0, meets the
/// plane y = `height`, and the length of the reflected segment; `None` if the ray does not reach
/// the mirror.
fn mirrored_hit(
    scene: &Scene,
    size: (u32, u32),
    sx: f64,
    sy: f64,
    height: f32,
) -> Option<(Vec3, f32)> {
    let view = scene.camera_at(0.0);
    let (x, y) = pixel_to_ndc(sx, sy, size.0, size.1);
    let d = view.ray_direction(x, y, size.0 as f32 / size.1 as f32);
    if d.y >= -1e-3 {
        return None;
    }
    let o = view.position;
    let p = o + d * (-o.y / d.y);
    let r = Vec3::new(d.x, -d.y, d.z);
    Some((p + r * (height / r.y), height / r.y))
}

#[test]
fn a_mirror_reflects_two_emitters_with_schlick_fresnel() {
    // Two large emitters side by side under a ceiling at y = 3 (x < 0 bright, x > 0 dim) over a
    // mirror floor (metallic 1, roughness 0, so α = ALPHA_MIN = 1e-3). GGX's tail is heavy
    // (P(θ_h > t) = α²/(α² + t²)), so only pixels whose reflection lands more than 0.25 rad from
    // the emitters' edges are compared: there the lobe's light from elsewhere is below 1e-4.
    let base = [0.9f32, 0.6, 0.3];
    let (bright, dim) = (2.0f32, 0.5f32);
    let (ey, ez) = (3.0f32, [-60.0f32, 10.0]);
    let mut b = GltfBuilder::new();
    let mirror = b.add_material(&MaterialDesc::metal_rough("mirror", base, 1.0, 0.0));
    let mut lamp = |name: &str, le: f32| {
        b.add_material(&MaterialDesc {
            double_sided: true,
            ..MaterialDesc::emitter(name, [0.0; 3], [le; 3])
        })
    };
    let (l0, l1) = (lamp("bright", bright), lamp("dim", dim));
    let floor = b.add_mesh(
        "mirror",
        &[plane_y([-60.0, 60.0], [-60.0, 10.0], 0.0, mirror)],
    );
    let lamps = b.add_mesh(
        "lights",
        &[
            plane_y([-60.0, 0.0], ez, ey, l0),
            plane_y([0.0, 60.0], ez, ey, l1),
        ],
    );
    let mut roots = Vec::new();
    for (name, mesh) in [("mirror", floor), ("lights", lamps)] {
        roots.push(b.add_node(&NodeDesc {
            name: Some(name.into()),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }));
    }
    roots.push(camera_node(
        &mut b,
        Vec3::new(0.0, 1.5, 3.0),
        Quat::from_rotation_x(-0.55),
        0.7,
    ));
    b.add_scene("mirror", &roots, None);
    let scene = write_and_load(&b, &temp_dir("mirror"), "mirror");

    let size = (32u32, 32u32);
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let spp = 256u32;
    let out = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 11);
    drop(gpu);
    finish(ctx);

    // The emitter a reflection sees, if it is 0.25 rad (as seen from the mirror) inside one.
    let side = |h: Option<(Vec3, f32)>| -> Option<f32> {
        let (q, len) = h?;
        let margin = 0.25 * len;
        let inside_z = q.z > ez[0] + margin && q.z < ez[1] - margin;
        if !inside_z || q.x.abs() < margin || q.x.abs() > 60.0 - margin {
            return None;
        }
        Some(if q.x < 0.0 { bright } else { dim })
    };
    let (mut n_bright, mut n_dim) = (0, 0);
    let (mut ratio_sum, mut ratios) = (0.0f64, 0u32);
    for py in 0..size.1 {
        for px in 0..size.0 {
            let (x, y) = (f64::from(px), f64::from(py));
            let corners = [(x, y), (x + 1.0, y), (x, y + 1.0), (x + 1.0, y + 1.0)]
                .map(|(sx, sy)| side(mirrored_hit(&scene, size, sx, sy, ey)));
            let Some(le) = corners[0] else { continue };
            if corners.iter().any(|c| *c != Some(le)) {
                continue;
            }
            if le == bright {
                n_bright += 1;
            } else {
                n_dim += 1;
            }
            let got = out.pixels[(py * size.0 + px) as usize];
            let mu = pixel_cos(&scene, size, px, py);
            let w = (1.0 - mu).powi(5);
            for c in 0..3 {
                let expected = le * (base[c] + (1.0 - base[c]) * w);
                let ratio = f64::from(got[c] / expected);
                // A BRDF sample in GGX's tail meets a light-sampling pdf as large as its own
                // there: its MIS weight is small and the light samples that carry the rest are
                // rare, so a pixel can lack a few samples' worth (1/spp each) while the mean
                // stays exact.
                assert!(
                    (ratio - 1.0).abs() <= 4.0 / f64::from(spp),
                    "mirror pixel ({px}, {py}) channel {c}: {}, expected {expected} (n·v {mu})",
                    got[c]
                );
                ratio_sum += ratio;
                ratios += 1;
            }
        }
    }
    let mean = ratio_sum / f64::from(ratios);
    eprintln!(
        "mirror: {n_bright} pixels reflect the bright emitter, {n_dim} the dim one; mean of \
         rendered/expected {mean:.5}"
    );
    assert!(
        n_bright >= 60 && n_dim >= 60,
        "bright {n_bright}, dim {n_dim}"
    );
    assert!((mean - 1.0).abs() <= 1e-3, "mean ratio {mean}");
}

/// A closed white room (2 × 2 × 2, walls Lambertian) lit by a square emitter under its ceiling,
/// with a rough gold-coloured metal sphere and a rough blue dielectric sphere; the camera looks in
/// through the front wall's inside.
fn spheres_room(tag: &str) -> Scene {
    use radcache_tests::geometry::{room, uv_sphere};
    let mut b = GltfBuilder::new();
    let [white, red, light] = lit_room_materials(&mut b);
    let gold = b.add_material(&MaterialDesc::metal_rough(
        "gold",
        [0.95, 0.7, 0.35],
        1.0,
        0.35,
    ));
    let blue = b.add_material(&MaterialDesc::metal_rough(
        "blue",
        [0.15, 0.3, 0.7],
        0.0,
        0.3,
    ));
    let tri = |m: &radcache_tests::geometry::Mesh, material: usize, smooth: Option<Vec3>| {
        PrimitiveDesc::triangles(
            m.positions.iter().map(|p| p.to_array()).collect(),
            smooth.map(|c| {
                m.positions
                    .iter()
                    .map(|p| (*p - c).normalize().to_array())
                    .collect()
            }),
            m.indices.clone(),
            Some(material),
        )
    };
    let walls = room(Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut prims = vec![
        tri(&walls, white, None),
        // A red panel on the left wall, a hair in front of it.
        plane_x([-1.0, 1.0], [-1.0, 1.0], -0.999, 1.0, red),
        plane_y([-0.3, 0.3], [-0.3, 0.3], 0.99, light),
    ];
    let mut sphere = |centre: Vec3, r: f32, material: usize| {
        let mut m = uv_sphere(r, 24, 48);
        for p in &mut m.positions {
            *p += centre;
        }
        prims.push(tri(&m, material, Some(centre)));
    };
    sphere(Vec3::new(-0.45, -0.6, -0.2), 0.4, gold);
    sphere(Vec3::new(0.45, -0.6, 0.2), 0.4, blue);
    let mesh = b.add_mesh("room", &prims);
    let roots = vec![
        b.add_node(&NodeDesc {
            name: Some("room".into()),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }),
        camera_node(&mut b, Vec3::new(0.0, 0.0, 0.99), Quat::IDENTITY, 1.4),
    ];
    b.add_scene(tag, &roots, None);
    write_and_load(&b, &temp_dir(tag), tag)
}

#[test]
fn the_cache_frame_matches_the_path_tracer_on_metal_and_dielectric_spheres() {
    let scene = spheres_room("spheres_room");
    assert!(scene.plan().specular);
    let blue = scene
        .materials
        .iter()
        .find(|m| m.name.as_deref() == Some("blue"));
    assert!(blue.is_some_and(|m| m.specular_factor == 1.0 && m.metallic == 0.0));
    let size = (48u32, 48u32);
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let reference = render(&ctx, &shaders, &scene, &mut gpu, size, 4096, 1);
    let settings = IcSettings {
        width: size.0,
        height: size.1,
        params: IcParams::default(),
        ..IcSettings::default()
    };
    let (ic, stats) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    drop(gpu);
    finish(ctx);
    assert_eq!(ic.nonfinite_pixels, 0);
    let image = |o: &FrameOutput| Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap();
    let m = compare(&image(&reference), &image(&ic)).unwrap();
    eprintln!(
        "spheres room, cache frame vs path tracer (4096 spp): {m}; records {}",
        stats.records
    );
    assert_eq!(m.nonfinite_candidate, 0);
    assert!(m.relmse <= 0.01, "relMSE {}", m.relmse);
    for (c, r) in m.mean_ratio.iter().enumerate() {
        assert!((r - 1.0).abs() <= 0.02, "channel {c} mean ratio {r}");
    }
}
