//! `cargo xtask gallery`: the real glTF files of `../shared/models/` (Khronos sample models, not
//! in the repository) rendered with the irradiance cache under a uniform environment, each next to
//! its path-traced reference, with the cache frame's error against it; the frames are tiled into
//! `docs/gallery.png` (a contact sheet: per model, the cache frame then the reference) for the
//! design notes (docs/design.md).
//!
//! Options: `--size N` (square images, default 192), `--spp N` (reference samples per pixel,
//! default 1024), `--models a,b` (default: every model below that exists), `--out FILE`.

use std::path::PathBuf;

use anyhow::{bail, Context as _, Result};
use radcache_image::{compare, contact_sheet, write_png, Image, PngOptions};
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcSettings, PathSettings};
use radcache_scene::{EnvOverride, LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};

/// The models: a name and its path under `../shared/models/`.
const MODELS: &[(&str, &str)] = &[
    (
        "DamagedHelmet",
        "DamagedHelmet/glTF-Binary/DamagedHelmet.glb",
    ),
    ("Suzanne", "Suzanne/glTF/Suzanne.gltf"),
];

/// The environment the models are lit by (they have no lights of their own).
const ENV_RADIANCE: [f32; 3] = [0.8, 0.8, 0.8];

const USAGE: &str =
    "usage: cargo xtask gallery [--size N] [--spp N] [--models a,b] [--out docs/gallery.png]";

pub fn run(args: &[&str]) -> Result<()> {
    let (mut size, mut spp) = (192u32, 1024u32);
    let mut names: Vec<String> = MODELS.iter().map(|m| m.0.to_string()).collect();
    let mut out = crate::root().join("docs/gallery.png");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || {
            it.next()
                .with_context(|| format!("{a} needs a value; {USAGE}"))
        };
        match *a {
            "--size" => size = value()?.parse()?,
            "--spp" => spp = value()?.parse()?,
            "--models" => names = value()?.split(',').map(str::to_string).collect(),
            "--out" => out = PathBuf::from(value()?),
            _ => bail!("unknown argument {a}; {USAGE}"),
        }
    }
    if std::env::var_os("RADCACHE_VALIDATION").is_none() {
        std::env::set_var("RADCACHE_VALIDATION", "0");
    }
    let models_dir = crate::root().join("../shared/models");
    let ctx = Context::new()?;
    let shaders = ShaderCompiler::new(crate::root().join("shaders"))?;
    let mut frames = Vec::new();
    println!("| model | cache frame s | relMSE vs path tracer ({spp} spp) | mean ratio | FLIP |");
    println!("|---|---|---|---|---|");
    for name in &names {
        let Some((_, rel)) = MODELS.iter().find(|m| m.0 == name) else {
            bail!("unknown model {name}; {USAGE}");
        };
        let path = models_dir.join(rel);
        let opts = LoadOptions {
            env: EnvOverride {
                radiance: Some(ENV_RADIANCE),
                ..EnvOverride::default()
            },
            ..LoadOptions::default()
        };
        let (scene, _) =
            Scene::load(&path, &opts).with_context(|| format!("gallery: {}", path.display()))?;
        let mut gpu = GpuScene::new(&ctx, &scene, None)?;
        let settings = IcSettings {
            width: size,
            height: size,
            ..IcSettings::default()
        };
        let t0 = std::time::Instant::now();
        let (ic, _) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
        let ic_s = t0.elapsed().as_secs_f64();
        let pt = render_path(
            &ctx,
            &shaders,
            &scene,
            &mut gpu,
            &PathSettings {
                width: size,
                height: size,
                budget: Budget::Samples(spp),
                seed: 1,
                ..PathSettings::default()
            },
            &mut |_| {},
        )?;
        let ic = Image::from_pixels(ic.width, ic.height, ic.pixels)?;
        let pt = Image::from_pixels(pt.width, pt.height, pt.pixels)?;
        let m = compare(&pt, &ic)?;
        println!(
            "| {name} | {ic_s:.1} | {:.2e} | {:.4} {:.4} {:.4} | {} |",
            m.relmse,
            m.mean_ratio[0],
            m.mean_ratio[1],
            m.mean_ratio[2],
            m.flip.map_or("-".into(), |f| format!("{f:.4}"))
        );
        frames.push(ic);
        frames.push(pt);
        drop(gpu);
    }
    let sheet = contact_sheet(&frames)?;
    write_png(&out, &sheet, &PngOptions::default())?;
    println!("wrote {}", out.display());
    Ok(())
}
