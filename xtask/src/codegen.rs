//! `cargo xtask codegen [--check]`: writes the generated GLSL (`shaders/shared/layouts.glsl`) from
//! `radcache-shared`, or with `--check` fails if the file on disk is stale.

use anyhow::{bail, Result};

pub fn run(args: &[&str]) -> Result<()> {
    let path = crate::root().join("shaders/shared/layouts.glsl");
    let text = radcache_shared::gpu::generated_glsl();
    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
    match args {
        ["--check"] if on_disk != text => {
            bail!("{} is stale: run `cargo xtask codegen`", path.display())
        }
        ["--check"] => println!("{} is up to date", path.display()),
        [] if on_disk == text => println!("{} unchanged", path.display()),
        [] => {
            std::fs::create_dir_all(path.parent().unwrap_or(&crate::root()))?;
            std::fs::write(&path, text)?;
            println!("wrote {}", path.display());
        }
        _ => bail!("usage: cargo xtask codegen [--check]"),
    }
    Ok(())
}
