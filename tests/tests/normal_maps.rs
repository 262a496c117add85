//! Normal maps on lavapipe (docs/materials.md §12):
//!
//! - The GLSL twin `shaders/common/normal_map.glsl` against `radcache_material::normal_map` over a
//!   table of rows (random and edge cases: flat, zero and saturated texels, scale 0, negative and
//!   huge scales, tangents zero, parallel to the normal or of either handedness, interpolated
//!   normals past the geometric horizon, texels pointing into the surface). Tolerance: the
//!   harness's `|gpu − cpu| <= 1e-5 · max(|cpu|, scale) + 1e-6`; rows within 5 % of a
//!   degenerate tangent (where Gram–Schmidt loses digits) or within 1e-3 of a branch are drawn
//!   again.
//! - A Lambertian plane under a directional light with a constant normal map that tilts its
//!   normal by θ: each pixel is ρ/π · E · cos(θ_light − θ) (the light lies in the plane of the
//!   tilted normal), not ρ/π · E · cos θ_light, in the path tracer (every sample is that value:
//!   the plane cannot see itself and nothing else is there) and in the cache's frame (its
//!   direct pass at the G-buffer's mapped normals; the records gather nothing). The same plane
//!   under a mirroring node, lit from the mirrored direction, gives the same values (the
//!   handedness flips with the mirror); with scale 0 the map is flat.

use std::f32::consts::PI;

use glam::{Quat, Vec3, Vec4};
use radcache_cache::IcParams;
use radcache_material::brdf::COS_MIN;
use radcache_material::normal_map::{
    normal_map_decode, normal_map_normal, normal_map_perpendicular,
};
use radcache_material::{brdf_eval, Material};
use radcache_render::{render_ic, FrameOutput, GpuScene, IcSettings};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{EnvOverride, LoadOptions, Scene};
use radcache_tests::scenes::{
    camera_node, path_and_cache, pixel_to_ndc, render, temp_dir, write_and_load,
};
use radcache_tests::twin::{
    check_diffs, twin_pipeline, unit, v4, vec, Case, Expect, Row, ShaderMode,
};
use radcache_tests::{context, finish, shaders, Rng};

/// The twin shader's only mode.
#[derive(Clone, Copy)]
struct NormalMapMode;

impl ShaderMode for NormalMapMode {
    fn bits(self) -> u32 {
        0
    }
}

fn row(n: Vec3, ng: Vec3, t: Vec4, texel: Vec3, scale: f32) -> Case {
    let mut r: Row = [[0.0; 4]; 16];
    r[0] = v4(n, scale);
    r[1] = v4(ng, 0.0);
    r[2] = t.to_array();
    r[3] = v4(texel, 0.0);
    let mut e = Expect::new();
    e.v(0, normal_map_normal(n, ng, t, texel, scale), 1.0);
    e.v(1, normal_map_decode(texel, scale), scale.abs().max(1.0));
    e.v(2, normal_map_perpendicular(n), 1.0);
    (r, e)
}

/// Random rows away from the functions' branches, then edge rows.
fn cases(rng: &mut Rng) -> Vec<Case> {
    let mut out = Vec::new();
    while out.len() < 600 {
        let n = unit(rng);
        let ng = if out.len() % 3 == 0 { n } else { unit(rng) };
        let t3 = vec(rng, 2.0);
        let w = [1.0, -1.0, 0.0, 0.3][out.len() % 4];
        let texel = match out.len() % 5 {
            0 => Vec3::new(rng.f32(), rng.f32(), rng.f32()),
            // 8-bit texels as the GPU decodes them.
            _ => Vec3::new(rng.f32(), rng.f32(), rng.f32()).map(|c| (c * 255.0).round() / 255.0),
        };
        let scale = [1.0, 0.0, 0.5, 2.0, -1.0, rng.range(-3.0, 3.0)][out.len() % 6];
        let d = n.dot(ng);
        let n_used = if d > 0.0 { n } else { ng };
        let across = (t3 - n_used * n_used.dot(t3)).length() / t3.length();
        if d.abs() < 1e-3 || across < 0.05 || (n.x.abs() - 0.9).abs() < 1e-3 {
            continue;
        }
        if (n_used.x.abs() - 0.9).abs() < 1e-3 {
            continue;
        }
        out.push(row(n, ng, t3.extend(w), texel, scale));
    }
    let y = Vec3::Y;
    let tilted = Vec3::new(0.9, 0.2, 0.3).normalize();
    let t = Vec4::new(1.0, 0.0, 0.0, 1.0);
    for texel in [
        Vec3::new(0.5, 0.5, 1.0),
        Vec3::ZERO,
        Vec3::ONE,
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(1.0, 0.5, 0.5),
        Vec3::new(0.0, 1.0, 0.55),
        Vec3::new(200.0, 128.0, 230.0) / 255.0,
    ] {
        for scale in [1.0, 0.0, -1.0, 8.0, 1e20] {
            for (n, ng) in [
                (y, y),
                (tilted, y),
                (-tilted, y),
                (Vec3::new(0.95, 0.31, 0.0).normalize(), y),
            ] {
                for tangent in [
                    t,
                    Vec4::new(0.0, 0.0, 1.0, -1.0),
                    Vec4::ZERO,
                    (y * 2.0).extend(1.0),
                    Vec4::new(3.0, 5.0, -2.0, 0.0),
                ] {
                    out.push(row(n, ng, tangent, texel, scale));
                }
            }
        }
    }
    out
}

