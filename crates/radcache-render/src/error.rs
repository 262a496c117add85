//! Errors of the renderer: each names what failed (file, pass, resource).

use std::path::PathBuf;

/// A renderer error.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A Vulkan-level failure (device, allocation, shader, pipeline).
    #[error(transparent)]
    Vk(#[from] radcache_vk::Error),
    /// An image file could not be read or written.
    #[error(transparent)]
    Image(#[from] radcache_image::Error),
    /// The environment map cannot be used.
    #[error("environment map {path}: {message}")]
    EnvMap {
        /// The map file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// The request is not valid for this scene or device.
    #[error("{0}")]
    Invalid(String),
    /// The scene needs more device memory than the device has (checked before any upload; the
    /// message names the parts and the sizes).
    #[error("{0}")]
    SceneTooLarge(String),
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
