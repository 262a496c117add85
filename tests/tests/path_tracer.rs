//! The reference path tracer against closed-form answers on lavapipe.
//!
//! - Furnaces (closed box, albedo ρ, emission Le everywhere): every pixel converges to
//!   Le / (1 − ρ); checked for ρ = 0.5, 0.9 and 0.99 (paths of ~100 bounces) at several sample
//!   counts (the estimate is unbiased at every count and its standard error shrinks), and for a
//!   mirrored (negative-determinant) furnace box.
//! - A diffuse plane under one punctual light (point, point with range, spot, directional): only
//!   direct light (a plane cannot see itself), so each pixel is the box-filtered ρ/π · E(p) with
//!   the KHR_lights_punctual formulas, integrated here on the CPU through the same camera.
//! - The same kind of plane under a constant sky: each plane sample is exactly ρ·L, each sky
//!   sample exactly L.
//! - A textured emitter seen directly: emissive factor × texel, nothing else.
//! - Seeds: different seeds give independent, equally distributed images; the same seed gives the
//!   same image bit for bit.
//!
//! Tolerances come from the samples: per-pixel estimates are independent, so the image mean's
//! standard error is the per-pixel spread / √N and the test accepts |mean − expected| < 5 SE plus a
//! float slack of a few ulps of f32 accumulation. Where the only randomness is the pixel jitter,
//! the per-pixel bound is 5 × (jitter standard deviation / √spp) plus the CPU quadrature error.

use std::f64::consts::PI;
use std::path::PathBuf;

use glam::{Quat, Vec3};
use radcache_render::{render_path, Budget, FrameOutput, GpuScene, PathSettings};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc};
use radcache_scene::{CameraView, Scene};
use radcache_tests::scenes::{
    camera_node, convex_hull, inside_margin, load, mean_se, ndc_to_pixel, pixel_coverage,
    pixel_to_ndc, plane_y, temp_dir, write_and_load, Coverage,
};
use radcache_tests::{context, finish, shaders};
use radcache_vk::{Context, ShaderCompiler};

/// Relative float slack for f32 accumulation and camera-matrix round-off (far below any
/// statistical tolerance used here).
const FLOAT_SLACK: f64 = 1e-5;