#[test]
fn the_glsl_normal_map_matches_the_rust_twin() {
    let ctx = context();
    let pl = twin_pipeline(&ctx, "normal_map_twin.comp", "normal_map_twin");
    let mut rng = Rng::new(17);
    let rows = cases(&mut rng);
    let diffs = check_diffs(&ctx, &pl, NormalMapMode, &rows, &[]);
    for (slot, what) in [
        (0, "normal_map_normal"),
        (1, "normal_map_decode"),
        (2, "normal_map_perpendicular"),
    ] {
        let d = diffs[slot].iter().fold((0.0f32, 0.0f32), |a, d| {
            (a.0.max(d.abs), a.1.max(d.of_tolerance))
        });
        eprintln!(
            "{what}: {} rows, largest |gpu − cpu| {:.2e} ({:.2} of the tolerance)",
            rows.len(),
            d.0,
            d.1
        );
    }
    drop(pl);
    finish(ctx);
}

const ALBEDO: [f32; 3] = [0.8, 0.5, 0.25];
const ILLUMINANCE: f32 = 2.0;
/// The light's angle from the plane's normal.
const THETA_LIGHT: f32 = 0.9;

/// An 8-bit texel whose tangent-space normal is tilted by `theta` toward azimuth `phi`.
fn texel_for(theta: f32, phi: f32) -> [u8; 4] {
    let m = Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    );
    let c = (m + Vec3::ONE) * 0.5 * 255.0;
    [c.x.round() as u8, c.y.round() as u8, c.z.round() as u8, 255]
}

/// The world normal the map gives on the plane y = 0 with u along +x and v along +z, worked out
/// by hand: tangent +x, bitangent (up the image, −v) −z, normal +y; mirrored in x by a node of
/// scale (−1, 1, 1), its x component changes sign.
fn mapped_normal(texel: [u8; 4], scale: f32, mirror: bool) -> Vec3 {
    let m = |c: u8| 2.0 * f32::from(c) / 255.0 - 1.0;
    let (x, y, z) = (m(texel[0]) * scale, m(texel[1]) * scale, m(texel[2]));
    let n = Vec3::new(x, z, -y).normalize();
    if mirror {
        Vec3::new(-n.x, n.y, n.z)
    } else {
        n
    }
}

/// Toward the light: `THETA_LIGHT` from +y, in the vertical plane of `n` (or along +x when `n`
/// is vertical).
fn light_toward(n: Vec3) -> Vec3 {
    let h = Vec3::new(n.x, 0.0, n.z).try_normalize().unwrap_or(Vec3::X);
    Vec3::Y * THETA_LIGHT.cos() + h * THETA_LIGHT.sin()
}

/// A 40 m Lambertian plane at y = 0 (u = x/4, v = z/4) with a constant normal map, optionally
/// under a mirroring node, a directional light arriving from `to_light`, and a camera above.
fn bumpy_plane(tag: &str, texel: [u8; 4], scale: f32, mirror: bool, to_light: Vec3) -> Scene {
    let mut scene = bumpy_plane_with_layer(tag, texel, scale, mirror, to_light);
    // Lambertian: no dielectric specular layer (`specularFactor` 0, as KHR_materials_specular
    // writes it).
    scene.materials[0].specular_factor = 0.0;
    assert!(scene.materials[0].is_lambertian());
    scene
}

