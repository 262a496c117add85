//! Render metadata and its mapping to EXR header attributes.
//!
//! | field               | EXR attribute              | EXR type |
//! |---------------------|----------------------------|----------|
//! | `method`            | `radcache.method`          | string   |
//! | `spp`               | `radcache.spp`             | int      |
//! | `render_time_s`     | `radcache.renderTime`      | double (seconds) |
//! | `scene_file`        | `radcache.sceneFile`       | string   |
//! | `world_from_camera` | `radcache.worldFromCamera` | m44f     |
//! | `projection`        | `radcache.projection`      | m44f     |
//! | `radcache_version`  | `radcache.version`         | string (also `software` = `radcache <v>`) |
//! | `extra[key]`        | `radcache.extra.<key>`     | string   |
//!
//! Matrices are 16 floats in column-major order (glam's `Mat4::to_cols_array`) for column
//! vectors (`p_world = world_from_camera * p_camera`). Written verbatim into an `m44f`, whose
//! storage is Imath's row-major order for row vectors, this is exactly the same transform in
//! Imath's convention, so tools reading the attribute as an Imath matrix see the right thing.
//! Strings are stored as UTF-8 bytes. Attributes outside the `radcache.` namespace are ignored
//! on reading.

use std::collections::BTreeMap;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

const METHOD: &str = "radcache.method";
const SPP: &str = "radcache.spp";
const RENDER_TIME: &str = "radcache.renderTime";
const SCENE_FILE: &str = "radcache.sceneFile";
const WORLD_FROM_CAMERA: &str = "radcache.worldFromCamera";
const PROJECTION: &str = "radcache.projection";
const VERSION: &str = "radcache.version";
const EXTRA_PREFIX: &str = "radcache.extra.";
/// EXR attribute names are at most 255 bytes.
const MAX_EXTRA_KEY: usize = 255 - EXTRA_PREFIX.len();

/// The version of this crate, which is the radcache workspace version.
pub const RADCACHE_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Render metadata stored in EXR headers. All fields are optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Metadata {
    /// Rendering method (e.g. `"ircache"`, `"path"`).
    pub method: Option<String>,
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Render time in seconds.
    pub render_time_s: Option<f64>,
    /// Scene file the image was rendered from.
    pub scene_file: Option<String>,
    /// Camera-to-world transform, column-major (see the module docs).
    pub world_from_camera: Option<[f32; 16]>,
    /// Projection matrix, column-major.
    pub projection: Option<[f32; 16]>,
    /// radcache version that wrote the image.
    pub radcache_version: Option<String>,
    /// Free-form key/value pairs (keys: 1-240 bytes, no NUL).
    pub extra: BTreeMap<String, String>,
}

impl Metadata {
    /// Empty metadata with `radcache_version` set to [`RADCACHE_VERSION`].
    pub fn new() -> Self {
        Self {
            radcache_version: Some(RADCACHE_VERSION.to_owned()),
            ..Self::default()
        }
    }

    /// The EXR attributes for this metadata; `path` is only used in error messages.
    pub(crate) fn to_attributes(&self, path: &Path) -> Result<Vec<(Text, AttributeValue)>> {
        let mut out = Vec::new();
        let mut push_text = |name: &str, value: &str| {
            out.push((text(name), AttributeValue::Text(text(value))));
        };
        if let Some(method) = &self.method {
            push_text(METHOD, method);
        }
        if let Some(scene) = &self.scene_file {
            push_text(SCENE_FILE, scene);
        }
        if let Some(version) = &self.radcache_version {
            push_text(VERSION, version);
        }
        for (key, value) in &self.extra {
            if key.is_empty() || key.len() > MAX_EXTRA_KEY || key.contains('\0') {
                return Err(Error::Metadata {
                    path: path.to_owned(),
                    message: format!(
                        "extra key '{key}' must be 1-{MAX_EXTRA_KEY} bytes without NUL"
                    ),
                });
            }
            push_text(&format!("{EXTRA_PREFIX}{key}"), value);
        }
        if let Some(spp) = self.spp {
            let spp = i32::try_from(spp).map_err(|_| Error::Metadata {
                path: path.to_owned(),
                message: format!("spp {spp} does not fit an EXR int attribute"),
            })?;
            out.push((text(SPP), AttributeValue::I32(spp)));
        }
        if let Some(time) = self.render_time_s {
            out.push((text(RENDER_TIME), AttributeValue::F64(time)));
        }
        if let Some(m) = self.world_from_camera {
            out.push((text(WORLD_FROM_CAMERA), AttributeValue::Matrix4x4(m)));
        }
        if let Some(m) = self.projection {
            out.push((text(PROJECTION), AttributeValue::Matrix4x4(m)));
        }
        Ok(out)
    }

