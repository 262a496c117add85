//! Text outputs of the CLI: reports on stdout, and files (stats, profiles) written atomically into
//! a folder made on demand.

use std::path::Path;

use anyhow::{Context as _, Result};

/// Writes `text` to stdout; a closed pipe (`radcache info x | head`) is not an error.
pub fn emit(text: &str) -> std::io::Result<()> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}

/// Creates the folder `path` goes into, if any; errors name `what`.
pub fn make_parent(path: &Path, what: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the {what} folder {}", dir.display()))?;
    }
    Ok(())
}

/// Writes `text` to `path` atomically, creating its folder; errors name `what` (and the writer's
/// name the path).
pub fn write_text(path: &Path, text: &str, what: &str) -> Result<()> {
    write_bytes(path, text.as_bytes(), what)
}

/// Writes `bytes` to `path` atomically, creating its folder; errors name `what` (and the writer's
/// name the path).
pub fn write_bytes(path: &Path, bytes: &[u8], what: &str) -> Result<()> {
    make_parent(path, what)?;
    radcache_image::write_atomic(path, |w| {
        use std::io::Write;
        w.write_all(bytes)
            .map_err(|source| radcache_image::Error::Io {
                op: "cannot write",
                path: path.to_path_buf(),
                source,
            })
    })
    .with_context(|| format!("writing the {what}"))
}
