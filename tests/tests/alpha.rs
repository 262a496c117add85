//! glTF alpha modes (issue 17; docs/materials.md §11) on lavapipe, against closed forms. Every
//! material is Lambertian (the writer's `specularFactor` 0, checked by `lambertian`) so the
//! closed forms are those of ρ/π.
//!
//! - A MASK quad textured with a 4 × 4 checkerboard of alpha 0 and 1, under a uniform sky, in
//!   front of a black emissive backdrop: every pixel wholly inside an opaque cell is the quad's
//!   ρ·L (a plane under a uniform sky sees only the sky), wholly inside a transparent cell or
//!   beside the quad the backdrop's radiance. Bilinear filtering of a 0/1 checkerboard crosses
//!   alpha/cutoff = 1/2 exactly on the cell edges, so the cells are exact squares. The same mesh
//!   holds an OPAQUE primitive with the same texture, which must show whole (one BLAS geometry,
//!   non-opaque, with an opaque material in it). Path tracer (and its albedo AOV) and the cache's
//!   frame (rasterized G-buffer, its occluder rays, the emission pass); the path tracer again with
//!   the glossy default dielectric.
//! - The quad's shadow: a black MASK quad between a diffuse floor and a directional light casts
//!   its checkerboard; every floor pixel wholly inside a cell's shadow is 0, wholly inside a
//!   transparent cell's shadow or outside the quad's shadow ρ/π·E·cos θ (nothing else lights the
//!   floor: the quad is black and there is no sky). Path tracer and cache frame.
//! - A MASK emitter over a floor: the floor's radiance is ρ/π·L times the projected solid angle
//!   of the opaque cells alone (Lambert's formula), light sampling and BSDF sampling alike.
//! - A BLEND quad of alpha 0.5 in front of the sky: each sample sees the quad (ρ·L) or the sky
//!   (L) with probability ½, so pixels converge to their mean with binomial spread.
//! - Opaque scenes (and the Cornell box) plan no alpha test and compile none.

use std::f64::consts::PI;
use std::path::PathBuf;

use glam::{Quat, Vec3};
use radcache_material::polygon::triangle_projected_solid_angle;
use radcache_render::{
    render_ic, render_path, Budget, FrameOutput, GpuScene, IcSettings, PathSettings,
};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{CameraView, Scene};
use radcache_tests::scenes::{
    camera_node, convex_hull, load, mean_se, ndc_to_pixel, pixel_coverage, plane_y, render,
    temp_dir, write_and_load, Coverage, Polygon,
};
use radcache_tests::{context, finish, shaders};

/// Cells of the checkerboard texture per side.
const CELLS: usize = 4;
/// Margin (pixels) for a pixel to count as wholly inside or outside a region.
const EPS_PX: f64 = 0.05;

/// A cell of the checkerboard (column `i` along u, row `j` along v) is opaque when i + j is even.
fn cell_opaque(i: usize, j: usize) -> bool {
    (i + j).is_multiple_of(2)
}

/// RGBA8 texels of the checkerboard: white, alpha 255 in opaque cells and 0 in the others.
fn checker() -> Vec<u8> {
    (0..CELLS * CELLS)
        .flat_map(|k| {
            let a = if cell_opaque(k % CELLS, k / CELLS) {
                255
            } else {
                0
            };
            [255, 255, 255, a]
        })
        .collect()
}

/// The parallelogram `origin + u·a + v·b`, (u, v) ∈ [0, 1]² (its texture coordinates), facing
/// a × b.
fn quad(origin: Vec3, a: Vec3, b: Vec3, material: usize) -> PrimitiveDesc {
    let n = a.cross(b).normalize();
    let corners = [origin, origin + a, origin + a + b, origin + b];
    let mut p = PrimitiveDesc::triangles(
        corners.iter().map(|c| c.to_array()).collect(),
        Some(vec![n.to_array(); 4]),
        vec![0, 1, 2, 0, 2, 3],
        Some(material),
    );
    p.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    p
}

/// The point of the quad `origin + u·a + v·b` at (u, v).
fn quad_point(origin: Vec3, a: Vec3, b: Vec3, u: f32, v: f32) -> Vec3 {
    origin + a * u + b * v
}

/// The image-space outline (pixels, y down; positive area) of a convex world polygon in front
/// of the camera.
fn image_polygon(view: &CameraView, size: (u32, u32), corners: &[Vec3]) -> Polygon {
    let aspect = size.0 as f32 / size.1 as f32;
    let points: Vec<(f64, f64)> = corners
        .iter()
        .map(|&c| {
            let ndc = view
                .project(c, aspect)
                .expect("corner in front of the camera");
            ndc_to_pixel(ndc.x, ndc.y, size.0, size.1)
        })
        .collect();
    convex_hull(&points)
}

