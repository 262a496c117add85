//! `cargo xtask codegen [--check]`: writes the generated GLSL from the Rust sources of truth
//! (`shaders/shared/layouts.glsl` and `constants.glsl` from `radcache-shared`,
//! `shaders/shared/bindings.glsl` from `radcache-render::bindings`, `shaders/shared/push.glsl`
//! from the passes' push-constant structs), or with `--check` fails if a file on disk is stale.

use anyhow::{bail, Result};

pub fn run(args: &[&str]) -> Result<()> {
    let check = match args {
        [] => false,
        ["--check"] => true,
        _ => bail!("usage: cargo xtask codegen [--check]"),
    };
    let files = [
        ("layouts.glsl", radcache_shared::gpu::generated_glsl()),
        ("constants.glsl", radcache_shared::consts::generated_glsl()),
        ("bindings.glsl", radcache_render::bindings::generated_glsl()),
        ("push.glsl", radcache_render::passes::push_constants_glsl()),
    ];
    let dir = crate::root().join("shaders/shared");
    let mut stale = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
        if on_disk == text {
            println!("{} is up to date", path.display());
        } else if check {
            stale.push(path.display().to_string());
        } else {
            std::fs::create_dir_all(&dir)?;
            std::fs::write(&path, text)?;
            println!("wrote {}", path.display());
        }
    }
    if !stale.is_empty() {
        bail!(
            "stale generated files (run `cargo xtask codegen`): {}",
            stale.join(", ")
        );
    }
    Ok(())
}
