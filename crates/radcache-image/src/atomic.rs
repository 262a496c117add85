//! Atomic file output: write a temporary file beside the destination, then rename it.
//!
//! The temporary file lives in the destination's directory (so the rename never crosses file
//! systems) under a hidden name `.<file name>.<pid>.<n>.tmp`. Its contents are flushed and
//! `fsync`ed before the rename, and it is removed again when writing fails. A reader polling the
//! final path (e.g. a sequence viewer) therefore sees either the previous file or the complete
//! new one, never a partial write. An interrupted process may leave a hidden `.tmp` file behind,
//! but never a partial file at the final path.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Distinguishes temporary files of concurrent writes from one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically: `write` fills a buffered temporary file, which is renamed to `path`
/// only when `write` and the flush succeed. Errors name `path`.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let temp = temp_path(path)?;
    let result = write_temp(path, &temp, write).and_then(|()| {
        std::fs::rename(&temp, path).map_err(|source| Error::Io {
            op: "cannot rename temporary file onto",
            path: path.to_owned(),
            source,
        })
    });
    if result.is_err() {
        // Best effort: the temporary file may not exist (e.g. missing directory).
        let _ = std::fs::remove_file(&temp);
    }
    result
}

fn write_temp<F>(path: &Path, temp: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let file = File::create(temp).map_err(|source| Error::Io {
        op: "cannot create temporary file for",
        path: path.to_owned(),
        source,
    })?;
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let io_error = |source| Error::Io {
        op: "cannot finish writing",
        path: path.to_owned(),
        source,
    };
    writer.flush().map_err(io_error)?;
    let file = writer.into_inner().map_err(|e| io_error(e.into_error()))?;
    file.sync_all().map_err(io_error)
}

/// `.<file name>.<pid>.<n>.tmp` in the directory of `path`.
fn temp_path(path: &Path) -> Result<PathBuf> {
    let name = path.file_name().ok_or_else(|| Error::Io {
        op: "cannot write to",
        path: path.to_owned(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the path does not name a file",
        ),
    })?;
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(
        ".{}.{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    Ok(path.with_file_name(temp_name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_path_is_hidden_sibling() {
        let temp = temp_path(Path::new("out/dir/frame.exr")).unwrap();
        assert_eq!(temp.parent(), Some(Path::new("out/dir")));
        let name = temp.file_name().unwrap().to_str().unwrap();
        assert!(
            name.starts_with(".frame.exr.") && name.ends_with(".tmp"),
            "{name}"
        );
        let bare = temp_path(Path::new("frame.exr")).unwrap();
        assert_eq!(bare.parent(), Some(Path::new("")));
    }

    #[test]
    fn rejects_paths_without_file_name() {
        assert!(temp_path(Path::new("/")).is_err());
        assert!(temp_path(Path::new("out/..")).is_err());
    }
}
