//! The errors of reading and checking a cache file: one variant per refusal class, each naming
//! the file.

use std::path::PathBuf;

/// Why a cache file was refused.
#[derive(Debug, thiserror::Error)]
pub enum Refusal {
    /// The file does not start with the cache file's magic.
    #[error("not a radcache cache file (it does not start with \"RADCACHE\")")]
    NotACacheFile,
    /// Written by a format version this build cannot read.
    #[error(
        "format version {found}, this radcache reads versions {oldest} to {newest} (write it again)"
    )]
    Version {
        /// The file's version.
        found: u32,
        /// The oldest version this build reads.
        oldest: u32,
        /// The version this build writes (the newest it reads).
        newest: u32,
    },
    /// Shorter than its header says.
    #[error("truncated: {len} bytes, the header says {expected}")]
    Truncated {
        /// The file's length.
        len: u64,
        /// The length its header announces (or the header's own length).
        expected: u64,
    },
    /// A checksum, a length or a field that cannot be right.
    #[error("corrupted: {0}")]
    Corrupt(String),
    /// Made for another scene (geometry, materials, lights, environment or animation differ).
    #[error(
        "made for another scene: its scene content hash is {file:016x}, this scene's is \
         {scene:016x} (geometry, materials, lights, environment or animation differ)"
    )]
    OtherScene {
        /// The file's scene hash.
        file: u64,
        /// The current scene's hash.
        scene: u64,
    },
    /// Made with other cache parameters.
    #[error("made with other cache parameters: {0}")]
    OtherParams(String),
    /// Made with other camera-independent settings.
    #[error("made with other settings: {0}")]
    OtherSettings(String),
    /// More records than the renderer has room for.
    #[error("holds {count} records, more than the renderer's capacity of {capacity}")]
    TooManyRecords {
        /// Records in the file.
        count: u32,
        /// The renderer's record capacity.
        capacity: u32,
    },
}

/// A cache file that could not be read, written or used.
#[derive(Debug, thiserror::Error)]
pub enum CacheFileError {
    /// Reading failed.
    #[error("cannot read cache file '{}': {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file was read and refused.
    #[error("cache file '{}': {refusal}", path.display())]
    Refused {
        /// The file.
        path: PathBuf,
        /// Why.
        refusal: Refusal,
    },
}

impl CacheFileError {
    /// The refusal, when the file was read and refused.
    pub fn refusal(&self) -> Option<&Refusal> {
        match self {
            CacheFileError::Refused { refusal, .. } => Some(refusal),
            CacheFileError::Io { .. } => None,
        }
    }
}
