//! Atomic file output: write a temporary file beside the destination, then rename it.
//!
//! The temporary file is a `tempfile` named temporary file in the destination's directory (so the
//! rename never crosses file systems) under a hidden name `.<file name>.<random>.tmp`, created
//! with the permissions a plain `File::create` would give (not `tempfile`'s private 0600). Its
//! contents are flushed and `fsync`ed before `persist` renames it onto the destination, and it
//! is removed again when writing or renaming fails. A reader polling the final path (e.g. a
//! sequence viewer) therefore sees either the previous file or the complete new one, never a
//! partial write. A process killed mid-write may leave a hidden `.tmp` file behind, but never a
//! partial file at the final path.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use tempfile::{Builder, NamedTempFile};

use crate::error::{Error, Result};

/// Writes `path` atomically: `write` fills a buffered temporary file, which is renamed to `path`
/// only when `write` and the flush succeed. Errors name `path`.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    // Dropping `temp` (on any error below) deletes the temporary file.
    let (file, temp) = create_temp(path)?.into_parts();
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let io_error = |source| Error::Io {
        op: "cannot finish writing",
        path: path.to_owned(),
        source,
    };
    writer.flush().map_err(io_error)?;
    let file = writer.into_inner().map_err(|e| io_error(e.into_error()))?;
    file.sync_all().map_err(io_error)?;
    drop(file);
    temp.persist(path).map_err(|e| Error::Io {
        op: "cannot rename temporary file onto",
        path: path.to_owned(),
        source: e.error,
    })
}

/// A hidden temporary file `.<file name>.<random>.tmp` in the directory of `path`.
fn create_temp(path: &Path) -> Result<NamedTempFile> {
    let name = path.file_name().ok_or_else(|| Error::Io {
        op: "cannot write to",
        path: path.to_owned(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the path does not name a file",
        ),
    })?;
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    let mut builder = Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        // 0666 before the umask, as `File::create`; tempfile's default is 0600.
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir).map_err(|source| Error::Io {
        op: "cannot create temporary file for",
        path: path.to_owned(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_paths_without_file_name() {
        for bad in ["/", "out/.."] {
            let err = write_atomic(Path::new(bad), |_| Ok(())).unwrap_err();
            let text = err.to_string();
            assert!(matches!(err, Error::Io { .. }), "{text}");
            assert!(text.contains(bad), "{text}");
        }
    }
}