fn render(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    size: (u32, u32),
    spp: u32,
    seed: u32,
) -> FrameOutput {
    let settings = PathSettings {
        width: size.0,
        height: size.1,
        budget: Budget::Samples(spp),
        seed,
        chunk_target_ms: 200.0,
        ..PathSettings::default()
    };
    let out = render_path(ctx, shaders, scene, gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(out.spp, spp);
    assert_eq!(out.pixels.len(), (size.0 * size.1) as usize);
    assert_eq!(out.nonfinite_pixels, 0, "non-finite pixels");
    for (i, p) in out.pixels.iter().enumerate() {
        assert!(
            p.iter().all(|c| c.is_finite() && *c >= 0.0),
            "pixel {i} is {p:?}"
        );
    }
    out
}

fn channel(out: &FrameOutput, c: usize) -> Vec<f64> {
    out.pixels.iter().map(|p| f64::from(p[c])).collect()
}

fn furnace(albedo: f32, le: f32) -> Scene {
    let dir = temp_dir(&format!("furnace-{albedo}"));
    load(&radcache_scene::assets::write_furnace(&dir, albedo, le).unwrap())
}

/// Checks that the image mean of every channel is within 5 standard errors of `expected`;
/// returns the standard errors.
fn assert_mean(out: &FrameOutput, expected: f64, what: &str) -> [f64; 3] {
    let mut ses = [0.0; 3];
    for (c, se_out) in ses.iter_mut().enumerate() {
        let s = mean_se(&channel(out, c));
        assert!(s.se > 0.0, "{what}: no spread between pixels (channel {c})");
        eprintln!(
            "{what}, channel {c}: mean {:.5} ± {:.5} (SE), expected {expected:.5}, {:+.2} SE",
            s.mean,
            s.se,
            (s.mean - expected) / s.se
        );
        assert!(
            (s.mean - expected).abs() < 5.0 * s.se + FLOAT_SLACK * expected,
            "{what}, channel {c}: mean {} over {} pixels, expected {expected}, SE {} ({:.2} SE off)",
            s.mean,
            s.n,
            s.se,
            (s.mean - expected) / s.se
        );
        *se_out = s.se;
    }
    ses
}

#[test]
fn furnace_converges_to_le_over_one_minus_albedo() {
    let le = 1.0f32;
    let ctx = context();
    let shaders = shaders();
    for (albedo, spp) in [(0.5f32, 128u32), (0.9, 128)] {
        let scene = furnace(albedo, le);
        let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
        let out = render(&ctx, &shaders, &scene, &mut gpu, (32, 32), spp, 7);
        let expected = f64::from(le) / (1.0 - f64::from(albedo));
        assert_mean(&out, expected, &format!("furnace rho={albedo}"));
        drop(gpu);
    }
    finish(ctx);
}

#[test]
fn mirrored_furnace_still_emits_and_samples_its_inner_faces() {
    // The furnace box with a mirroring node scale (−1, 1, 1): per glTF the front faces stay on the
    // side the (transformed) normals point to, inward, so the answer is unchanged. Both the hit
    // emission (front-face test in the shader) and emitter sampling (corner order of the uploaded
    // emitters) must handle the flipped winding, or light is lost.
    let (albedo, le) = (0.5f32, 1.0f32);
    let (mut root, _) = radcache_scene::assets::furnace_builder(albedo, le).to_json(None);
    let nodes = root["nodes"].as_array_mut().unwrap();
    let node = nodes
        .iter_mut()
        .find(|n| n["name"] == "furnace_box")
        .expect("the furnace box node");
    node["scale"] = serde_json::json!([-1.0, 1.0, 1.0]);
    let path = temp_dir("mirrored-furnace").join("mirrored.gltf");
    radcache_scene::writer::write_files(&path, &root, None).unwrap();
    let scene = load(&path);
    let m = scene.instance_transforms(0.0)[0];
    assert!(m.determinant() < 0.0, "the box is not mirrored");

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    assert!(gpu.plan().has_emissive());
    let out = render(&ctx, &shaders, &scene, &mut gpu, (32, 32), 64, 21);
    drop(gpu);
    finish(ctx);
    let expected = f64::from(le) / (1.0 - f64::from(albedo));
    assert_mean(&out, expected, "mirrored furnace rho=0.5");
}

#[test]
fn furnace_099_is_unbiased_at_every_sample_count() {
    let (albedo, le) = (0.99f32, 1.0f32);
    let expected = f64::from(le) / (1.0 - f64::from(albedo));
    let ctx = context();
    let shaders = shaders();
    let scene = furnace(albedo, le);
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut last_se = f64::INFINITY;
    for (spp, seed) in [(4u32, 101u32), (16, 102), (64, 103)] {
        let out = render(&ctx, &shaders, &scene, &mut gpu, (16, 16), spp, seed);
        let se = assert_mean(&out, expected, &format!("furnace rho=0.99 at {spp} spp"))[1];
        assert!(
            se < last_se,
            "the standard error did not shrink: {se} at {spp} spp after {last_se}"
        );
        last_se = se;
    }
    drop(gpu);
    finish(ctx);
}

const ALBEDO: [f32; 3] = [0.8, 0.5, 0.25];
const CAMERA_POS: Vec3 = Vec3::new(0.0, 2.0, 3.0);
const CAMERA_PITCH: f32 = -0.6;
const CAMERA_YFOV: f32 = 0.7;

/// A punctual light above the plane y = 0 (KHR_lights_punctual units).
#[derive(Debug, Clone, Copy)]
enum Light {
    /// Point light of `intensity` cd, optionally with a range.
    Point {
        position: Vec3,
        intensity: f32,
        range: Option<f32>,
    },
    /// Spot light of `intensity` cd pointing straight down (−Y).
    SpotDown {
        position: Vec3,
        intensity: f32,
        inner: f32,
        outer: f32,
    },
    /// Directional light of `illuminance` lx travelling along unit `direction`.
    Directional { direction: Vec3, illuminance: f32 },
}

impl Light {
    /// Irradiance on the upward-facing plane at ground point `p`, from the extension's
    /// definitions: point/spot I/d² · window · spot² · cosθ, with the recommended range window
    /// clamp(1 − (d/range)⁴, 0, 1) and spot falloff clamp(cd·scale + offset, 0, 1)²;
    /// directional E · cosθ.
    fn irradiance(&self, p: Vec3) -> f64 {
        match *self {
            Light::Point {
                position,
                intensity,
                range,
            } => {
                let to = (position - p).as_dvec3();
                let d = to.length();
                let window =
                    range.map_or(1.0, |r| (1.0 - (d / f64::from(r)).powi(4)).clamp(0.0, 1.0));
                f64::from(intensity) / (d * d) * window * (to.y / d).max(0.0)
            }
            Light::SpotDown {
                position,
                intensity,
                inner,
                outer,
            } => {
                let to = (position - p).as_dvec3();
                let d = to.length();
                let cd = to.y / d; // cos of the angle between the spot axis (−Y) and light → p
                let (ci, co) = (f64::from(inner).cos(), f64::from(outer).cos());
                let scale = 1.0 / (ci - co).max(0.001);
                let att = (cd * scale - co * scale).clamp(0.0, 1.0);
                f64::from(intensity) / (d * d) * att * att * (to.y / d).max(0.0)
            }
            Light::Directional {
                direction,
                illuminance,
            } => f64::from(illuminance) * f64::from(-direction.y).max(0.0),
        }
    }

    /// Circles on the plane (centre x, z and radius) across which the irradiance has a kink (the
    /// range cut-off, the spot cone edges): pixels straddling one are integrated less accurately.
    fn kinks(&self) -> Vec<(Vec3, f32)> {
        match *self {
            Light::Point {
                position,
                range: Some(r),
                ..
            } if r > position.y => {
                vec![(
                    position * Vec3::new(1.0, 0.0, 1.0),
                    (r * r - position.y * position.y).sqrt(),
                )]
            }
            Light::SpotDown {
                position,
                inner,
                outer,
                ..
            } => {
                let foot = position * Vec3::new(1.0, 0.0, 1.0);
                vec![
                    (foot, position.y * inner.tan()),
                    (foot, position.y * outer.tan()),
                ]
            }
            _ => Vec::new(),
        }
    }
}

/// A scene with one horizontal diffuse plane (albedo [`ALBEDO`], `x × z` at y = 0, facing up), a
/// camera above it looking down and ahead, and optionally a punctual light and a constant sky.
fn plane_scene(
    name: &str,
    x: [f32; 2],
    z: [f32; 2],
    light: Option<Light>,
    sky: Option<[f32; 3]>,
) -> Scene {
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::diffuse("plane", ALBEDO));
    let mesh = b.add_mesh("plane", &[plane_y(x, z, 0.0, mat)]);
    let mut roots = vec![b.add_node(&NodeDesc {
        name: Some("plane".into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    })];
    roots.push(camera_node(
        &mut b,
        CAMERA_POS,
        Quat::from_rotation_x(CAMERA_PITCH),
        CAMERA_YFOV,
    ));
    if let Some(light) = light {
        // Lights shine down their node's −Z axis.
        let (kind, position, rotation, intensity, range) = match light {
            Light::Point {
                position,
                intensity,
                range,
            } => (LightKind::Point, position, Quat::IDENTITY, intensity, range),
            Light::SpotDown {
                position,
                intensity,
                inner,
                outer,
            } => (
                LightKind::Spot {
                    inner_cone_angle: inner,
                    outer_cone_angle: outer,
                },
                position,
                Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
                intensity,
                None,
            ),
            Light::Directional {
                direction,
                illuminance,
            } => (
                LightKind::Directional,
                Vec3::new(0.0, 5.0, 0.0),
                Quat::from_rotation_arc(-Vec3::Z, direction),
                illuminance,
                None,
            ),
        };
        let l = b.add_light(&LightDesc {
            name: Some("light".into()),
            kind,
            color: [1.0; 3],
            intensity,
            range,
        });
        roots.push(b.add_node(&NodeDesc {
            name: Some("light".into()),
            translation: Some(position.to_array()),
            rotation: Some(rotation.to_array()),
            light: Some(l),
            ..NodeDesc::default()
        }));
    }
    let extras = sky.map(|l| serde_json::json!({"environment": {"radiance": l}}));
    b.add_scene(name, &roots, extras);
    write_and_load(&b, &temp_dir(name), name)
}

/// Where the camera ray through image position `(sx, sy)` (pixels, y down) meets the plane y = 0.
fn ground_hit(view: &CameraView, size: (u32, u32), sx: f64, sy: f64) -> Vec3 {
    let aspect = size.0 as f32 / size.1 as f32;
    let (x, y) = pixel_to_ndc(sx, sy, size.0, size.1);
    let d = view.ray_direction(x, y, aspect);
    assert!(
        d.y < 0.0,
        "image position ({sx}, {sy}) sees above the horizon"
    );
    view.position + d * (-view.position.y / d.y)
}

/// Mean and variance over pixel `(px, py)` of `f` at the camera rays of a k × k grid of
/// sub-pixel positions (midpoint rule).
fn pixel_integral(
    view: &CameraView,
    size: (u32, u32),
    (px, py): (u32, u32),
    k: u32,
    f: &dyn Fn(Vec3) -> f64,
) -> (f64, f64) {
    let mut values = Vec::with_capacity((k * k) as usize);
    for j in 0..k {
        for i in 0..k {
            let sx = f64::from(px) + (f64::from(i) + 0.5) / f64::from(k);
            let sy = f64::from(py) + (f64::from(j) + 0.5) / f64::from(k);
            values.push(f(ground_hit(view, size, sx, sy)));
        }
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var)
}

/// Whether the footprint of pixel `(px, py)` on the plane lies entirely on one side of every
/// kink circle of `light` (so the irradiance is smooth over it). The footprint is the convex quad
/// of the corner rays' hits: it is inside a disk when all its corners are, and outside when the
/// disk's centre is farther from it than the radius. A margin of 1e-4 m covers round-off.
fn smooth_over_pixel(
    view: &CameraView,
    size: (u32, u32),
    (px, py): (u32, u32),
    light: &Light,
) -> bool {
    let quad: Vec<(f64, f64)> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        .iter()
        .map(|&(dx, dy)| {
            let p = ground_hit(view, size, f64::from(px) + dx, f64::from(py) + dy);
            (f64::from(p.x), f64::from(p.z))
        })
        .collect();
    let quad = convex_hull(&quad);
    light.kinks().iter().all(|&(centre, radius)| {
        let (c, r) = (
            (f64::from(centre.x), f64::from(centre.z)),
            f64::from(radius),
        );
        let dist = |p: (f64, f64)| ((p.0 - c.0).powi(2) + (p.1 - c.1).powi(2)).sqrt();
        let inside = quad.iter().all(|&p| dist(p) < r - 1e-4);
        // Distance from the centre to the quad: 0 inside it, else to the nearest edge.
        let to_quad = if inside_margin(&quad, c) >= 0.0 {
            0.0
        } else {
            (0..quad.len())
                .map(|i| {
                    let (a, b) = (quad[i], quad[(i + 1) % quad.len()]);
                    let (ex, ez) = (b.0 - a.0, b.1 - a.1);
                    let t = (((c.0 - a.0) * ex + (c.1 - a.1) * ez) / (ex * ex + ez * ez))
                        .clamp(0.0, 1.0);
                    dist((a.0 + t * ex, a.1 + t * ez))
                })
                .fold(f64::INFINITY, f64::min)
        };
        inside || to_quad > r + 1e-4
    })
}

/// Renders the plane lit by `light` only and compares every pixel with the box-filtered analytic
/// radiance ρ/π · E(p) (direct light only: a plane cannot see itself, and nothing else is there).
fn check_direct_light(name: &str, light: Light) {
    let scene = plane_scene(name, [-20.0, 20.0], [-20.0, 20.0], Some(light), None);
    let (size, spp) = ((32u32, 32u32), 64u32);
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let out = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 3);
    drop(gpu);
    finish(ctx);

    let irradiance = |p: Vec3| light.irradiance(p);
    let view = scene.camera_at(0.0);
    let (mut sum_gpu, mut sum_cpu, mut var_sum, mut quad_err_sum) = (0.0, 0.0, 0.0, 0.0);
    let (mut smooth, mut dark) = (0, 0);
    let (mut all_gpu, mut all_cpu) = (0.0, 0.0);
    for py in 0..size.1 {
        for px in 0..size.0 {
            // The box filter: the pixel's value is the mean over its area. A 16×16 midpoint grid
            // integrates it; where the irradiance is smooth over the pixel, the grid's error is
            // bounded by its difference from the 8×8 grid (the midpoint rule's error drops ~4×
            // per halving).
            let (e16, var) = pixel_integral(&view, size, (px, py), 16, &irradiance);
            let gpu_px = out.pixels[(py * size.0 + px) as usize];
            let k1 = f64::from(ALBEDO[1]) / PI;
            all_gpu += f64::from(gpu_px[1]);
            all_cpu += k1 * e16;
            if !smooth_over_pixel(&view, size, (px, py), &light) {
                continue;
            }
            smooth += 1;
            if e16 == 0.0 {
                dark += 1;
            }
            let (e8, _) = pixel_integral(&view, size, (px, py), 8, &irradiance);
            let quad_err = (e16 - e8).abs();
            for (c, &albedo) in ALBEDO.iter().enumerate() {
                let k = f64::from(albedo) / PI;
                let expected = k * e16;
                // The only randomness is the jitter: the pixel mean of `spp` uniform positions has
                // variance var / spp.
                let tol = 5.0 * k * (var / f64::from(spp)).sqrt()
                    + k * quad_err
                    + FLOAT_SLACK * 10.0 * expected;
                let got = f64::from(gpu_px[c]);
                assert!(
                    (got - expected).abs() <= tol,
                    "{name}: pixel ({px}, {py}) channel {c}: {got}, expected {expected} ± {tol}"
                );
            }
            sum_gpu += f64::from(gpu_px[1]);
            sum_cpu += k1 * e16;
            var_sum += k1 * k1 * var / f64::from(spp);
            quad_err_sum += k1 * quad_err;
        }
    }
    let se = var_sum.sqrt();
    eprintln!(
        "{name}: {smooth} smooth pixels ({dark} unlit), sum {sum_gpu:.6} vs analytic {sum_cpu:.6} \
         (SE {se:.2e}); whole image mean {:.6} vs {:.6}",
        all_gpu / f64::from(size.0 * size.1),
        all_cpu / f64::from(size.0 * size.1)
    );
    assert!(
        smooth >= 800 && smooth - dark >= 300,
        "{name}: only {smooth} pixels away from kinks, {dark} of them unlit"
    );
    assert!(
        (sum_gpu - sum_cpu).abs() < 5.0 * se + quad_err_sum + FLOAT_SLACK * 10.0 * sum_cpu,
        "{name}: sum over smooth pixels {sum_gpu}, analytic {sum_cpu}, SE {se}"
    );
    let rel = (all_gpu - all_cpu).abs() / all_cpu;
    assert!(rel < 0.01, "{name}: whole-image mean off by {rel}");
}