    /// Collects metadata from EXR attributes; a known attribute with an unexpected type is an
    /// error naming `path`.
    pub(crate) fn from_attributes<'a>(
        attributes: impl IntoIterator<Item = (&'a Text, &'a AttributeValue)>,
        path: &Path,
    ) -> Result<Self> {
        let mut meta = Self::default();
        for (name, value) in attributes {
            let name = string(name);
            let Some(key) = name.strip_prefix("radcache.") else {
                continue;
            };
            let wrong_type = || Error::ExrContent {
                path: path.to_owned(),
                message: format!("attribute '{name}' has an unexpected type"),
            };
            match (name.as_str(), value) {
                (METHOD, AttributeValue::Text(t)) => meta.method = Some(string(t)),
                (SCENE_FILE, AttributeValue::Text(t)) => meta.scene_file = Some(string(t)),
                (VERSION, AttributeValue::Text(t)) => meta.radcache_version = Some(string(t)),
                (SPP, AttributeValue::I32(n)) => {
                    meta.spp = Some(u32::try_from(*n).map_err(|_| wrong_type())?);
                }
                (RENDER_TIME, AttributeValue::F64(t)) => meta.render_time_s = Some(*t),
                (RENDER_TIME, AttributeValue::F32(t)) => meta.render_time_s = Some(f64::from(*t)),
                (WORLD_FROM_CAMERA, AttributeValue::Matrix4x4(m)) => {
                    meta.world_from_camera = Some(*m);
                }
                (PROJECTION, AttributeValue::Matrix4x4(m)) => meta.projection = Some(*m),
                (METHOD | SCENE_FILE | VERSION | SPP | RENDER_TIME, _)
                | (WORLD_FROM_CAMERA | PROJECTION, _) => return Err(wrong_type()),
                (_, value) => match (key.strip_prefix("extra."), value) {
                    (Some(extra), AttributeValue::Text(t)) => {
                        meta.extra.insert(extra.to_owned(), string(t));
                    }
                    (Some(_), _) => return Err(wrong_type()),
                    (None, _) => log::debug!("{}: ignoring attribute '{name}'", path.display()),
                },
            }
        }
        Ok(meta)
    }
}

/// UTF-8 bytes as an EXR text (the `exr` crate's `From<&str>` panics on non-Latin-1 input).
pub(crate) fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

/// EXR text as a string; invalid UTF-8 is replaced, never an error.
pub(crate) fn string(t: &Text) -> String {
    String::from_utf8_lossy(t.as_slice()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attributes_round_trip() {
        let mut meta = Metadata::new();
        meta.method = Some("ircache".into());
        meta.spp = Some(64);
        meta.render_time_s = Some(1.25);
        meta.scene_file = Some("scènes/cornell.gltf".into());
        meta.world_from_camera = Some(std::array::from_fn(|i| i as f32));
        meta.projection = Some(std::array::from_fn(|i| -(i as f32)));
        meta.extra.insert("seed".into(), "7".into());
        let path = Path::new("x.exr");
        let attributes = meta.to_attributes(path).unwrap();
        let back = Metadata::from_attributes(attributes.iter().map(|(n, v)| (n, v)), path);
        assert_eq!(back.unwrap(), meta);
    }

    #[test]
    fn bad_extra_key_and_wrong_type_are_errors() {
        let path = Path::new("x.exr");
        let mut meta = Metadata::default();
        meta.extra.insert(String::new(), "v".into());
        assert!(meta.to_attributes(path).is_err());
        let attributes = [(text(SPP), AttributeValue::Text(text("many")))];
        let err = Metadata::from_attributes(attributes.iter().map(|(n, v)| (n, v)), path);
        assert!(err.unwrap_err().to_string().contains("x.exr"));
    }
}
