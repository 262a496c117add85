//! The crate's error type.
//!
//! Every variant that concerns a file names its path, so a failed frame of a long sequence can be
//! found from the message alone. Bad input (missing, corrupt or unexpected files, mismatched
//! image sizes, malformed path patterns) is always reported through [`Error`], never by a panic.
//!
//! A variant that wraps an underlying error returns it from [`std::error::Error::source`] and
//! does not repeat it in its own message, so a chain printed cause by cause (anyhow's `{:#}`)
//! names each cause once: `cannot write EXR 'out.exr': No space left on device (os error 28)`.
//! I/O failures inside the `exr` and `png` encoders become [`Error::Io`]: the `exr` crate's own
//! error both shows and returns its I/O cause, which would print it twice.

use std::path::{Path, PathBuf};

/// Errors of `radcache-image`.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An operating-system I/O operation on `path` failed.
    #[error("{op} '{path}'")]
    Io {
        /// What was being done, e.g. "cannot create temporary file for".
        op: &'static str,
        /// The file concerned (the final path for atomic writes).
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },

    /// The `exr` crate failed to encode `path` (other than by an I/O error, which is [`Error::Io`]).
    #[error("cannot write EXR '{path}'")]
    ExrWrite {
        /// The destination file.
        path: PathBuf,
        /// The underlying error.
        source: exr::error::Error,
    },

    /// The `exr` crate failed to decode `path` (truncated or corrupt file; a missing or
    /// unreadable one is [`Error::Io`]).
    #[error("cannot read EXR '{path}'")]
    ExrRead {
        /// The source file.
        path: PathBuf,
        /// The underlying error.
        source: exr::error::Error,
    },

    /// `path` is a valid EXR but not one this crate can interpret (e.g. no R, G, B channels).
    #[error("unsupported EXR content in '{path}': {message}")]
    ExrContent {
        /// The source file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// A sample that would put NaN or ±inf into `path`: non-finite, or (for `f16` output)
    /// beyond ±65504. Only the first such sample is reported; set
    /// [`crate::ExrOptions::sanitize`] to replace these values instead.
    #[error(
        "refusing to write '{path}': channel '{channel}' at pixel ({x}, {y}) is {value}, {problem} \
         (set ExrOptions::sanitize to replace such values)"
    )]
    NonFinite {
        /// The destination file.
        path: PathBuf,
        /// Full EXR channel name, e.g. `R` or `albedo.G`.
        channel: String,
        /// Column of the pixel (0 = left).
        x: u32,
        /// Row of the pixel (0 = top).
        y: u32,
        /// The offending value.
        value: f32,
        /// Why it cannot be written, e.g. "which is not finite".
        problem: &'static str,
    },

    /// Metadata that cannot be stored as EXR header attributes.
    #[error("invalid metadata for '{path}': {message}")]
    Metadata {
        /// The destination file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// The `png` crate failed to encode `path` (other than by an I/O error, which is [`Error::Io`]).
    #[error("cannot write PNG '{path}'")]
    Png {
        /// The destination file.
        path: PathBuf,
        /// The underlying error.
        source: png::EncodingError,
    },

    /// An output path pattern could not be expanded.
    #[error("invalid output path pattern '{pattern}': {message}")]
    PathPattern {
        /// The pattern as given.
        pattern: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// Two images that must have the same size do not.
    #[error(
        "image size mismatch: reference is {}x{}, candidate is {}x{}",
        reference.0, reference.1, candidate.0, candidate.1
    )]
    SizeMismatch {
        /// Reference (width, height).
        reference: (u32, u32),
        /// Candidate (width, height).
        candidate: (u32, u32),
    },

    /// A frame sequence is too short to have a pair of consecutive frames.
    #[error("a frame sequence needs at least 2 frames, got {frames}")]
    TooFewFrames {
        /// The number of frames given.
        frames: usize,
    },

    /// A frame of a sequence, or of its reference sequence, differs in size from the first frame
    /// of the sequence.
    #[error(
        "{sequence} frame {frame} is {}x{}, but frame 0 of the sequence is {}x{}",
        found.0, found.1, expected.0, expected.1
    )]
    FrameSizeMismatch {
        /// Which sequence the frame belongs to: `"sequence"` or `"reference"`.
        sequence: &'static str,
        /// Index of the frame in its sequence (0 = first).
        frame: usize,
        /// The frame's (width, height).
        found: (u32, u32),
        /// (width, height) of the sequence's first frame.
        expected: (u32, u32),
    },

    /// A reference sequence does not have as many frames as the sequence it is compared with.
    #[error("the sequence has {frames} frames but its reference has {reference}")]
    SequenceLengthMismatch {
        /// Frames in the sequence.
        frames: usize,
        /// Frames in the reference sequence.
        reference: usize,
    },

    /// Pixel data or a layer does not fit the image it is given to.
    #[error("invalid image data: {0}")]
    InvalidImage(String),
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An `exr` crate failure while writing `path` ([`Error::ExrWrite`], or [`Error::Io`]).
    pub(crate) fn exr_write(path: &Path, error: exr::error::Error) -> Error {
        match error {
            exr::error::Error::Io(source) => Error::io("cannot write EXR", path, source),
            source => Error::ExrWrite {
                path: path.to_owned(),
                source,
            },
        }
    }

    /// An `exr` crate failure while reading `path` ([`Error::ExrRead`], or [`Error::Io`]).
    pub(crate) fn exr_read(path: &Path, error: exr::error::Error) -> Error {
        match error {
            exr::error::Error::Io(source) => Error::io("cannot read EXR", path, source),
            source => Error::ExrRead {
                path: path.to_owned(),
                source,
            },
        }
    }

    /// A `png` crate failure while writing `path` ([`Error::Png`], or [`Error::Io`]).
    pub(crate) fn png_write(path: &Path, error: png::EncodingError) -> Error {
        match error {
            png::EncodingError::IoError(source) => Error::io("cannot write PNG", path, source),
            source => Error::Png {
                path: path.to_owned(),
                source,
            },
        }
    }

    fn io(op: &'static str, path: &Path, source: std::io::Error) -> Error {
        Error::Io {
            op,
            path: path.to_owned(),
            source,
        }
    }
}

#[cfg(test)]
mod tests {
    use std::error::Error as _;

    use super::*;

    /// The chain as anyhow's `{:#}` prints it.
    fn chain(e: &Error) -> String {
        let mut text = e.to_string();
        let mut cause = e.source();
        while let Some(c) = cause {
            text += &format!(": {c}");
            cause = c.source();
        }
        text
    }

    #[test]
    fn a_full_disk_is_named_once() {
        let full = || std::io::Error::from_raw_os_error(28);
        let os = full().to_string();
        let path = Path::new("out/frame.exr");
        for err in [
            Error::exr_write(path, exr::error::Error::Io(full())),
            Error::exr_read(path, exr::error::Error::Io(full())),
            Error::png_write(path, png::EncodingError::IoError(full())),
        ] {
            let text = chain(&err);
            assert_eq!(text.matches(&os).count(), 1, "{text}");
            assert!(text.contains("'out/frame.exr'"), "{text}");
        }
        let text = chain(&Error::exr_write(
            path,
            exr::error::Error::Invalid("bad".into()),
        ));
        assert_eq!(text, "cannot write EXR 'out/frame.exr': invalid: bad");
    }
}