#[test]
fn plane_under_a_point_light_matches_the_analytic_direct_light() {
    check_direct_light(
        "point",
        Light::Point {
            position: Vec3::new(0.4, 1.2, -0.5),
            intensity: 3.0,
            range: None,
        },
    );
}

#[test]
fn point_light_range_uses_the_recommended_window() {
    // The cut-off circle (d = 3.5 m) crosses the upper part of the view; beyond it pixels are
    // unlit, inside it the window clamp(1 − (d/range)⁴, 0, 1) dims the light smoothly.
    check_direct_light(
        "point_range",
        Light::Point {
            position: Vec3::new(0.4, 1.2, -0.5),
            intensity: 3.0,
            range: Some(3.5),
        },
    );
}

#[test]
fn spot_light_matches_the_recommended_falloff() {
    check_direct_light(
        "spot",
        Light::SpotDown {
            position: Vec3::new(0.2, 2.0, -0.8),
            intensity: 4.0,
            inner: 0.35,
            outer: 0.7,
        },
    );
}

#[test]
fn directional_light_lights_the_plane_uniformly() {
    check_direct_light(
        "directional",
        Light::Directional {
            direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
            illuminance: 2.0,
        },
    );
}

#[test]
fn plane_under_a_constant_sky_reflects_albedo_times_sky() {
    let sky = [0.7f32, 1.3, 2.0];
    let (x, z) = ([-1.5f32, 3.0], [-3.0f32, 2.5]);
    let scene = plane_scene("sky_plane", x, z, None, Some(sky));
    let (size, spp) = ((32u32, 32u32), 8u32);
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let out = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 5);
    drop(gpu);
    finish(ctx);

    // The plane's outline in the image (all four corners are in front of the camera).
    let view = scene.camera_at(0.0);
    let aspect = size.0 as f32 / size.1 as f32;
    let corners: Vec<(f64, f64)> = [(x[0], z[0]), (x[0], z[1]), (x[1], z[1]), (x[1], z[0])]
        .iter()
        .map(|&(cx, cz)| {
            let ndc = view
                .project(Vec3::new(cx, 0.0, cz), aspect)
                .expect("plane corner in front of the camera");
            ndc_to_pixel(ndc.x, ndc.y, size.0, size.1)
        })
        .collect();
    let outline = convex_hull(&corners);
    assert_eq!(outline.len(), 4);

    // Every sample of a plane pixel is camera → plane → cosine bounce → sky = ρ·L exactly (f32
    // products of the same numbers); every sample of a sky pixel is L.
    let rel_tol = 1e-4;
    let (mut on_plane, mut on_sky, mut partial) = (0, 0, 0);
    for py in 0..size.1 {
        for px in 0..size.0 {
            let got = out.pixels[(py * size.0 + px) as usize];
            match pixel_coverage(&outline, px, py, 1e-3) {
                Coverage::Inside => {
                    on_plane += 1;
                    for c in 0..3 {
                        let expected = ALBEDO[c] * sky[c];
                        assert!(
                            (got[c] - expected).abs() <= rel_tol * expected,
                            "plane pixel ({px}, {py}) channel {c}: {}, expected {expected}",
                            got[c]
                        );
                    }
                }
                Coverage::Outside => {
                    on_sky += 1;
                    for c in 0..3 {
                        assert!(
                            (got[c] - sky[c]).abs() <= rel_tol * sky[c],
                            "sky pixel ({px}, {py}) channel {c}: {}, expected {}",
                            got[c],
                            sky[c]
                        );
                    }
                }
                Coverage::Partial(f) => {
                    partial += 1;
                    // Each sample is ρL (plane) or L (sky): the fraction of plane samples is
                    // binomial with mean f; allow 5σ plus one sample (discreteness).
                    let c = 2;
                    let (l, rl) = (f64::from(sky[c]), f64::from(ALBEDO[c] * sky[c]));
                    let frac = (l - f64::from(got[c])) / (l - rl);
                    let tol = 5.0 * (f * (1.0 - f) / f64::from(spp)).sqrt() + 1.0 / f64::from(spp);
                    assert!(
                        (frac - f).abs() <= tol + f64::from(rel_tol),
                        "edge pixel ({px}, {py}): plane fraction {frac}, covered area {f}"
                    );
                }
            }
        }
    }
    eprintln!("sky plane: {on_plane} plane pixels, {on_sky} sky pixels, {partial} edge pixels");
    assert!(
        on_plane >= 300 && on_sky >= 100,
        "the view does not show both"
    );
}