/// [`bumpy_plane`] with glTF's default dielectric specular layer (F0 0.04, roughness 1).
fn bumpy_plane_with_layer(
    tag: &str,
    texel: [u8; 4],
    scale: f32,
    mirror: bool,
    to_light: Vec3,
) -> Scene {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(2, 2, &texel.repeat(4), 10497).unwrap();
    let mat = b.add_material(&MaterialDesc {
        normal_texture: Some((tex, scale)),
        ..MaterialDesc::metal_rough("bumpy", ALBEDO, 0.0, 1.0)
    });
    let (x, z) = ([-20.0f32, 20.0], [-20.0f32, 20.0]);
    let positions = vec![
        [x[0], 0.0, z[0]],
        [x[0], 0.0, z[1]],
        [x[1], 0.0, z[1]],
        [x[1], 0.0, z[0]],
    ];
    let prim = PrimitiveDesc {
        texcoords: Some(positions.iter().map(|p| [p[0] / 4.0, p[2] / 4.0]).collect()),
        ..PrimitiveDesc::triangles(
            positions,
            Some(vec![[0.0, 1.0, 0.0]; 4]),
            vec![0, 1, 2, 0, 2, 3],
            Some(mat),
        )
    };
    let mesh = b.add_mesh("plane", &[prim]);
    let mut roots = vec![b.add_node(&NodeDesc {
        name: Some("plane".into()),
        mesh: Some(mesh),
        scale: mirror.then_some([-1.0, 1.0, 1.0]),
        ..NodeDesc::default()
    })];
    roots.push(camera_node(
        &mut b,
        Vec3::new(0.0, 2.0, 3.0),
        Quat::from_rotation_x(-0.6),
        0.7,
    ));
    let light = b.add_light(&LightDesc {
        name: Some("sun".into()),
        kind: LightKind::Directional,
        color: [1.0; 3],
        intensity: ILLUMINANCE,
        range: None,
    });
    roots.push(b.add_node(&NodeDesc {
        name: Some("sun".into()),
        translation: Some([0.0, 5.0, 0.0]),
        rotation: Some(Quat::from_rotation_arc(-Vec3::Z, -to_light).to_array()),
        light: Some(light),
        ..NodeDesc::default()
    }));
    b.add_scene(tag, &roots, None);
    let scene = write_and_load(&b, &temp_dir(tag), tag);
    assert_eq!(mat, 0);
    scene
}

/// Every pixel against ρ/π · E · cos; returns the largest relative error.
fn check_uniform(what: &str, out: &FrameOutput, cos: f32, rel_tol: f32) -> f32 {
    assert_eq!(out.nonfinite_pixels, 0, "{what}");
    let mut worst = 0.0f32;
    for (i, p) in out.pixels.iter().enumerate() {
        for c in 0..3 {
            let want = ALBEDO[c] / PI * ILLUMINANCE * cos;
            let rel = (p[c] - want).abs() / want;
            assert!(
                rel <= rel_tol,
                "{what}: pixel {i} channel {c}: {}, expected {want}",
                p[c]
            );
            worst = worst.max(rel);
        }
    }
    worst
}

#[test]
fn a_tilting_normal_map_changes_the_cosine_on_a_plane() {
    let ctx = context();
    let shaders = shaders();
    let texel = texel_for(0.35, 0.6);
    let size = (24u32, 24u32);
    for (tag, scale, mirror) in [
        ("tilted", 1.0f32, false),
        ("mirrored", 1.0, true),
        ("flat", 0.0, false),
    ] {
        let n = mapped_normal(texel, scale, mirror);
        // The light is placed from the unmirrored normal and mirrored with the plane.
        let l = light_toward(mapped_normal(texel, scale, false));
        let l = if mirror { Vec3::new(-l.x, l.y, l.z) } else { l };
        let theta = Vec3::new(n.x, 0.0, n.z).length().atan2(n.y);
        let cos = n.dot(l);
        assert!(
            (cos - (THETA_LIGHT - theta).cos()).abs() < 1e-5,
            "the light is in n's plane"
        );
        let scene = bumpy_plane(&format!("bumpy-{tag}"), texel, scale, mirror, l);
        assert!(scene.plan().normal_maps);
        let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
        let out = render(&ctx, &shaders, &scene, &mut gpu, size, 4, 7);
        let pt = check_uniform(&format!("path tracer, {tag}"), &out, cos, 1e-5);
        let settings = IcSettings {
            width: size.0,
            height: size.1,
            params: IcParams::default(),
            ..IcSettings::default()
        };
        let (ic, _) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
        let cache = check_uniform(&format!("cache frame, {tag}"), &ic, cos, 1e-5);
        eprintln!(
            "{tag}: θ {theta:.4} rad, θ_light {THETA_LIGHT}: cos(θ_light − θ) {cos:.5} (unmapped \
             cos θ_light {:.5}); largest relative error: path tracer {pt:.2e}, cache frame \
             {cache:.2e}",
            THETA_LIGHT.cos()
        );
        drop(gpu);
    }
    finish(ctx);
}