/// An image region of known radiance.
struct Region {
    outline: Polygon,
    value: [f64; 3],
}

/// The expected radiance of every pixel: a region's value where the pixel lies wholly inside
/// it, `background` where it lies wholly outside every outline of `covered`, `None` elsewhere
/// (pixels across an edge).
fn expected_pixels(
    size: (u32, u32),
    regions: &[Region],
    covered: &[Polygon],
    background: [f64; 3],
) -> Vec<Option<[f64; 3]>> {
    let mut out = Vec::with_capacity((size.0 * size.1) as usize);
    for y in 0..size.1 {
        for x in 0..size.0 {
            let inside = regions
                .iter()
                .find(|r| pixel_coverage(&r.outline, x, y, EPS_PX) == Coverage::Inside);
            let outside = covered
                .iter()
                .all(|p| pixel_coverage(p, x, y, EPS_PX) == Coverage::Outside);
            out.push(match (inside, outside) {
                (Some(r), _) => Some(r.value),
                (None, true) => Some(background),
                (None, false) => None,
            });
        }
    }
    out
}

/// Compares `got` with the expected pixels: |error| ≤ `tol` per channel. Returns the number of
/// pixels checked with each distinct expected value (in order of first appearance) and the
/// largest error.
fn check_pixels(
    what: &str,
    size: (u32, u32),
    got: &[[f32; 3]],
    expected: &[Option<[f64; 3]>],
    tol: f64,
) -> (Vec<([f64; 3], usize)>, f64) {
    let mut counts: Vec<([f64; 3], usize)> = Vec::new();
    let mut worst = 0.0f64;
    for (i, e) in expected.iter().enumerate() {
        let Some(e) = e else { continue };
        let (x, y) = (i as u32 % size.0, i as u32 / size.0);
        for c in 0..3 {
            let err = (f64::from(got[i][c]) - e[c]).abs();
            worst = worst.max(err);
            assert!(
                err <= tol,
                "{what}: pixel ({x}, {y}) channel {c}: {}, expected {} ± {tol}",
                got[i][c],
                e[c]
            );
        }
        match counts.iter_mut().find(|(v, _)| v == e) {
            Some((_, n)) => *n += 1,
            None => counts.push((*e, 1)),
        }
    }
    (counts, worst)
}

/// `scene`, checked to have only Lambertian materials: the glTF default dielectric has a
/// specular layer (F0 = 0.04), which the writer's `specularFactor` 0 (`KHR_materials_specular`)
/// removes, so the closed forms below are those of ρ/π.
fn lambertian(scene: Scene) -> Scene {
    for m in &scene.materials {
        assert_eq!((m.metallic, m.specular_factor), (0.0, 0.0));
    }
    assert!(!scene.plan().specular);
    scene
}

/// `scene` with the glTF default dielectric's specular layer (`specularFactor` 1) on every
/// material.
fn glossy(mut scene: Scene) -> Scene {
    for m in &mut scene.materials {
        m.specular_factor = 1.0;
    }
    assert!(scene.plan().specular);
    scene
}

fn sky_extras(l: f32) -> serde_json::Value {
    serde_json::json!({"environment": {"radiance": [l, l, l]}})
}