#[test]
fn seeds_give_independent_images_and_reproduce_exactly() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = load(&root.join("assets/cornell/cornell.gltf"));
    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let (size, spp) = ((32u32, 32u32), 8u32);
    let a = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 1);
    let b = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 2);
    let a_again = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 1);
    drop(gpu);
    finish(ctx);

    assert!(
        a.pixels == a_again.pixels,
        "the same seed did not reproduce the image"
    );
    let differing = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p != q)
        .count();
    assert!(
        differing > a.pixels.len() / 2,
        "only {differing} pixels differ between seeds 1 and 2"
    );
    // Independent estimates of the same image: the per-pixel differences average to zero.
    for c in 0..3 {
        let diff: Vec<f64> = a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(p, q)| f64::from(p[c]) - f64::from(q[c]))
            .collect();
        let s = mean_se(&diff);
        let scale = mean_se(&channel(&a, c)).mean;
        assert!(
            s.mean.abs() < 5.0 * s.se + FLOAT_SLACK * scale,
            "channel {c}: mean difference {} with SE {}",
            s.mean,
            s.se
        );
    }
}

#[test]
fn textured_emitter_seen_directly_is_factor_times_texel() {
    // A black quad facing the camera and filling the view, emitting `factor` × its sRGB emissive
    // texture (uniform texels, so the bilinear lookup is the texel itself). Nothing else emits or
    // reflects: every camera sample returns exactly the emitted radiance of the first hit.
    let factor = [2.0f32, 1.5, 1.0];
    let texel = [200u8, 100, 50, 255];
    let mut b = GltfBuilder::new();
    let tex = b
        .add_texture_rgba8(2, 2, &texel.repeat(4), 10497)
        .expect("PNG encoding");
    let mat = b.add_material(&MaterialDesc {
        emissive: factor,
        emissive_texture: Some(tex),
        ..MaterialDesc::diffuse("glow", [0.0; 3])
    });
    let mut quad = radcache_scene::writer::PrimitiveDesc::triangles(
        vec![
            [-5.0, -5.0, 0.0],
            [5.0, -5.0, 0.0],
            [5.0, 5.0, 0.0],
            [-5.0, 5.0, 0.0],
        ],
        Some(vec![[0.0, 0.0, 1.0]; 4]),
        vec![0, 1, 2, 0, 2, 3],
        Some(mat),
    );
    quad.texcoords = Some(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
    let mesh = b.add_mesh("glow", &[quad]);
    let quad_node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let cam = camera_node(&mut b, Vec3::new(0.0, 0.0, 3.0), Quat::IDENTITY, 0.7);
    b.add_scene("glow", &[quad_node, cam], None);
    let scene = write_and_load(&b, &temp_dir("glow"), "glow");

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let out = render(&ctx, &shaders, &scene, &mut gpu, (8, 8), 4, 9);
    drop(gpu);
    finish(ctx);

    let expected: Vec<f32> = (0..3)
        .map(|c| factor[c] * radcache_scene::math::srgb_to_linear(f32::from(texel[c]) / 255.0))
        .collect();
    for (i, p) in out.pixels.iter().enumerate() {
        for c in 0..3 {
            assert!(
                (p[c] - expected[c]).abs() <= 1e-4 * expected[c],
                "pixel {i} channel {c}: {}, expected factor × texel = {}",
                p[c],
                expected[c]
            );
        }
    }
}
