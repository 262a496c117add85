//! `cargo xtask refs`: renders the path-traced references the cache tests compare against, into
//! `tests/refs/` (EXR with metadata; the exact settings are in each file's header and below).
//!
//! | file | scene | size | spp | seed |
//! |---|---|---|---|---|
//! | `cornell_256.exr` | `assets/cornell/cornell.gltf` | 256×256 | 2048 | 12345 |
//! | `courtyard_256.exr` | `assets/courtyard/courtyard.gltf` | 256×256 | 1024 | 0 |

use anyhow::{Context as _, Result};
use radcache_image::{write_exr, ExrOptions, Image, Metadata};
use radcache_render::{render_path, Budget, GpuScene, PathSettings};
use radcache_scene::{LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};

/// One reference image.
pub struct Reference {
    /// File name under `tests/refs/`.
    pub file: &'static str,
    /// Scene, relative to the repository root.
    pub scene: &'static str,
    /// Width and height.
    pub size: (u32, u32),
    /// Samples per pixel.
    pub spp: u32,
    /// Seed.
    pub seed: u32,
}

/// The references the tests use.
pub const REFERENCES: &[Reference] = &[
    Reference {
        file: "cornell_256.exr",
        scene: "assets/cornell/cornell.gltf",
        size: (256, 256),
        spp: 2048,
        seed: 12345,
    },
    Reference {
        file: "courtyard_256.exr",
        scene: "assets/courtyard/courtyard.gltf",
        size: (256, 256),
        spp: 1024,
        seed: 0,
    },
];

pub fn run(args: &[&str]) -> Result<()> {
    anyhow::ensure!(args.is_empty(), "usage: cargo xtask refs");
    if std::env::var_os("RADCACHE_VALIDATION").is_none() {
        std::env::set_var("RADCACHE_VALIDATION", "0");
    }
    let ctx = Context::new()?;
    let shaders = ShaderCompiler::new(crate::root().join("shaders"))?;
    for r in REFERENCES {
        let scene_path = crate::root().join(r.scene);
        let (scene, _) = Scene::load(&scene_path, &LoadOptions::default())?;
        let mut gpu = GpuScene::new(&ctx, &scene, None)?;
        let settings = PathSettings {
            width: r.size.0,
            height: r.size.1,
            budget: Budget::Samples(r.spp),
            seed: r.seed,
            ..PathSettings::default()
        };
        let mut last = 0;
        let out = render_path(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |p| {
            if p.done * 10 / p.total.max(1) > last {
                last = p.done * 10 / p.total.max(1);
                eprintln!(
                    "{}: {}/{} spp, {:.0} s",
                    r.file, p.done, p.total, p.elapsed_s
                );
            }
        })?;
        let image = Image::from_pixels(out.width, out.height, out.pixels)?;
        let mut meta = Metadata::new();
        meta.method = Some("path".into());
        meta.spp = Some(out.spp);
        meta.render_time_s = Some(out.time_s);
        meta.scene_file = Some(r.scene.into());
        meta.extra.insert("seed".into(), r.seed.to_string());
        meta.extra
            .insert("command".into(), "cargo xtask refs".into());
        let path = crate::root().join("tests/refs").join(r.file);
        std::fs::create_dir_all(path.parent().unwrap_or(&crate::root()))?;
        write_exr(&path, &image, &meta, &ExrOptions::default())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {} ({:.0} s)", path.display(), out.time_s);
    }
    Ok(())
}
