//! The reference path tracer against closed-form answers on lavapipe.
//!
//! - Furnaces (closed box, albedo ρ, emission Le everywhere): every pixel converges to
//!   Le / (1 − ρ); checked for ρ = 0.5, 0.9 and 0.99 (paths of ~100 bounces) at several sample
//!   counts (the estimate is unbiased at every count and its standard error shrinks), and for a
//!   mirrored (negative-determinant) furnace box.
//! - Planes under punctual lights and a constant sky: `path_lights.rs`.
//! - A textured emitter seen directly: emissive factor × texel, nothing else; a NEAREST-filtered
//!   one shows its texels unblended.
//! - Seeds: different seeds give independent, equally distributed images; the same seed gives the
//!   same image bit for bit.
//!
//! Tolerances come from the samples: per-pixel estimates are independent, so the image mean's
//! standard error is the per-pixel spread / √N and the test accepts |mean − expected| < 5 SE plus a
//! float slack of a few ulps of f32 accumulation. Where the only randomness is the pixel jitter,
//! the per-pixel bound is 5 × (jitter standard deviation / √spp) plus the CPU quadrature error.

use std::path::PathBuf;

use glam::{Quat, Vec3};
use radcache_render::{FrameOutput, GpuScene};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc};
use radcache_scene::Scene;
use radcache_tests::scenes::{
    camera_node, channel, load, mean_se, render, temp_dir, write_and_load, FLOAT_SLACK,
};
use radcache_tests::{context, finish, shaders};

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

/// A black 10 m quad at z = 0 facing a camera 3 m in front of it (yfov 0.7: the view spans uv
/// 0.39–0.61), emitting `factor` × texture `tex` of `b` (u along +x, v down).
fn emissive_quad(mut b: GltfBuilder, tex: usize, factor: [f32; 3], tag: &str) -> Scene {
    let mat = b.add_material(&MaterialDesc {
        emissive: factor,
        emissive_texture: Some(tex),
        ..MaterialDesc::diffuse(tag, [0.0; 3])
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
    let mesh = b.add_mesh(tag, &[quad]);
    let quad_node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let cam = camera_node(&mut b, Vec3::new(0.0, 0.0, 3.0), Quat::IDENTITY, 0.7);
    b.add_scene(tag, &[quad_node, cam], None);
    write_and_load(&b, &temp_dir(tag), tag)
}

#[test]
fn a_nearest_filtered_texture_shows_its_texels_unblended() {
    // A 2 × 2 emissive texture with magFilter NEAREST on a black quad, magnified so that the
    // image's four quadrants fall in its four texels (the texel edges run between pixels 3 and 4):
    // every pixel is its texel exactly, where a bilinear lookup would blend the four everywhere
    // (the view spans uv 0.39–0.61, within half a texel of the centre).
    let texels: [[u8; 4]; 4] = [
        [255, 0, 0, 255],
        [0, 255, 0, 255],
        [0, 0, 255, 255],
        [255, 255, 255, 255],
    ];
    let mut b = GltfBuilder::new();
    let tex = b
        .add_texture_rgba8(2, 2, &texels.concat(), 33071)
        .expect("PNG encoding");
    b.set_mag_filter(tex, 9728);
    let scene = emissive_quad(b, tex, [1.0; 3], "nearest");
    assert!(scene.textures[0].nearest);

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let out = render(&ctx, &shaders, &scene, &mut gpu, (8, 8), 4, 9);
    drop(gpu);
    finish(ctx);
    for (i, p) in out.pixels.iter().enumerate() {
        let (x, y) = (i % 8, i / 8);
        let texel = texels[usize::from(y >= 4) * 2 + usize::from(x >= 4)];
        for c in 0..3 {
            let expected = f32::from(texel[c]) / 255.0;
            assert!(
                (p[c] - expected).abs() <= 1e-5,
                "pixel ({x}, {y}) channel {c}: {}, expected the texel's {expected}",
                p[c]
            );
        }
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
    let scene = emissive_quad(b, tex, factor, "glow");

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
