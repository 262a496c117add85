//! Output path patterns for frame sequences.
//!
//! A pattern holds exactly one run of `#`; [`frame_path`] replaces it by the frame number,
//! zero-padded to the run's length (`frame_####.exr`, 7 → `frame_0007.exr`). Numbers wider
//! than the run are written in full (`f_##.exr`, 123 → `f_123.exr`), as `printf("%02d")` does.
//! Patterns must be valid UTF-8.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Whether `pattern` contains a `#`.
pub fn has_frame_pattern(pattern: impl AsRef<Path>) -> bool {
    pattern.as_ref().to_str().is_some_and(|p| p.contains('#'))
}

/// `pattern` with its single run of `#` replaced by the zero-padded `frame`.
///
/// Errors (naming the pattern) when it has no `#`, more than one run of `#`, or is not UTF-8.
pub fn frame_path(pattern: impl AsRef<Path>, frame: u32) -> Result<PathBuf> {
    let pattern = pattern.as_ref();
    let error = |message: &str| Error::PathPattern {
        pattern: pattern.to_owned(),
        message: message.to_owned(),
    };
    let text = pattern
        .to_str()
        .ok_or_else(|| error("the path is not valid UTF-8"))?;
    let start = text
        .find('#')
        .ok_or_else(|| error("a frame sequence needs a run of '#' for the frame number"))?;
    let width = text[start..].bytes().take_while(|&b| b == b'#').count();
    let rest = &text[start + width..];
    if rest.contains('#') {
        return Err(error("more than one run of '#'"));
    }
    Ok(PathBuf::from(format!(
        "{}{frame:0width$}{rest}",
        &text[..start]
    )))
}

/// The output path for `frame`: with `sequence`, the pattern must contain `#` (see
/// [`frame_path`]); for a single image a pattern with `#` is still expanded with `frame`, and a
/// path without `#` is used as it is.
pub fn output_path(pattern: impl AsRef<Path>, frame: u32, sequence: bool) -> Result<PathBuf> {
    let pattern = pattern.as_ref();
    if sequence || has_frame_pattern(pattern) {
        frame_path(pattern, frame)
    } else {
        Ok(pattern.to_owned())
    }
}

/// The PNG preview path beside an image path: the extension is replaced by (or, without one,
/// extended with) `png`, e.g. `out/frame_0007.exr` → `out/frame_0007.png`.
pub fn png_beside(path: impl AsRef<Path>) -> PathBuf {
    path.as_ref().with_extension("png")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide_numbers_are_not_truncated() {
        assert_eq!(frame_path("f_##.exr", 123).unwrap(), Path::new("f_123.exr"));
    }

    #[test]
    fn two_runs_are_an_error() {
        let err = frame_path("a##/b##.exr", 1).unwrap_err().to_string();
        assert!(err.contains("a##/b##.exr"), "{err}");
    }
}