/// A cache frame of `scene` at `size` with the default settings.
fn cache_frame(
    ctx: &radcache_vk::Context,
    shaders: &radcache_vk::ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    size: (u32, u32),
) -> (FrameOutput, IcSettings) {
    let settings = IcSettings {
        width: size.0,
        height: size.1,
        ..IcSettings::default()
    };
    let (out, _) = render_ic(ctx, shaders, scene, gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(out.nonfinite_pixels, 0);
    (out, settings)
}

const SKY: f32 = 1.0;
const MASK_RGB: [f32; 3] = [0.8, 0.3, 0.1];
const OPAQUE_RGB: [f32; 3] = [0.2, 0.6, 0.4];
const MASK_ORIGIN: Vec3 = Vec3::new(-1.0, -1.0, 0.0);
const MASK_A: Vec3 = Vec3::new(2.0, 0.0, 0.0);
const MASK_B: Vec3 = Vec3::new(0.0, 2.0, 0.0);
const SIDE_ORIGIN: Vec3 = Vec3::new(1.2, -1.0, 0.0);
const SIDE_A: Vec3 = Vec3::new(0.6, 0.0, 0.0);

/// Radiance of the backdrop behind the masked quad.
const BACKDROP: f32 = 2.0;

/// The masked checkerboard quad and, in the same mesh, an opaque quad beside it with the same
/// texture, facing a camera on +Z under a uniform sky, in front of a black emissive backdrop
/// that fills the view (it reflects nothing; it lies behind the quads' lit faces). The mask's
/// alpha is factor 0.8 × texture alpha against the cutoff 0.4, so it crosses the cutoff where the
/// texture's bilinear alpha crosses ½: on the cell edges.
fn mask_scene(tag: &str) -> Scene {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(4, 4, &checker(), 33071).unwrap();
    let mut mask = MaterialDesc::diffuse("mask", MASK_RGB);
    mask.base_color[3] = 0.8;
    mask.base_color_texture = Some(tex);
    mask.alpha_mode = Some("MASK".into());
    mask.alpha_cutoff = Some(0.4);
    let mask = b.add_material(&mask);
    // OPAQUE ignores alpha, the factor's and the texture's.
    let mut solid = MaterialDesc::diffuse("solid", OPAQUE_RGB);
    solid.base_color[3] = 0.3;
    solid.base_color_texture = Some(tex);
    let solid = b.add_material(&solid);
    let backdrop = b.add_material(&MaterialDesc::emitter("backdrop", [0.0; 3], [BACKDROP; 3]));
    let mesh = b.add_mesh(
        "quads",
        &[
            quad(MASK_ORIGIN, MASK_A, MASK_B, mask),
            quad(SIDE_ORIGIN, SIDE_A, MASK_B, solid),
        ],
    );
    let wall = quad(
        Vec3::new(-6.0, -6.0, -1.5),
        Vec3::new(12.0, 0.0, 0.0),
        Vec3::new(0.0, 12.0, 0.0),
        backdrop,
    );
    let backdrop_mesh = b.add_mesh("backdrop", &[wall]);
    let roots = vec![
        b.add_node(&NodeDesc {
            name: Some("quads".into()),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }),
        b.add_node(&NodeDesc {
            name: Some("backdrop".into()),
            mesh: Some(backdrop_mesh),
            ..NodeDesc::default()
        }),
        camera_node(&mut b, Vec3::new(0.4, 0.0, 3.5), Quat::IDENTITY, 0.9),
    ];
    b.add_scene(tag, &roots, Some(sky_extras(SKY)));
    write_and_load(&b, &temp_dir(tag), tag)
}

/// The cells of a quad as world polygons, with whether each is opaque.
fn cells(origin: Vec3, a: Vec3, b: Vec3) -> Vec<([Vec3; 4], bool)> {
    let mut out = Vec::new();
    let n = CELLS as f32;
    for j in 0..CELLS {
        for i in 0..CELLS {
            let (u0, v0) = (i as f32 / n, j as f32 / n);
            let (u1, v1) = ((i + 1) as f32 / n, (j + 1) as f32 / n);
            let p = |u, v| quad_point(origin, a, b, u, v);
            out.push((
                [p(u0, v0), p(u1, v0), p(u1, v1), p(u0, v1)],
                cell_opaque(i, j),
            ));
        }
    }
    out
}

#[test]
fn a_masked_quad_shows_its_checkerboard_in_the_path_tracer_and_the_cache_frame() {
    let scene = lambertian(mask_scene("alpha-mask"));
    let glossy = glossy(scene.clone());
    assert!(scene.plan().alpha);
    assert!(scene
        .plan()
        .to_string()
        .contains("alpha: masked or blended"));
    let size = (48u32, 48u32);
    let view = scene.camera_at(0.0);
    let back = [f64::from(BACKDROP); 3];
    let rgb = |c: [f32; 3]| c.map(|v| f64::from(v * SKY));
    let mut regions: Vec<Region> = cells(MASK_ORIGIN, MASK_A, MASK_B)
        .into_iter()
        .map(|(corners, opaque)| Region {
            outline: image_polygon(&view, size, &corners),
            value: if opaque { rgb(MASK_RGB) } else { back },
        })
        .collect();
    let side = [
        SIDE_ORIGIN,
        SIDE_ORIGIN + SIDE_A,
        SIDE_ORIGIN + SIDE_A + MASK_B,
        SIDE_ORIGIN + MASK_B,
    ];
    regions.push(Region {
        outline: image_polygon(&view, size, &side),
        value: rgb(OPAQUE_RGB),
    });
    let mask_outline = image_polygon(
        &view,
        size,
        &[
            MASK_ORIGIN,
            MASK_ORIGIN + MASK_A,
            MASK_ORIGIN + MASK_A + MASK_B,
            MASK_ORIGIN + MASK_B,
        ],
    );
    let covered = [mask_outline, regions[CELLS * CELLS].outline.clone()];
    let expected = expected_pixels(size, &regions, &covered, back);

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    assert!(gpu.material_defines().contains(&("HAS_ALPHA", "1")));
    // Every sample is exact (camera → quad → sky, or camera → backdrop): a few suffice.
    let settings = PathSettings {
        width: size.0,
        height: size.1,
        budget: Budget::Samples(4),
        seed: 7,
        aovs: true,
        ..PathSettings::default()
    };
    let path = render_path(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(path.nonfinite_pixels, 0);
    let (counts, worst) = check_pixels("path tracer", size, &path.pixels, &expected, 1e-4);
    eprintln!("path tracer: pixels checked per value {counts:?}, worst |error| {worst:.2e}");
    let n = |v: [f64; 3]| counts.iter().find(|c| c.0 == v).map_or(0, |c| c.1);
    assert!(n(rgb(MASK_RGB)) >= 60 && n(rgb(OPAQUE_RGB)) >= 60 && n(back) >= 300);

    // The albedo AOV (its own 4×4 grid of camera rays per pixel): the mask's colour in opaque
    // cells, the black backdrop's 0 in transparent ones.
    let aovs = path.aovs.as_ref().expect("AOVs asked for");
    let albedo: Vec<[f32; 3]> = aovs
        .albedo
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let albedo_expected: Vec<Option<[f64; 3]>> = expected
        .iter()
        .map(|e| e.map(|v| if v == back { [0.0; 3] } else { v }))
        .collect();
    check_pixels("albedo AOV", size, &albedo, &albedo_expected, 1e-4);

    // The cache frame: the G-buffer discards the transparent cells' fragments, and the backdrop's
    // fragments behind them keep their place because the occluder ray skips the same points;
    // the emission pass's own camera rays see through them too. The records gather the uniform
    // sky (E = π·L on every ray), so the frame is exact.
    let (ic, _) = cache_frame(&ctx, &shaders, &scene, &mut gpu, size);
    let (counts, worst) = check_pixels("cache frame", size, &ic.pixels, &expected, 1e-4);
    eprintln!("cache frame: pixels checked per value {counts:?}, worst |error| {worst:.2e}");
    drop(gpu);

    // The quads with the default dielectric (HAS_SPECULAR and HAS_ALPHA together; the backdrop
    // stays black): the backdrop's pixels are still exact; the mask's are its diffuse share plus
    // the specular layer's few per cent of the sky (their mean green channel, ρ_g = 0.3, stays
    // far from the backdrop's 2).
    let mut glossy = glossy;
    glossy.materials[2].specular_factor = 0.0;
    let mut gpu = GpuScene::new(&ctx, &glossy, None).unwrap();
    let defines = gpu.material_defines();
    assert!(defines.contains(&("HAS_ALPHA", "1")) && defines.contains(&("HAS_SPECULAR", "1")));
    let out = render(&ctx, &shaders, &glossy, &mut gpu, size, 16, 3);
    let backdrop_only: Vec<Option<[f64; 3]>> =
        expected.iter().map(|e| e.filter(|v| *v == back)).collect();
    check_pixels(
        "path tracer, glossy",
        size,
        &out.pixels,
        &backdrop_only,
        1e-4,
    );
    let quad_green: Vec<f64> = expected
        .iter()
        .zip(&out.pixels)
        .filter(|(e, _)| *e == &Some(rgb(MASK_RGB)))
        .map(|(_, p)| f64::from(p[1]))
        .collect();
    let green = mean_se(&quad_green);
    eprintln!("path tracer, glossy: the mask's opaque cells, mean green {green:?}");
    assert!(green.mean > 0.2 && green.mean < 0.45, "{green:?}");
    drop(gpu);
    finish(ctx);
}

const FLOOR_RGB: [f32; 3] = [0.8, 0.5, 0.25];
const ILLUMINANCE: f32 = 3.0;
const SHADOW_ORIGIN: Vec3 = Vec3::new(-1.0, 2.0, -1.0);
const SHADOW_A: Vec3 = Vec3::new(2.0, 0.0, 0.0);
const SHADOW_B: Vec3 = Vec3::new(0.0, 0.0, 2.0);

/// Where a point of the mask casts its shadow on the floor under light travelling along
/// (1, −1, 0)/√2: 2 m to +X at the mask's height of 2 m.
fn shadow_of(p: Vec3) -> Vec3 {
    Vec3::new(p.x + p.y, 0.0, p.z)
}

#[test]
fn a_masked_quad_casts_its_checkerboard_shadow() {
    let tag = "alpha-shadow";
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(4, 4, &checker(), 33071).unwrap();
    let floor = b.add_material(&MaterialDesc::diffuse("floor", FLOOR_RGB));
    // Black: the quad reflects nothing, so the floor's only light is the direct light.
    let mut mask = MaterialDesc::diffuse("mask", [0.0; 3]);
    mask.base_color_texture = Some(tex);
    mask.alpha_mode = Some("MASK".into());
    let mask = b.add_material(&mask);
    let floor_mesh = b.add_mesh("floor", &[plane_y([-6.0, 6.0], [-6.0, 6.0], 0.0, floor)]);
    let mask_mesh = b.add_mesh("mask", &[quad(SHADOW_ORIGIN, SHADOW_A, SHADOW_B, mask)]);
    let direction = Vec3::new(1.0, -1.0, 0.0).normalize();
    let light = b.add_light(&LightDesc {
        name: Some("sun".into()),
        kind: LightKind::Directional,
        color: [1.0; 3],
        intensity: ILLUMINANCE,
        range: None,
    });
    let roots = vec![
        b.add_node(&NodeDesc {
            mesh: Some(floor_mesh),
            ..NodeDesc::default()
        }),
        b.add_node(&NodeDesc {
            mesh: Some(mask_mesh),
            ..NodeDesc::default()
        }),
        b.add_node(&NodeDesc {
            name: Some("sun".into()),
            translation: Some([0.0, 5.0, 0.0]),
            // Lights shine down their node's −Z axis.
            rotation: Some(Quat::from_rotation_arc(-Vec3::Z, direction).to_array()),
            light: Some(light),
            ..NodeDesc::default()
        }),
        // Below the mask, looking straight down at its shadow: the mask is out of view.
        camera_node(
            &mut b,
            Vec3::new(2.0, 1.5, 0.0),
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            1.3,
        ),
    ];
    b.add_scene(tag, &roots, None);
    let scene = lambertian(write_and_load(&b, &temp_dir(tag), tag));
    assert!(scene.plan().alpha);

    let size = (40u32, 40u32);
    let view = scene.camera_at(0.0);
    // ρ/π · E · cos θ, θ = 45° between the floor's normal and the light.
    let lit = FLOOR_RGB.map(|r| f64::from(r) / PI * f64::from(ILLUMINANCE) * 0.5f64.sqrt());
    let regions: Vec<Region> = cells(SHADOW_ORIGIN, SHADOW_A, SHADOW_B)
        .into_iter()
        .map(|(corners, opaque)| Region {
            outline: image_polygon(&view, size, &corners.map(shadow_of)),
            value: if opaque { [0.0; 3] } else { lit },
        })
        .collect();
    let outline = image_polygon(
        &view,
        size,
        &[
            SHADOW_ORIGIN,
            SHADOW_ORIGIN + SHADOW_A,
            SHADOW_ORIGIN + SHADOW_A + SHADOW_B,
            SHADOW_ORIGIN + SHADOW_B,
        ]
        .map(shadow_of),
    );
    let expected = expected_pixels(size, &regions, &[outline], lit);

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    // Each sample: camera → floor, one shadow ray (exact), one continuation that finds the black
    // quad or nothing.
    let path = render(&ctx, &shaders, &scene, &mut gpu, size, 4, 11);
    let (counts, worst) = check_pixels("path tracer", size, &path.pixels, &expected, 1e-4);
    eprintln!("path tracer: pixels checked per value {counts:?}, worst |error| {worst:.2e}");
    let n = |v: [f64; 3]| counts.iter().find(|c| c.0 == v).map_or(0, |c| c.1);
    assert!(n([0.0; 3]) >= 150 && n(lit) >= 400, "{counts:?}");

    // The cache frame: the direct pass's shadow rays from the G-buffer; the records gather
    // nothing (the quad is black).
    let (ic, _) = cache_frame(&ctx, &shaders, &scene, &mut gpu, size);
    let (counts, worst) = check_pixels("cache frame", size, &ic.pixels, &expected, 1e-4);
    eprintln!("cache frame: pixels checked per value {counts:?}, worst |error| {worst:.2e}");
    drop(gpu);
    finish(ctx);
}

const BLEND_RGB: f32 = 0.2;

#[test]
fn a_blended_quad_of_alpha_half_converges_to_the_mean_of_quad_and_sky() {
    let tag = "alpha-blend";
    let mut b = GltfBuilder::new();
    let mut glass = MaterialDesc::diffuse("glass", [BLEND_RGB; 3]);
    glass.base_color[3] = 0.5;
    glass.alpha_mode = Some("BLEND".into());
    let glass = b.add_material(&glass);
    let mesh = b.add_mesh("quad", &[quad(MASK_ORIGIN, MASK_A, MASK_B, glass)]);
    let roots = vec![
        b.add_node(&NodeDesc {
            mesh: Some(mesh),
            ..NodeDesc::default()
        }),
        camera_node(&mut b, Vec3::new(0.0, 0.0, 3.0), Quat::IDENTITY, 0.9),
    ];
    b.add_scene(tag, &roots, Some(sky_extras(SKY)));
    let scene = lambertian(write_and_load(&b, &temp_dir(tag), tag));
    assert!(scene.plan().alpha && scene.materials[0].has_alpha());

    let size = (32u32, 32u32);
    let view = scene.camera_at(0.0);
    let outline = image_polygon(
        &view,
        size,
        &[
            MASK_ORIGIN,
            MASK_ORIGIN + MASK_A,
            MASK_ORIGIN + MASK_A + MASK_B,
            MASK_ORIGIN + MASK_B,
        ],
    );
    let inside: Vec<usize> = (0..size.0 * size.1)
        .filter(|&i| pixel_coverage(&outline, i % size.0, i / size.0, EPS_PX) == Coverage::Inside)
        .map(|i| i as usize)
        .collect();
    let (rho, l) = (f64::from(BLEND_RGB), f64::from(SKY));
    let mean = 0.5 * rho * l + 0.5 * l;
    // One sample is ρ·L or L with probability ½ each: standard deviation ½·(1 − ρ)·L.
    let sample_sd = 0.5 * (1.0 - rho) * l;

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let spp = 64u32;
    let path = render(&ctx, &shaders, &scene, &mut gpu, size, spp, 5);
    let values: Vec<f64> = inside
        .iter()
        .map(|&i| f64::from(path.pixels[i][1]))
        .collect();
    let stats = mean_se(&values);
    let pixel_sd = sample_sd / f64::from(spp).sqrt();
    let var = stats.se * stats.se * stats.n as f64;
    eprintln!(
        "path tracer: {} pixels, mean {:.5} (expected {mean:.5}, SE {:.1e}), pixel variance \
         {var:.3e} (binomial {:.3e})",
        stats.n,
        stats.mean,
        pixel_sd / (stats.n as f64).sqrt(),
        pixel_sd * pixel_sd
    );
    assert!(stats.n >= 200, "{} pixels inside the quad", stats.n);
    assert!(
        (stats.mean - mean).abs() <= 4.0 * pixel_sd / (stats.n as f64).sqrt(),
        "path tracer: mean {} over the quad, expected {mean}",
        stats.mean
    );
    // Independent coverage per sample and pixel: the pixels' spread is the binomial one (an
    // alpha-weighted blend would have none, coverage shared between samples more).
    assert!(
        var > 0.5 * pixel_sd * pixel_sd && var < 2.0 * pixel_sd * pixel_sd,
        "path tracer: pixel variance {var}, binomial {}",
        pixel_sd * pixel_sd
    );
    for &i in &inside {
        let p = path.pixels[i];
        assert!(p[0] == p[1] && p[1] == p[2], "grey pixel {i}: {p:?}");
    }

    // The cache frame: each sub-frame's G-buffer keeps the quad with probability ½ per pixel, so
    // a pixel is k/8 of the way from the sky to the quad's ρ·L.
    let (ic, settings) = cache_frame(&ctx, &shaders, &scene, &mut gpu, size);
    let subs = f64::from(settings.sub_frames);
    let values: Vec<f64> = inside.iter().map(|&i| f64::from(ic.pixels[i][1])).collect();
    let stats = mean_se(&values);
    let pixel_sd = sample_sd / subs.sqrt();
    let mut off_lattice = 0.0f64;
    for &v in &values {
        let k = ((l - v) / ((l - rho * l) / subs)).round();
        let on = l - k * (l - rho * l) / subs;
        off_lattice = off_lattice.max((v - on).abs());
    }
    eprintln!(
        "cache frame: mean {:.5} (expected {mean:.5}, SE {:.1e}), largest distance from the \
         k/{subs} lattice {off_lattice:.2e}",
        stats.mean,
        pixel_sd / (stats.n as f64).sqrt()
    );
    assert!(
        (stats.mean - mean).abs() <= 4.0 * pixel_sd / (stats.n as f64).sqrt(),
        "cache frame: mean {} over the quad, expected {mean}",
        stats.mean
    );
    assert!(
        off_lattice < 1e-4,
        "cache frame: a pixel is {off_lattice} off the sub-frame lattice"
    );
    drop(gpu);
    finish(ctx);
}

const EMISSION: f32 = 2.0;
/// The emitter's floor lies at this height, away from 0: there `offset_ray_origin` moves a shadow
/// ray's origin by a fixed scene scale / 65536 (2.6e-4 m in a scene 17 m across), which is more
/// than the 1e-4 of the distance by which shadow rays stop short of a light 2 m away, so the
/// rays met the emitter itself (a limitation outside the alpha test).
const LAMP_FLOOR_Y: f32 = 1.0;
const LAMP_ORIGIN: Vec3 = Vec3::new(-1.0, 3.0, -1.0);

/// Irradiance per unit radiance at floor point `p` (normal +Y) from the cells of the emitter quad
/// at LAMP_ORIGIN that `lit` selects: Lambert's formula, two triangles per cell.
fn cells_projected_solid_angle(p: Vec3, lit: impl Fn(bool) -> bool) -> f64 {
    cells(LAMP_ORIGIN, SHADOW_A, SHADOW_B)
        .iter()
        .filter(|(_, opaque)| lit(*opaque))
        .map(|(c, _)| {
            f64::from(triangle_projected_solid_angle(
                p,
                Vec3::Y,
                [c[0], c[1], c[2]],
            )) + f64::from(triangle_projected_solid_angle(
                p,
                Vec3::Y,
                [c[0], c[2], c[3]],
            ))
        })
        .sum()
}

/// Mean of `f` over the floor points that pixel `(px, py)` sees, on a k × k grid of sub-pixel
/// positions (midpoint rule).
fn floor_pixel_mean(
    view: &CameraView,
    size: (u32, u32),
    (px, py): (u32, u32),
    k: u32,
    f: &dyn Fn(Vec3) -> f64,
) -> f64 {
    let aspect = size.0 as f32 / size.1 as f32;
    let mut sum = 0.0;
    for j in 0..k {
        for i in 0..k {
            let sx = f64::from(px) + (f64::from(i) + 0.5) / f64::from(k);
            let sy = f64::from(py) + (f64::from(j) + 0.5) / f64::from(k);
            let (x, y) = radcache_tests::scenes::pixel_to_ndc(sx, sy, size.0, size.1);
            let d = view.ray_direction(x, y, aspect);
            assert!(d.y < 0.0, "pixel ({px}, {py}) does not see the floor");
            sum += f(view.position + d * ((LAMP_FLOOR_Y - view.position.y) / d.y));
        }
    }
    sum / f64::from(k * k)
}

/// Checks two independent renders `a`, `b` of the floor against the expected radiance `exp`
/// (and its quadrature error `quad`) over 8 × 8 pixel blocks: the block sum of (a + b)/2 within
/// 5 standard errors (estimated from (a − b)²/4 per pixel) plus the quadrature bound. Returns
/// the largest deviation in standard errors and the image sums (measured, expected).
fn check_blocks(
    what: &str,
    size: (u32, u32),
    a: &[[f32; 3]],
    b: &[[f32; 3]],
    exp: &[[f64; 3]],
    quad: &[[f64; 3]],
) -> (f64, f64, f64) {
    let (mut worst, mut got_all, mut exp_all) = (0.0f64, 0.0, 0.0);
    for by in (0..size.1).step_by(8) {
        for bx in (0..size.0).step_by(8) {
            for c in 0..3 {
                let (mut got, mut want, mut var, mut q) = (0.0, 0.0, 0.0, 0.0);
                for y in by..(by + 8).min(size.1) {
                    for x in bx..(bx + 8).min(size.0) {
                        let i = (y * size.0 + x) as usize;
                        let (va, vb) = (f64::from(a[i][c]), f64::from(b[i][c]));
                        got += 0.5 * (va + vb);
                        var += 0.25 * (va - vb).powi(2);
                        want += exp[i][c];
                        q += quad[i][c];
                    }
                }
                let se = var.sqrt();
                let tol = 5.0 * se + q + 1e-4 * want;
                assert!(
                    (got - want).abs() <= tol,
                    "{what}: block at ({bx}, {by}) channel {c}: sum {got}, expected {want} ± {tol} \
                     (SE {se})"
                );
                worst = worst.max((got - want).abs() / se.max(1e-12));
                if c == 1 {
                    got_all += got;
                    exp_all += want;
                }
            }
        }
    }
    eprintln!(
        "{what}: block sums within {worst:.2} SE; image sum {got_all:.4}, expected {exp_all:.4}"
    );
    (worst, got_all, exp_all)
}

#[test]
fn a_masked_emitter_emits_only_where_it_is_there() {
    let tag = "alpha-emitter";
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(4, 4, &checker(), 33071).unwrap();
    let floor = b.add_material(&MaterialDesc::diffuse("floor", FLOOR_RGB));
    // Black: the emitter reflects nothing, so the floor's only light is the emitter's.
    let mut lamp = MaterialDesc::emitter("lamp", [0.0; 3], [EMISSION; 3]);
    lamp.base_color_texture = Some(tex);
    lamp.alpha_mode = Some("MASK".into());
    let lamp = b.add_material(&lamp);
    let floor_mesh = b.add_mesh(
        "floor",
        &[plane_y([-3.0, 3.0], [-3.0, 3.0], LAMP_FLOOR_Y, floor)],
    );
    // Facing down (front face towards the floor), 2 m above it.
    let lamp_mesh = b.add_mesh("lamp", &[quad(LAMP_ORIGIN, SHADOW_A, SHADOW_B, lamp)]);
    let roots = vec![
        b.add_node(&NodeDesc {
            mesh: Some(floor_mesh),
            ..NodeDesc::default()
        }),
        b.add_node(&NodeDesc {
            mesh: Some(lamp_mesh),
            ..NodeDesc::default()
        }),
        // Below the emitter, looking straight down: the emitter is out of view.
        camera_node(
            &mut b,
            Vec3::new(0.3, 2.5, 0.2),
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            1.4,
        ),
    ];
    b.add_scene(tag, &roots, None);
    let scene = lambertian(write_and_load(&b, &temp_dir(tag), tag));
    let plan = scene.plan();
    assert!(plan.alpha && plan.has_emissive());
    assert!(
        !plan.analytic_emitters,
        "the closed form takes whole triangles: not for a masked emitter"
    );

    let size = (40u32, 40u32);
    let view = scene.camera_at(0.0);
    let e_masked = |p: Vec3| f64::from(EMISSION) * cells_projected_solid_angle(p, |o| o);
    let mut exp = Vec::new();
    let mut quad_err = Vec::new();
    let (mut sum_masked, mut sum_whole) = (0.0, 0.0);
    for py in 0..size.1 {
        for px in 0..size.0 {
            let e8 = floor_pixel_mean(&view, size, (px, py), 8, &e_masked);
            let e4 = floor_pixel_mean(&view, size, (px, py), 4, &e_masked);
            exp.push(FLOOR_RGB.map(|r| f64::from(r) / PI * e8));
            quad_err.push(FLOOR_RGB.map(|r| f64::from(r) / PI * (e8 - e4).abs()));
            sum_masked += e8;
            sum_whole += floor_pixel_mean(&view, size, (px, py), 2, &|p| {
                f64::from(EMISSION) * cells_projected_solid_angle(p, |_| true)
            });
        }
    }
    // The mask takes about half of the light: a renderer that ignored it would be far off.
    let ratio = sum_masked / sum_whole;
    assert!(ratio > 0.3 && ratio < 0.7, "masked/whole {ratio}");

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    // Light samples on a transparent cell find no radiance, BSDF samples pass through it; MIS
    // weighs the two.
    let a = render(&ctx, &shaders, &scene, &mut gpu, size, 64, 1);
    let b = render(&ctx, &shaders, &scene, &mut gpu, size, 64, 2);
    check_blocks("path tracer", size, &a.pixels, &b.pixels, &exp, &quad_err);

    // The cache frame: the direct pass's one-sample MIS of the emitter (the records gather
    // nothing: the emitter is black, and its light straight from it is the direct pass's).
    let mut frame = |seed: u32| {
        let settings = IcSettings {
            width: size.0,
            height: size.1,
            seed,
            ..IcSettings::default()
        };
        render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {})
            .unwrap()
            .0
    };
    let (a, b) = (frame(1), frame(2));
    check_blocks("cache frame", size, &a.pixels, &b.pixels, &exp, &quad_err);
    drop(gpu);
    finish(ctx);
}

#[test]
fn opaque_scenes_plan_no_alpha_test() {
    let cornell =
        load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/cornell/cornell.gltf"));
    let tag = "alpha-opaque";
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(4, 4, &checker(), 33071).unwrap();
    // OPAQUE with a transparent texture, and MASK whose constant alpha always passes.
    let mut textured = MaterialDesc::diffuse("textured", [0.5; 3]);
    textured.base_color_texture = Some(tex);
    let textured = b.add_material(&textured);
    let mut passing = MaterialDesc::diffuse("passing", [0.5; 3]);
    passing.alpha_mode = Some("MASK".into());
    passing.base_color[3] = 0.6;
    let passing = b.add_material(&passing);
    let mesh = b.add_mesh(
        "quads",
        &[
            quad(MASK_ORIGIN, MASK_A, MASK_B, textured),
            quad(SIDE_ORIGIN, SIDE_A, MASK_B, passing),
        ],
    );
    let roots = vec![b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    })];
    b.add_scene(tag, &roots, Some(sky_extras(SKY)));
    let opaque = write_and_load(&b, &temp_dir(tag), tag);

    let ctx = context();
    for (what, scene) in [("cornell", &cornell), ("opaque", &opaque)] {
        let plan = scene.plan();
        assert!(!plan.alpha, "{what}: plan has alpha");
        assert!(
            plan.to_string()
                .contains("alpha: none (opaque ray queries)"),
            "{what}: {plan}"
        );
        let gpu = GpuScene::new(&ctx, scene, None).unwrap();
        assert!(
            !gpu.material_defines().iter().any(|d| d.0 == "HAS_ALPHA"),
            "{what}: {:?}",
            gpu.material_defines()
        );
        assert!(!gpu.defines().iter().any(|d| d.0 == "HAS_ALPHA"));
    }
    finish(ctx);
}
