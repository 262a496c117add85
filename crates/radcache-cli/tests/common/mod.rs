//! Helpers shared by the `radcache` binary's integration tests (each test file uses some).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `radcache` binary under test. It leaves the user's pipeline cache alone (the cache is
/// off) unless `RADCACHE_PIPELINE_CACHE` is set for the test run or by the test.
pub fn bin() -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_radcache"));
    if std::env::var_os("RADCACHE_PIPELINE_CACHE").is_none() {
        cmd.env("RADCACHE_PIPELINE_CACHE", "off");
    }
    cmd
}

/// Runs `radcache` with `args` and waits for it.
pub fn radcache(args: &[&str]) -> Output {
    bin().args(args).output().expect("running radcache")
}

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The bundled Cornell box.
pub fn cornell() -> String {
    repo()
        .join("assets/cornell/cornell.gltf")
        .display()
        .to_string()
}

/// `radcache-<tag>-<pid>-<name>` in the temp dir, removed if it exists (not created).
pub fn fresh_path(tag: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radcache-{tag}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A fresh, empty directory for one test ([`fresh_path`], created).
pub fn fresh_dir(tag: &str, name: &str) -> PathBuf {
    let dir = fresh_path(tag, name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as a command-line argument.
pub fn text(p: &Path) -> String {
    p.display().to_string()
}

/// `shared/models/<rel>`: the Khronos sample models kept beside the checkout (`../shared/models`
/// from the repository root in CI; a git worktree finds it in a folder further up). Panics,
/// naming where it looked, when the file is absent.
pub fn shared_model(rel: &str) -> PathBuf {
    let root = repo().canonicalize().unwrap_or_else(|_| repo());
    let candidates: Vec<PathBuf> = root
        .ancestors()
        .map(|dir| dir.join("shared/models").join(rel))
        .collect();
    match candidates.iter().find(|p| p.is_file()) {
        Some(p) => p.clone(),
        None => panic!("shared model {rel} not found; looked for {candidates:?}"),
    }
}
