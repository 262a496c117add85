//! The reference path tracer under punctual lights and a constant sky, against closed forms on
//! lavapipe: a diffuse plane under one light (point, point with range, spot, directional) sees only
//! direct light (a plane cannot see itself), so each pixel is the box-filtered ρ/π · E(p) of the
//! KHR_lights_punctual formulas, integrated here on the CPU through the same camera; under a
//! constant sky each plane sample is exactly ρ·L and each sky sample exactly L.

use std::f64::consts::PI;

use glam::{Quat, Vec3};
use radcache_render::GpuScene;
use radcache_scene::light::LightKind;
use radcache_scene::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc};
use radcache_scene::{CameraView, Scene};
use radcache_tests::scenes::{
    camera_node, convex_hull, inside_margin, ndc_to_pixel, path_and_cache, pixel_coverage,
    pixel_to_ndc, plane_y, render, temp_dir, write_and_load, Coverage, FLOAT_SLACK,
};
use radcache_tests::{context, finish, shaders};

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

/// A 12 m floor at y = 0 lit by a 0.5 m square emitter 2 m above the world origin. A coordinate
/// near 0 (here every floor point's y) is offset off its surface by a fixed scene scale / 65536
/// (2.6e-4 m here): more than the 1e-4 of the 2 m shadow ray by which it stops short of the light. Measured
/// from the surface point, such shadow rays ended past the emitter and hit it, and the floor got
/// about 5 % of its light. Every pixel is ρ/π · L · (the emitter's projected solid angle,
/// Lambert's formula), path tracer and cache frame.
#[test]
fn a_floor_at_the_world_origin_sees_an_emitter_above_it() {
    use radcache_material::polygon::triangle_projected_solid_angle;
    let (le, half, height) = (10.0f32, 0.25f32, 2.0f32);
    let mut b = GltfBuilder::new();
    let floor = b.add_material(&MaterialDesc::diffuse("floor", ALBEDO));
    let lamp = b.add_material(&MaterialDesc {
        double_sided: true,
        ..MaterialDesc::emitter("lamp", [0.0; 3], [le; 3])
    });
    let meshes = [
        ("floor", plane_y([-6.0, 6.0], [-6.0, 6.0], 0.0, floor)),
        ("lamp", plane_y([-half, half], [-half, half], height, lamp)),
    ];
    let mut roots = Vec::new();
    for (name, prim) in meshes {
        let mesh = b.add_mesh(name, &[prim]);
        roots.push(b.add_node(&NodeDesc {
            name: Some(name.into()),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }));
    }
    roots.push(camera_node(
        &mut b,
        Vec3::new(0.0, 1.0, 2.5),
        Quat::from_rotation_x(-0.38),
        0.25,
    ));
    b.add_scene("origin_floor", &roots, None);
    let scene = write_and_load(&b, &temp_dir("origin_floor"), "origin_floor");
    let lamp_tris = [
        [
            Vec3::new(-half, height, -half),
            Vec3::new(-half, height, half),
            Vec3::new(half, height, half),
        ],
        [
            Vec3::new(-half, height, -half),
            Vec3::new(half, height, half),
            Vec3::new(half, height, -half),
        ],
    ];
    let irradiance = |p: Vec3| -> f64 {
        lamp_tris
            .iter()
            .map(|t| f64::from(le * triangle_projected_solid_angle(p, Vec3::Y, *t)))
            .sum()
    };
    let size = (16u32, 16u32);
    let ctx = context();
    let shaders = shaders();
    let (pt, ic) = path_and_cache(&ctx, &shaders, &scene, size, 64, 9);
    finish(ctx);
    let view = scene.camera_at(0.0);
    for (what, out) in [("path tracer", &pt), ("cache frame", &ic)] {
        let (mut sum_got, mut sum_expected, mut worst) = (0.0f64, 0.0f64, 0.0f64);
        for py in 0..size.1 {
            for px in 0..size.0 {
                let (e, _) = pixel_integral(&view, size, (px, py), 4, &irradiance);
                let p = ground_hit(&view, size, f64::from(px) + 0.5, f64::from(py) + 0.5);
                assert!(
                    p.x.abs() < 3.0 && p.z.abs() < 3.0,
                    "pixel ({px}, {py}) sees {p}"
                );
                let pixel = out.pixels[(py * size.0 + px) as usize];
                for (&albedo, &value) in ALBEDO.iter().zip(&pixel) {
                    let expected = f64::from(albedo) / PI * e;
                    let got = f64::from(value);
                    worst = worst.max((got / expected - 1.0).abs());
                    sum_got += got;
                    sum_expected += expected;
                }
            }
        }
        let ratio = sum_got / sum_expected;
        eprintln!("{what}: image over closed form {ratio:.5}, worst pixel {worst:.4}");
        assert!((ratio - 1.0).abs() < 0.01, "{what}: ratio {ratio}");
        assert!(worst < 0.05, "{what}: worst pixel off by {worst}");
    }
}