/// The unit direction toward the camera from where the ray through image position `(sx, sy)`
/// (pixels) meets the plane y = 0.
fn to_camera(scene: &Scene, size: (u32, u32), sx: f64, sy: f64) -> Vec3 {
    let view = scene.camera_at(0.0);
    let (x, y) = pixel_to_ndc(sx, sy, size.0, size.1);
    -view.ray_direction(x, y, size.0 as f32 / size.1 as f32)
}

/// E · f(v, l) · (n·l) of the glTF BRDF (`radcache-material`) in the frame of the passes'
/// `bsdf_at`: the shading normal `ns`, or the geometric normal +y where `ns` faces away from
/// the viewer. Also says whether `ns` was used.
fn reflected(m: &Material, ns: Vec3, v: Vec3, l: Vec3) -> (Vec3, bool) {
    let mapped = ns.dot(v) > COS_MIN;
    let n = if mapped { ns } else { Vec3::Y };
    let x = (v - n * n.dot(v)).normalize();
    let y = n.cross(x);
    let local = |d: Vec3| Vec3::new(d.dot(x), d.dot(y), d.dot(n));
    let l_local = local(l);
    (
        brdf_eval(m, local(v), l_local) * l_local.z * ILLUMINANCE,
        mapped,
    )
}

#[test]
fn a_normal_map_tilts_the_specular_shading_frame_too() {
    // glTF's default dielectric layer (HAS_SPECULAR): each pixel is E·f(v, l)·(n·l) in the
    // mapped normal's frame (the geometric one where the mapped normal faces away from the
    // viewer: `bsdf_at`), which changes with the view across a pixel; its box-filtered value
    // lies between the extremes of a 6×6 grid over the pixel (the tolerance, plus 1e-5).
    let ctx = context();
    let shaders = shaders();
    // Tilted by 0.7 rad, mostly away from the camera: the upper rows see its back.
    let texel = texel_for(0.7, 1.2);
    let size = (16u32, 16u32);
    let n = mapped_normal(texel, 1.0, false);
    let l = light_toward(n);
    let scene = bumpy_plane_with_layer("bumpy-specular", texel, 1.0, false, l);
    let plan = scene.plan();
    assert!(plan.specular && plan.normal_maps);
    let m = Material::metal_rough(Vec3::from(ALBEDO), 0.0, 1.0);
    // Per pixel: the mean and extremes over the grid, or None where the frame switches inside
    // the pixel (corners included); and whether the mapped normal is the frame.
    let k = 6u32;
    let expected: Vec<Option<(Vec3, Vec3, Vec3, bool)>> = (0..size.0 * size.1)
        .map(|i| {
            let (px, py) = (f64::from(i % size.0), f64::from(i / size.0));
            let (mut sum, mut lo, mut hi) = (Vec3::ZERO, Vec3::splat(f32::MAX), Vec3::ZERO);
            let mut frames = Vec::new();
            for j in 0..k * k {
                let sx = px + (f64::from(j % k) + 0.5) / f64::from(k);
                let sy = py + (f64::from(j / k) + 0.5) / f64::from(k);
                let (r, mapped) = reflected(&m, n, to_camera(&scene, size, sx, sy), l);
                sum += r;
                lo = lo.min(r);
                hi = hi.max(r);
                frames.push(mapped);
            }
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                frames.push(reflected(&m, n, to_camera(&scene, size, px + dx, py + dy), l).1);
            }
            let mapped = frames[0];
            frames
                .iter()
                .all(|&f| f == mapped)
                .then(|| (sum / (k * k) as f32, lo, hi, mapped))
        })
        .collect();
    let (mixed, flipped) = (
        expected.iter().filter(|e| e.is_none()).count(),
        expected.iter().filter(|e| e.is_some_and(|e| !e.3)).count(),
    );
    let in_mapped_frame = expected.len() - mixed - flipped;
    assert!(
        flipped >= 10 && in_mapped_frame >= 10,
        "{flipped} / {in_mapped_frame}"
    );
    let (pt, ic) = path_and_cache(&ctx, &shaders, &scene, size, 8, 11);
    finish(ctx);
    for (what, out) in [("path tracer", &pt), ("cache frame", &ic)] {
        assert_eq!(out.nonfinite_pixels, 0);
        let mut worst = 0.0f32;
        for (i, (p, e)) in out.pixels.iter().zip(&expected).enumerate() {
            let Some((mean, lo, hi, _)) = *e else {
                continue;
            };
            for c in 0..3 {
                let slack = 1e-5 * hi[c];
                assert!(
                    p[c] >= lo[c] - slack && p[c] <= hi[c] + slack,
                    "{what}: pixel {i} channel {c}: {} outside [{}, {}]",
                    p[c],
                    lo[c],
                    hi[c]
                );
                worst = worst.max((p[c] - mean[c]).abs() / mean[c]);
            }
        }
        let lambert = ALBEDO[1] / PI * ILLUMINANCE * n.dot(l);
        eprintln!(
            "{what}, specular layer: {} pixels compared ({in_mapped_frame} in the mapped frame, \
             {flipped} in the geometric one: the mapped normal faces away from the viewer; {mixed} \
             straddling the switch skipped), \
             largest relative deviation from the pixel means {worst:.2e} (green at the centre \
             {:.5}, Lambert alone {lambert:.5})",
            expected.len() - mixed,
            out.pixels[(size.1 / 2 * size.0 + size.0 / 2) as usize][1]
        );
    }
}

