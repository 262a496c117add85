//! `cargo xtask assets [--check]`: writes the bundled glTF scenes (Cornell box, furnace, animated
//! room, static Cornell fly-through, Sponza-class courtyard) into `<repo>/assets` with
//! `radcache_scene::assets::write_bundled_assets`, or with `--check` regenerates them into a
//! temporary directory and fails if any generated file is missing from `assets/` or differs from
//! it byte for byte (the generators are deterministic).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The repository root: the parent of the xtask crate's directory.
fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(PathBuf::from)
        .unwrap_or_default()
}

/// Runs the task with the arguments after `assets`.
pub fn run(args: &[String]) -> Result<()> {
    let assets = repo_root().join("assets");
    match args {
        [] => {
            let written = radcache_scene::assets::write_bundled_assets(&assets)
                .with_context(|| format!("writing the bundled assets into {}", assets.display()))?;
            for path in written {
                println!("wrote {}", path.display());
            }
            Ok(())
        }
        [flag] if flag == "--check" => check(&assets),
        _ => bail!("usage: cargo xtask assets [--check]"),
    }
}

/// Regenerates into a temporary directory and compares with `assets`.
fn check(assets: &Path) -> Result<()> {
    let tmp = std::env::temp_dir().join(format!("radcache-assets-check-{}", std::process::id()));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).with_context(|| format!("removing {}", tmp.display()))?;
    }
    let result = compare(assets, &tmp);
    // Best effort: a leftover temporary directory is harmless.
    let _ = std::fs::remove_dir_all(&tmp);
    let (checked, stale) = result?;
    if stale.is_empty() {
        println!("{} is up to date ({checked} files)", assets.display());
        Ok(())
    } else {
        bail!(
            "{} is stale (changed or missing: {}); run `cargo xtask assets`",
            assets.display(),
            stale.join(", ")
        )
    }
}

/// Writes the assets into `tmp` and returns (number of files compared, stale relative paths).
fn compare(assets: &Path, tmp: &Path) -> Result<(usize, Vec<String>)> {
    radcache_scene::assets::write_bundled_assets(tmp)
        .with_context(|| format!("writing the bundled assets into {}", tmp.display()))?;
    let mut files = Vec::new();
    collect_files(tmp, &mut files)?;
    files.sort();
    let mut stale = Vec::new();
    for file in &files {
        let rel = file
            .strip_prefix(tmp)
            .context("generated file outside the directory")?;
        let fresh = std::fs::read(file).with_context(|| format!("reading {}", file.display()))?;
        if std::fs::read(assets.join(rel)).ok().as_deref() != Some(fresh.as_slice()) {
            stale.push(rel.display().to_string());
        }
    }
    Ok((files.len(), stale))
}

/// Every regular file under `dir`, recursively.
fn collect_files(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    for entry in std::fs::read_dir(dir).with_context(|| format!("listing {}", dir.display()))? {
        let path = entry?.path();
        if path.is_dir() {
            collect_files(&path, out)?;
        } else {
            out.push(path);
        }
    }
    Ok(())
}
