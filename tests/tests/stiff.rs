//! The stiff and extreme suite (issue 8) at test size: every scene of
//! `radcache_scene::assets::stiff`, small images, modest effort. The thorough figures (every
//! preset on every scene, bigger images, better references) are `cargo xtask stiff`'s
//! (`bench/stiff.md`). Figures: `radcache_tests::stiff`.

use std::path::PathBuf;

use radcache_cache::Preset;
use radcache_image::Image;
use radcache_render::GpuScene;
use radcache_scene::assets::stiff::{
    stiff_scene, write_stiff_scene, StiffCheck, DEGENERATE_DROPPED, DEGENERATE_GENERATED_NORMALS,
};
use radcache_scene::{Error, LoadOptions, Scene, Warning, WarningKind};
use radcache_tests::scenes::{mean_se, temp_dir};
use radcache_tests::stiff::{figures, mean_luminance, render, Effort, Figures, Method, Render};
use radcache_tests::{context, finish, shaders};
use radcache_vk::{Context, ShaderCompiler};

const SIZE: u32 = 32;

fn effort(sub_frames: u32) -> Effort {
    Effort {
        size: SIZE,
        sub_frames,
        direct_samples: 8,
        seed: 7,
    }
}

fn write(name: &str) -> PathBuf {
    write_stiff_scene(&stiff_scene(name), &temp_dir("stiff")).unwrap()
}

fn load(name: &str) -> (Scene, Vec<Warning>) {
    let path = write(name);
    Scene::load(&path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("loading {}: {e}", path.display()))
}

/// Renders and checks that no pixel is non-finite.
fn finite_render(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    method: Method,
    effort: Effort,
) -> Render {
    let r = render(ctx, shaders, scene, gpu, method, effort).unwrap();
    assert_eq!(r.nonfinite, 0, "{}: non-finite pixels", method.label());
    assert!(r.image.rgb().iter().all(|c| c.is_finite() && *c >= 0.0));
    r
}

fn show(scene: &str, method: Method, f: &Figures) {
    eprintln!(
        "{scene} {}: relMSE {:.3e}, block RMSE {:.3e}, leak {:?}, mean ratio {:.4}",
        method.label(),
        f.metrics.relmse,
        f.metrics.block_rmse,
        f.leak,
        f.metrics.mean_ratio[1]
    );
}

#[test]
fn furnaces_converge_to_le_over_one_minus_albedo() {
    let ctx = context();
    let shaders = shaders();
    for name in ["furnace_0.5", "furnace_0.9", "furnace_0.99"] {
        let s = stiff_scene(name);
        let StiffCheck::Analytic(expected) = s.check else {
            panic!("{name} is analytic")
        };
        let (scene, _) = load(name);
        let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
        for (method, eff) in [
            (Method::Ic(Preset::Draft), effort(1)),
            (Method::Path(8), effort(1)),
        ] {
            let r = finite_render(&ctx, &shaders, &scene, &mut gpu, method, eff);
            let values: Vec<f64> = r.image.pixels().map(|p| f64::from(p[1])).collect();
            let m = mean_se(&values);
            // Cache records are shared by pixels: the records are the independent estimates.
            let n_eff = if r.records > 0 {
                (r.records as f64).min(values.len() as f64)
            } else {
                values.len() as f64
            };
            let se = m.se * (values.len() as f64 / n_eff).sqrt();
            let expected = f64::from(expected);
            eprintln!("{name} {}: mean {:.4} ± {se:.4}", method.label(), m.mean);
            assert!(
                (m.mean - expected).abs() <= 5.0 * se + 1e-3 * expected,
                "{name} {}: mean {}, expected {expected} (SE {se})",
                method.label(),
                m.mean
            );
        }
        drop(gpu);
    }
    finish(ctx);
}

#[test]
fn albedo_one_terminates_with_finite_output() {
    let ctx = context();
    let shaders = shaders();
    let (scene, _) = load("furnace_1.0");
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    for method in [Method::Ic(Preset::Draft), Method::Path(4)] {
        let r = finite_render(&ctx, &shaders, &scene, &mut gpu, method, effort(1));
        let mean = mean_luminance(&r.image);
        eprintln!("furnace_1.0 {}: mean {mean:.1}", method.label());
        // Brighter than the albedo-0.99 furnace's exact 100 (the true answer is infinite).
        assert!(mean > 100.0, "{}: mean {mean}", method.label());
    }
    drop(gpu);
    finish(ctx);
}

#[test]
fn dark_rooms_stay_dark() {
    let ctx = context();
    let shaders = shaders();
    for name in ["two_rooms", "inside_object"] {
        let (scene, _) = load(name);
        let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
        // Eight sub-frames: before the G-buffer's visibility check, the eighth one's jitter put
        // samples of `two_rooms` on the lit floor behind the wall.
        for (method, eff) in [
            (Method::Ic(Preset::Draft), effort(8)),
            (Method::Ic(Preset::Default), effort(2)),
            (Method::Path(16), effort(1)),
        ] {
            let r = finite_render(&ctx, &shaders, &scene, &mut gpu, method, eff);
            let leak = mean_luminance(&r.image);
            eprintln!("{name} {}: leak {leak:e}", method.label());
            assert!(leak <= 1e-6, "{name} {}: leak {leak}", method.label());
        }
        drop(gpu);
    }
    finish(ctx);
}