/// `shared/models/<rel>` in the nearest ancestor of the repository that has `shared/models`
/// (CI: beside the checkout; a worktree may sit deeper).
fn shared_model(rel: &str) -> std::path::PathBuf {
    let repo = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let repo = repo.canonicalize().unwrap();
    let models = repo
        .ancestors()
        .skip(1)
        .map(|d| d.join("shared/models"))
        .find(|d| d.is_dir())
        .unwrap_or_else(|| panic!("no shared/models beside {} or above it", repo.display()));
    models.join(rel)
}

#[test]
fn damaged_helmet_renders_with_its_generated_tangents() {
    // A real normal map on generated tangents, with the specular BRDF and textured emission, in
    // every pass: finite images, no validation error, and the cache frame near the path tracer.
    let path = shared_model("DamagedHelmet/glTF-Binary/DamagedHelmet.glb");
    let opts = LoadOptions {
        env: EnvOverride {
            radiance: Some([0.8; 3]),
            ..EnvOverride::default()
        },
        ..LoadOptions::default()
    };
    let (scene, _) = Scene::load(&path, &opts).unwrap();
    let plan = scene.plan();
    assert!(plan.normal_maps && plan.specular);
    let ctx = context();
    let shaders = shaders();
    let size = (24u32, 24u32);
    let (pt, ic) = path_and_cache(&ctx, &shaders, &scene, size, 16, 5);
    finish(ctx);
    assert_eq!(ic.nonfinite_pixels, 0);
    let mean = |o: &FrameOutput| {
        o.pixels
            .iter()
            .map(|p| f64::from(p[0] + p[1] + p[2]))
            .sum::<f64>()
            / o.pixels.len() as f64
    };
    assert!(ic
        .pixels
        .iter()
        .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
    let (m_pt, m_ic) = (mean(&pt), mean(&ic));
    eprintln!(
        "DamagedHelmet {}×{}: mean radiance (r+g+b) path tracer {m_pt:.4}, cache frame {m_ic:.4}",
        size.0, size.1
    );
    assert!(
        m_pt > 0.1 && (m_ic / m_pt - 1.0).abs() < 0.1,
        "{m_pt} vs {m_ic}"
    );
}
