//! Errors and warnings of the scene loader and writer.
//!
//! Every [`Error`] names the glTF file and the element at fault (buffer, accessor, mesh/primitive,
//! node, camera, animation, image), with index and name where known, so that a user can find it in
//! the JSON. Bad input never panics: it becomes an `Error`, or a [`Warning`] when the loader can
//! carry on with a documented fallback (e.g. skins rendered in their rest pose).
//!
//! A variant that wraps an I/O error returns it from [`std::error::Error::source`] and does not
//! repeat it in its own message, so a chain printed cause by cause (anyhow's `{:#}`) names each
//! cause once: `scene.gltf: cannot read glTF file: No such file or directory (os error 2)`.

use std::fmt;
use std::path::PathBuf;

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A load or write failure. Each variant carries the path of the glTF file it concerns.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The glTF file itself cannot be read (missing, permissions, ...).
    #[error("{path}: cannot read glTF file")]
    Io {
        /// The glTF file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file is not valid glTF 2.0 JSON/GLB, or fails the gltf crate's schema validation.
    #[error("{path}: invalid glTF: {message}")]
    Parse {
        /// The glTF file.
        path: PathBuf,
        /// What the parser or validator reported.
        message: String,
    },
    /// `asset.version` is not 2.x, or `asset.minVersion` asks for more than glTF 2.0.
    #[error("{path}: unsupported glTF version: asset.{field} is {version:?}, {reason}")]
    UnsupportedVersion {
        /// The glTF file.
        path: PathBuf,
        /// The offending field: `version` or `minVersion`.
        field: &'static str,
        /// Its value.
        version: String,
        /// What this loader reads instead.
        reason: &'static str,
    },
    /// `extensionsRequired` names an extension this loader does not implement.
    #[error("{path}: the file requires the glTF extension {name:?} (extensionsRequired), which radcache does not support: {reason}")]
    UnsupportedExtension {
        /// The glTF file.
        path: PathBuf,
        /// The extension name.
        name: String,
        /// What the extension needs that radcache lacks.
        reason: String,
    },
    /// A buffer's file is missing or unreadable, or its data URI cannot be decoded.
    #[error("{path}: {element}: cannot load buffer data from {uri:?}: {reason}")]
    MissingBuffer {
        /// The glTF file.
        path: PathBuf,
        /// The buffer, e.g. `buffer 0 "geometry"`.
        element: String,
        /// The buffer's URI (data URIs are shortened).
        uri: String,
        /// Why it could not be loaded.
        reason: String,
    },
    /// A buffer holds fewer bytes than its declared `byteLength`.
    #[error("{path}: {element}: buffer holds {actual} bytes but byteLength is {expected}")]
    ShortBuffer {
        /// The glTF file.
        path: PathBuf,
        /// The buffer.
        element: String,
        /// Declared `byteLength`.
        expected: usize,
        /// Bytes available.
        actual: usize,
    },
    /// An accessor (or its buffer view) reaches outside its buffer view or buffer, or has a layout
    /// that this loader cannot read for its use.
    #[error("{path}: {element}: {reason}")]
    Accessor {
        /// The glTF file.
        path: PathBuf,
        /// The accessor, with its user (e.g. `mesh 0 "box" primitive 1 POSITION accessor 3`).
        element: String,
        /// What is wrong.
        reason: String,
    },
    /// A vertex index is not smaller than the primitive's vertex count.
    #[error("{path}: {element}: index {index} at position {position} is out of range (vertex count {vertex_count})")]
    IndexOutOfRange {
        /// The glTF file.
        path: PathBuf,
        /// The mesh/primitive/accessor.
        element: String,
        /// The offending index value.
        index: u32,
        /// Its position in the index list.
        position: usize,
        /// Number of vertices of the primitive.
        vertex_count: usize,
    },
    /// A vertex attribute or animation value is NaN or infinite.
    #[error("{path}: {element}: non-finite value (NaN or Inf) at element {position}")]
    NonFinite {
        /// The glTF file.
        path: PathBuf,
        /// The mesh/primitive/accessor or animation/sampler/accessor.
        element: String,
        /// Index of the first bad element.
        position: usize,
    },
    /// A camera node references an orthographic camera.
    #[error("{path}: {element}: orthographic cameras are not supported yet")]
    OrthographicCamera {
        /// The glTF file.
        path: PathBuf,
        /// The camera.
        element: String,
    },
    /// `LoadOptions::camera_name` names no camera of the scene.
    #[error("{path}: no camera named {name:?}; available cameras: {available:?}")]
    CameraNotFound {
        /// The glTF file.
        path: PathBuf,
        /// The requested name.
        name: String,
        /// Names of the cameras in the scene (node name, else camera name, else `#index`).
        available: Vec<String>,
    },
    /// Any other invalid element (node hierarchy cycle, bad image, bad animation, ...).
    #[error("{path}: {element}: {reason}")]
    Invalid {
        /// The glTF file.
        path: PathBuf,
        /// The element at fault.
        element: String,
        /// What is wrong.
        reason: String,
    },
    /// Writing a glTF file (writer/assets) failed.
    #[error("{path}: cannot write")]
    Write {
        /// The file being written.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
}

/// What a [`Warning`] is about; lets callers and tests match warnings without parsing text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WarningKind {
    /// A primitive whose mode is not TRIANGLES was skipped.
    UnsupportedPrimitiveMode,
    /// Degenerate triangles (zero area or repeated index) were dropped; `count` says how many.
    DegenerateTriangles,
    /// A primitive had no (or unusable) normals; flat normals were generated.
    GeneratedNormals,
    /// A texture uses a texCoord set above 1, an unsupported image format or an unreadable or
    /// non-finite `KHR_texture_transform`, or sits in a slot radcache does not sample
    /// (KHR_materials_specular's textures: the factors are used), or a primitive lacks the
    /// texture coordinates or normals its material's textures need.
    TextureIgnored,
    /// Skins or morph targets are ignored (rest pose is used).
    SkinOrMorphIgnored,
    /// A morph-weights animation channel is ignored.
    WeightsChannelIgnored,
    /// The scene has no camera; a default camera frames the scene bounds.
    DefaultCamera,
    /// An animation targets a node given by a matrix; the matrix was decomposed to TRS.
    MatrixNodeAnimated,
    /// Two animation channels target the same node property; the later one wins.
    DuplicateChannel,
    /// Materials use an extension radcache does not implement (e.g. KHR_materials_transmission):
    /// they render with the core metallic-roughness model; `count` says how many materials.
    MaterialExtensionIgnored,
    /// The scene has no light source at all (no emitter, no punctual light, no environment):
    /// it renders black.
    NoLight,
    /// Anything else the loader worked around.
    Other,
}

/// A recoverable problem found while loading. Also emitted through `log::warn!`.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// Category of the warning.
    pub kind: WarningKind,
    /// How many items it concerns (e.g. dropped triangles); 1 for single events.
    pub count: usize,
    /// Human-readable message naming the file and element.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// Collects warnings during a load and forwards each to `log::warn!`.
#[derive(Debug, Default)]
pub(crate) struct Warnings {
    pub(crate) list: Vec<Warning>,
}

impl Warnings {
    /// Records a warning of `kind` concerning `count` items.
    pub(crate) fn push(&mut self, kind: WarningKind, count: usize, message: String) {
        log::warn!("{message}");
        self.list.push(Warning {
            kind,
            count,
            message,
        });
    }
}

/// Formats an element label such as `mesh 2 "floor"` (the name is omitted when absent).
pub(crate) fn label(kind: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) => format!("{kind} {index} {n:?}"),
        None => format!("{kind} {index}"),
    }
}