#[test]
fn the_image_does_not_depend_on_the_scene_scale() {
    let ctx = context();
    let shaders = shaders();
    let mut base: Option<(Image, Image)> = None;
    for name in ["cornell_1", "cornell_1e-3", "cornell_1e4"] {
        let (scene, _) = load(name);
        let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
        let ic = finite_render(
            &ctx,
            &shaders,
            &scene,
            &mut gpu,
            Method::Ic(Preset::Draft),
            effort(4),
        );
        let path = finite_render(
            &ctx,
            &shaders,
            &scene,
            &mut gpu,
            Method::Path(64),
            effort(1),
        );
        drop(gpu);
        let Some((ic1, path1)) = &base else {
            base = Some((ic.image, path.image));
            continue;
        };
        let check = StiffCheck::Reference(None);
        let (fi, fp) = (
            figures(&check, ic1, &ic.image),
            figures(&check, path1, &path.image),
        );
        show(name, Method::Ic(Preset::Draft), &fi);
        show(name, Method::Path(64), &fp);
        // Same seeds, same image up to float round-off and the odd different ray.
        assert!(
            fi.metrics.relmse <= 2e-3,
            "{name}: cache relMSE {}",
            fi.metrics.relmse
        );
        assert!(
            fi.metrics.max_mean_ratio_dev() <= 0.01,
            "{name}: cache {fi:?}"
        );
        assert!(
            fp.metrics.max_mean_ratio_dev() <= 0.03,
            "{name}: path {fp:?}"
        );
    }
    finish(ctx);
}

fn warned(w: &[Warning], kind: WarningKind) -> usize {
    w.iter().filter(|w| w.kind == kind).map(|w| w.count).sum()
}

#[test]
fn degenerate_input_warns_or_fails_clearly() {
    let (_, w) = load("degenerate");
    assert_eq!(
        warned(&w, WarningKind::DegenerateTriangles),
        DEGENERATE_DROPPED
    );
    assert_eq!(
        warned(&w, WarningKind::GeneratedNormals),
        DEGENERATE_GENERATED_NORMALS
    );
    assert!(w
        .iter()
        .filter(|w| w.kind == WarningKind::DegenerateTriangles)
        .all(|w| w.message.contains("degenerate.gltf") && w.message.contains("mesh 1 \"junk\"")));
    for name in ["nan_vertex", "inf_vertex"] {
        let path = write(name);
        let e = Scene::load(&path, &LoadOptions::default()).unwrap_err();
        // NaN: the loader's finiteness check; ±inf: already the glTF validation (POSITION needs
        // finite min/max, which the writer cannot give).
        assert!(
            matches!(
                e,
                Error::NonFinite { position: 1, .. } | Error::Parse { .. }
            ),
            "{e:?}"
        );
        let msg = e.to_string();
        assert!(
            msg.contains(&*path.to_string_lossy()) && msg.contains("POSITION"),
            "{msg}"
        );
    }
}

/// Renders `name` with the cache at every preset in `presets` and with the path tracer at
/// 16 spp, against the path tracer at 256 spp; returns (method, figures).
fn against_the_path_tracer(
    ctx: &Context,
    shaders: &ShaderCompiler,
    name: &str,
    presets: &[Preset],
) -> Vec<(Method, Figures)> {
    let (scene, _) = load(name);
    let mut gpu = GpuScene::new(ctx, &scene, None).unwrap();
    let mut reference_effort = effort(1);
    reference_effort.seed = 99;
    let reference = finite_render(
        ctx,
        shaders,
        &scene,
        &mut gpu,
        Method::Path(256),
        reference_effort,
    );
    let check = StiffCheck::Reference(None);
    let mut out = Vec::new();
    let methods = presets
        .iter()
        .map(|&p| Method::Ic(p))
        .chain([Method::Path(16)]);
    for m in methods {
        let r = finite_render(ctx, shaders, &scene, &mut gpu, m, effort(4));
        let f = figures(&check, &reference.image, &r.image);
        show(name, m, &f);
        out.push((m, f));
    }
    drop(gpu);
    out
}

#[test]
fn hard_scenes_match_the_path_tracer() {
    let ctx = context();
    let shaders = shaders();
    // (scene, cache relMSE bound, cache block RMSE bound relative to the reference's mean); the
    // relMSE holds the 256-spp reference's own noise (about a sixteenth of the 16-spp row's).
    let cases = [
        ("slit", 0.1, 0.3),
        ("panel", 0.01, 0.05),
        ("wedge", 0.03, 0.05),
        ("tiny_bright", 0.005, 0.05),
        ("grazing", 0.015, 0.05),
        ("degenerate", 0.01, 0.05),
        ("glossy_bright", 0.01, 0.05),
        ("glossy_grazing", 0.01, 0.05),
    ];
    for (name, max_relmse, max_block) in cases {
        let presets: &[Preset] = if matches!(name, "tiny_bright" | "degenerate") {
            &[Preset::Draft, Preset::Default, Preset::High]
        } else {
            &[Preset::Draft]
        };
        for (m, f) in against_the_path_tracer(&ctx, &shaders, name, presets) {
            let mean = f.mean / f.metrics.mean_ratio[1].max(1e-30);
            let block = f.metrics.block_rmse / mean.max(1e-30);
            assert!(f.metrics.max_mean_ratio_dev() <= 0.1, "{name} {m:?}: {f:?}");
            if let Method::Ic(_) = m {
                assert!(f.metrics.relmse <= max_relmse, "{name} {m:?}: {f:?}");
                assert!(block <= max_block, "{name} {m:?}: block {block}");
            }
        }
    }
    finish(ctx);
}
