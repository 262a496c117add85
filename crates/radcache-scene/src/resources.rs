//! Reading a glTF file and its external resources (buffers, images) without panicking.
//!
//! The gltf crate's `import` is not used: it indexes buffers with unchecked slices and unwraps
//! percent-decoding, so a hostile file could panic it. Instead the JSON (or GLB) is parsed and
//! validated by the gltf crate, then each buffer is resolved here (data URI, relative path, or the
//! GLB `BIN` chunk) and checked against its `byteLength`. Images are decoded by the gltf crate only
//! after their source has been checked.

use std::path::{Path, PathBuf};

use base64::alphabet::STANDARD;
use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
use base64::Engine as _;

use crate::error::{label, Error, Result};
use crate::meshopt;

/// Standard base64 (RFC 4648, `+/` alphabet) for data URIs: padding optional, no whitespace.
const BASE64: GeneralPurpose = GeneralPurpose::new(
    &STANDARD,
    GeneralPurposeConfig::new()
        .with_decode_padding_mode(DecodePaddingMode::Indifferent)
        .with_decode_allow_trailing_bits(true),
);

/// A parsed and validated glTF document with its buffers loaded.
#[derive(Debug)]
pub(crate) struct Source {
    /// The glTF file (used in every error message).
    pub(crate) path: PathBuf,
    /// Directory that relative URIs resolve against.
    pub(crate) base: PathBuf,
    /// The validated document.
    pub(crate) doc: gltf::Document,
    /// Buffer contents, index-aligned with `doc.buffers()`; each is at least `byteLength` long,
    /// except a placeholder (an `EXT_meshopt_compression` fallback), which is empty.
    pub(crate) buffers: Vec<gltf::buffer::Data>,
    /// Per buffer view (index-aligned with `doc.views()`): its bytes decoded, where it is
    /// `EXT_meshopt_compression` compressed; accessors read these instead of the buffer.
    pub(crate) decoded_views: Vec<Option<Vec<u8>>>,
    /// Per material (index-aligned with `doc.materials()`): what the raw JSON says that the gltf
    /// crate does not give (see [`RawMaterial`]).
    pub(crate) raw_materials: Vec<RawMaterial>,
    /// Per node (index-aligned with `doc.nodes()`): the accessors of its
    /// `EXT_mesh_gpu_instancing` attributes, where it has the extension (the gltf crate does not
    /// read it).
    pub(crate) raw_instancing: Vec<Option<RawInstancing>>,
}

/// A node's `EXT_mesh_gpu_instancing` attributes: accessor indices of the instances'
/// translations, rotations and scales (each optional; other attributes are not read).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub(crate) struct RawInstancing {
    pub(crate) translation: Option<usize>,
    pub(crate) rotation: Option<usize>,
    pub(crate) scale: Option<usize>,
}

/// What a material's raw JSON holds beyond the gltf crate's view of it.
#[derive(Debug, Default)]
pub(crate) struct RawMaterial {
    /// The names of the extensions the material uses, on itself or on its texture references
    /// (the gltf crate drops extensions it does not know).
    pub(crate) extensions: Vec<String>,
    /// The `KHR_texture_transform` object of its `normalTexture` (the gltf crate reads that
    /// extension on `textureInfo` only).
    pub(crate) normal_texture_transform: Option<serde_json::Value>,
}

impl Source {
    /// Reads, parses and validates `path`, then loads all buffers.
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let parse_err = |e: gltf::Error| Error::Parse {
            path: path.to_path_buf(),
            message: describe_gltf_error(&e),
        };
        check_glb_header(&bytes).map_err(|message| Error::Parse {
            path: path.to_path_buf(),
            message,
        })?;
        let gltf::Gltf { document, blob } =
            gltf::Gltf::from_slice_without_validation(&bytes).map_err(parse_err)?;
        let mut root = document.into_json();
        check_version(path, &root.asset)?;
        for name in &root.extensions_required {
            if !SUPPORTED_REQUIRED.contains(&name.as_str()) {
                return Err(Error::UnsupportedExtension {
                    path: path.to_path_buf(),
                    name: name.clone(),
                    reason: unsupported_reason(name).into(),
                });
            }
        }
        // Checked above. The gltf crate's own check would refuse KHR_materials_specular, which
        // gltf-json 1.4 parses but leaves out of its list of enabled extensions.
        root.extensions_required.clear();
        precheck(path, &root)?;
        let doc = gltf::Document::from_json(root).map_err(parse_err)?;
        let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let raw = raw_json(&bytes);
        let compressed = compressed_views(path, &raw, doc.views().len())?;
        let mut source = Source {
            path: path.to_path_buf(),
            base,
            raw_materials: raw_materials(&raw, doc.materials().len()),
            raw_instancing: raw_instancing(path, &raw, doc.nodes().len())?,
            doc,
            buffers: Vec::new(),
            decoded_views: Vec::new(),
        };
        let placeholders = placeholder_buffers(&raw, &source.doc, &compressed, blob.is_some());
        source.buffers = source.load_buffers(blob, &placeholders)?;
        source.decoded_views = source.decompress(&compressed, &placeholders)?;
        Ok(source)
    }

    /// Each buffer's data; a placeholder buffer (see [`placeholder_buffers`]) is left empty (its
    /// views are decoded by [`Source::decompress`]).
    fn load_buffers(
        &self,
        mut blob: Option<Vec<u8>>,
        placeholders: &[bool],
    ) -> Result<Vec<gltf::buffer::Data>> {
        let mut out = Vec::new();
        for buffer in self.doc.buffers() {
            if placeholders[buffer.index()] {
                out.push(gltf::buffer::Data(Vec::new()));
                continue;
            }
            let element = label("buffer", buffer.index(), buffer.name());
            let (uri, data) = match buffer.source() {
                gltf::buffer::Source::Bin => ("<GLB BIN chunk>".to_string(), blob.take()),
                gltf::buffer::Source::Uri(uri) => {
                    let data = self.read_uri(uri).map_err(|reason| Error::MissingBuffer {
                        path: self.path.clone(),
                        element: element.clone(),
                        uri: short_uri(uri),
                        reason,
                    })?;
                    (short_uri(uri), Some(data))
                }
            };
            let data = data.ok_or_else(|| Error::MissingBuffer {
                path: self.path.clone(),
                element: element.clone(),
                uri,
                reason: "no GLB BIN chunk (or it is used by an earlier buffer)".into(),
            })?;
            if data.len() < buffer.length() {
                return Err(Error::ShortBuffer {
                    path: self.path.clone(),
                    element,
                    expected: buffer.length(),
                    actual: data.len(),
                });
            }
            out.push(gltf::buffer::Data(data));
        }
        Ok(out)
    }

    /// Decodes every `EXT_meshopt_compression` buffer view into the bytes its view describes
    /// (index-aligned with `doc.views()`; `None` for a view that is not compressed). A view in a
    /// placeholder buffer must be compressed, and compressed data must not come from one.
    fn decompress(
        &self,
        compressed: &[Option<CompressedView>],
        placeholders: &[bool],
    ) -> Result<Vec<Option<Vec<u8>>>> {
        let invalid = |view: &gltf::buffer::View<'_>, reason: String| Error::Invalid {
            path: self.path.clone(),
            element: label("buffer view", view.index(), view.name()),
            reason,
        };
        self.doc
            .views()
            .map(|view| {
                let buffer = view.buffer().index();
                let Some(c) = compressed[view.index()] else {
                    if placeholders[buffer] {
                        return Err(invalid(
                            &view,
                            format!(
                                "lies in buffer {buffer}, which has no data of its own (an \
                                 EXT_meshopt_compression fallback), but is not compressed"
                            ),
                        ));
                    }
                    return Ok(None);
                };
                let err =
                    |reason: String| invalid(&view, format!("EXT_meshopt_compression: {reason}"));
                if placeholders.get(c.buffer).copied().unwrap_or(false) {
                    return Err(err(format!(
                        "its compressed data is in buffer {}, a fallback buffer",
                        c.buffer
                    )));
                }
                let source = self
                    .buffers
                    .get(c.buffer)
                    .ok_or_else(|| err(format!("buffer {} does not exist", c.buffer)))?;
                let end = c.offset.checked_add(c.length);
                let bytes = end
                    .and_then(|end| source.0.get(c.offset..end))
                    .ok_or_else(|| {
                        err(format!(
                            "compressed data (offset {}, length {}) exceeds buffer {} ({} bytes)",
                            c.offset,
                            c.length,
                            c.buffer,
                            source.0.len()
                        ))
                    })?;
                let decoded = meshopt::decode(c.mode, c.filter, c.count, c.stride, bytes);
                Ok(Some(decoded.map_err(err)?))
            })
            .collect()
    }

    /// Reads a buffer URI: `data:...;base64,...` or a relative (percent-encoded) file path.
    fn read_uri(&self, uri: &str) -> std::result::Result<Vec<u8>, String> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let (_, payload) = rest
                .split_once(";base64,")
                .ok_or_else(|| "data URI is not base64-encoded".to_string())?;
            return BASE64
                .decode(payload)
                .map_err(|e| format!("bad base64 data: {e}"));
        }
        let rel = relative_path(uri)?;
        let file = self.base.join(rel);
        std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))
    }

    /// Decodes image `index` to pixels, checking its source first.
    pub(crate) fn decode_image(&self, image: &gltf::Image<'_>) -> Result<gltf::image::Data> {
        let element = label("image", image.index(), image.name());
        let invalid = |reason: String| Error::Invalid {
            path: self.path.clone(),
            element: element.clone(),
            reason,
        };
        // `Image::source` unwraps these two; check them on the JSON first.
        let json = self.doc.as_json().images.get(image.index());
        match json {
            Some(j) if j.buffer_view.is_some() && j.mime_type.is_none() => {
                return Err(invalid("an image in a buffer view needs a mimeType".into()));
            }
            Some(j) if j.buffer_view.is_none() && j.uri.is_none() => {
                return Err(invalid("image has neither uri nor bufferView".into()));
            }
            Some(_) => {}
            None => return Err(invalid("image does not exist".into())),
        }
        // The file an external image is read from, for messages.
        let mut file = None;
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                if self
                    .decoded_views
                    .get(view.index())
                    .is_some_and(Option::is_some)
                {
                    return Err(invalid(format!(
                        "an image in a meshopt-compressed buffer view ({}) is not read (the \
                         extension compresses geometry and animation; encoders leave images as \
                         they are)",
                        view.index()
                    )));
                }
                let len = self
                    .buffers
                    .get(view.buffer().index())
                    .map_or(0, |b| b.0.len());
                let end = view.offset().checked_add(view.length());
                if end.is_none_or(|end| end > len) {
                    return Err(invalid(format!(
                        "buffer view {} (offset {}, length {}) exceeds buffer {} ({len} bytes)",
                        view.index(),
                        view.offset(),
                        view.length(),
                        view.buffer().index()
                    )));
                }
            }
            gltf::image::Source::Uri { uri, .. } => {
                if !uri.starts_with("data:") {
                    file = Some(self.base.join(relative_path(uri).map_err(invalid)?));
                }
            }
        }
        gltf::image::Data::from_source(image.source(), Some(&self.base), &self.buffers).map_err(
            |e| match (&file, e) {
                (Some(file), gltf::Error::Io(io)) => {
                    invalid(format!("cannot read image file {}: {io}", file.display()))
                }
                (Some(file), e) => invalid(format!(
                    "cannot decode image file {}: {}",
                    file.display(),
                    describe_gltf_error(&e)
                )),
                (None, e) => invalid(format!("cannot decode: {}", describe_gltf_error(&e))),
            },
        )
    }

    /// The glTF file path as an owned value (for error construction).
    pub(crate) fn path(&self) -> PathBuf {
        self.path.clone()
    }
}

/// Refuses files that are not glTF 2.x (`asset.version`) or that need more than glTF 2.0
/// (`asset.minVersion`); both have the form `<major>.<minor>`.
fn check_version(path: &Path, asset: &gltf::json::Asset) -> Result<()> {
    fn parse(v: &str) -> Option<(u32, u32)> {
        let (major, minor) = v.split_once('.')?;
        // Digits only (`str::parse` would also take a sign); empty fails to parse.
        let number = |s: &str| {
            s.bytes()
                .all(|b| b.is_ascii_digit())
                .then(|| s.parse().ok())?
        };
        Some((number(major)?, number(minor)?))
    }
    let refuse = |field, version: &str, reason| Error::UnsupportedVersion {
        path: path.to_path_buf(),
        field,
        version: version.to_string(),
        reason,
    };
    const FORM: &str = "expected <major>.<minor>, e.g. \"2.0\"";
    match parse(&asset.version) {
        Some((2, _)) => {}
        Some(_) => {
            return Err(refuse(
                "version",
                &asset.version,
                "this loader reads glTF 2.x",
            ))
        }
        None => return Err(refuse("version", &asset.version, FORM)),
    }
    match asset.min_version.as_deref().map(|v| (v, parse(v))) {
        None | Some((_, Some((2, 0)))) => Ok(()),
        Some((v, Some(_))) => Err(refuse("minVersion", v, "this loader implements glTF 2.0")),
        Some((v, None)) => Err(refuse("minVersion", v, FORM)),
    }
}

/// Checks what the gltf crate's validation indexes without bounds checks (gltf-json 1.4's
/// primitive hook reads `accessors[POSITION]` directly and would panic on a bad index).
fn precheck(path: &Path, root: &gltf::json::Root) -> Result<()> {
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::Checked;
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            if let Some(index) = prim.attributes.get(&Checked::Valid(Semantic::Positions)) {
                if index.value() >= root.accessors.len() {
                    let element = label("mesh", mi, mesh.name.as_deref());
                    return Err(Error::Parse {
                        path: path.to_path_buf(),
                        message: format!(
                            "{element} primitive {pi}: POSITION accessor {} does not exist ({} accessors)",
                            index.value(),
                            root.accessors.len()
                        ),
                    });
                }
            }
        }
    }
    Ok(())
}

/// Checks a GLB header's declared length before the gltf crate reads it (gltf 1.4 subtracts the
/// 12-byte header size from it unchecked, which overflows for a length below 12). Files that do
/// not start with the `glTF` magic are JSON and pass.
fn check_glb_header(bytes: &[u8]) -> std::result::Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(len) = bytes.get(8..12) else {
        return Err("GLB header is truncated".into());
    };
    let declared = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
    if declared < 12 || declared > bytes.len() {
        return Err(format!(
            "GLB header declares {declared} bytes but the file has {} (and the header alone is 12)",
            bytes.len()
        ));
    }
    Ok(())
}

/// Required extensions this loader implements.
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    // Integer attributes (normalized or not) are read by `accessor.rs` like any other; the
    // dequantization is the node's transform and `KHR_texture_transform`.
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "EXT_mesh_gpu_instancing",
    // Each compressed view decoded on load by `meshopt.rs`; its fallback buffer is not loaded.
    "EXT_meshopt_compression",
];

/// Why a required extension cannot be honoured, for the error message.
fn unsupported_reason(name: &str) -> &'static str {
    match name {
        "KHR_draco_mesh_compression" => "Draco-compressed meshes cannot be decoded",
        "KHR_meshopt_compression" => {
            "its vertex codec 1 is not decoded (EXT_meshopt_compression is: gltfpack -ce ext)"
        }
        "KHR_texture_basisu" => "KTX2 / Basis Universal textures cannot be decoded",
        "EXT_texture_webp" => "WebP textures cannot be decoded",
        "EXT_texture_avif" => "AVIF textures cannot be decoded",
        "MSFT_texture_dds" => "DDS textures cannot be decoded",
        _ => "the file declares that it cannot be displayed without it",
    }
}

/// Texture references of a material object, by JSON path.
const TEXTURE_SLOTS: &[&[&str]] = &[
    &["pbrMetallicRoughness", "baseColorTexture"],
    &["pbrMetallicRoughness", "metallicRoughnessTexture"],
    &["normalTexture"],
    &["occlusionTexture"],
    &["emissiveTexture"],
];

/// The JSON of the text file or of the GLB JSON chunk in `bytes` (`Null` where it does not
/// parse: the gltf crate has parsed it already).
fn raw_json(bytes: &[u8]) -> serde_json::Value {
    let json = if bytes.starts_with(b"glTF") {
        gltf::Glb::from_slice(bytes).ok().map(|glb| glb.json)
    } else {
        Some(std::borrow::Cow::Borrowed(bytes))
    };
    json.and_then(|j| serde_json::from_slice(&j).ok())
        .unwrap_or_default()
}

/// Element `i` of the top-level list `list` of `root`, with its extension object `name`, where it
/// has one.
fn extension_of<'a>(
    root: &'a serde_json::Value,
    list: &str,
    i: usize,
    name: &str,
) -> Option<(&'a serde_json::Value, &'a serde_json::Value)> {
    let element = root.get(list)?.get(i)?;
    Some((element, element.get("extensions")?.get(name)?))
}

/// A buffer view's `EXT_meshopt_compression` object: where its compressed bytes are and how
/// they are coded.
#[derive(Debug, Clone, Copy)]
struct CompressedView {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: meshopt::Mode,
    filter: meshopt::Filter,
}

/// The [`CompressedView`] of each of the first `count` buffer views of `root`, checked against the
/// extension's rules (stride, count and filter for the mode; `count · byteStride` equal to the
/// view's length; a length the compressed bytes can hold); any fault is an error naming the view.
fn compressed_views(
    path: &Path,
    root: &serde_json::Value,
    count: usize,
) -> Result<Vec<Option<CompressedView>>> {
    (0..count)
        .map(|i| {
            let Some((view, ext)) = extension_of(root, "bufferViews", i, "EXT_meshopt_compression")
            else {
                return Ok(None);
            };
            let name = view.get("name").and_then(|n| n.as_str());
            let err = |reason: String| Error::Invalid {
                path: path.to_path_buf(),
                element: label("buffer view", i, name),
                reason: format!("EXT_meshopt_compression: {reason}"),
            };
            let int = |v: Option<&serde_json::Value>, key: &str| -> Result<usize> {
                v.and_then(|v| v.get(key))
                    .and_then(|v| v.as_u64())
                    .and_then(|v| usize::try_from(v).ok())
                    .ok_or_else(|| err(format!("{key} is missing or not a non-negative integer")))
            };
            let text = |key: &str, default: &'static str| -> Result<String> {
                match ext.get(key) {
                    None => Ok(default.to_string()),
                    Some(v) => v
                        .as_str()
                        .map(str::to_string)
                        .ok_or_else(|| err(format!("{key} is {v}, not a string"))),
                }
            };
            let mode_name = text("mode", "")?;
            let mode = meshopt::Mode::parse(&mode_name).ok_or_else(|| {
                err(format!(
                    "mode \"{mode_name}\" is not ATTRIBUTES, TRIANGLES or INDICES"
                ))
            })?;
            let filter_name = text("filter", "NONE")?;
            let filter = meshopt::Filter::parse(&filter_name).ok_or_else(|| {
                err(format!(
                    "filter \"{filter_name}\" is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL"
                ))
            })?;
            let c = CompressedView {
                buffer: int(Some(ext), "buffer")?,
                offset: if ext.get("byteOffset").is_some() {
                    int(Some(ext), "byteOffset")?
                } else {
                    0
                },
                length: int(Some(ext), "byteLength")?,
                stride: int(Some(ext), "byteStride")?,
                count: int(Some(ext), "count")?,
                mode,
                filter,
            };
            meshopt::check_layout(mode, filter, c.count, c.stride).map_err(err)?;
            if let Some(parent) = view.get("byteStride") {
                if parent.as_u64() != Some(c.stride as u64) {
                    return Err(err(format!(
                        "byteStride {} differs from the view's {parent}",
                        c.stride
                    )));
                }
            }
            let decoded = c.count.checked_mul(c.stride);
            let parent = int(Some(view), "byteLength")?;
            if decoded != Some(parent) {
                return Err(err(format!(
                    "count {} × byteStride {} is not the view's byteLength {parent}",
                    c.count, c.stride
                )));
            }
            if parent > meshopt::max_decoded_len(mode, c.length) {
                return Err(err(format!(
                    "{parent} bytes cannot be coded in {} compressed bytes",
                    c.length
                )));
            }
            Ok(Some(c))
        })
        .collect()
}

/// Which buffers have no data to load: those tagged `EXT_meshopt_compression.fallback`, and those
/// without a URI (and not the GLB BIN chunk) that compressed views decode into. The extension lets
/// a loader that decodes skip a tagged fallback even where it has a URI.
fn placeholder_buffers(
    root: &serde_json::Value,
    doc: &gltf::Document,
    compressed: &[Option<CompressedView>],
    has_blob: bool,
) -> Vec<bool> {
    let mut targets = vec![false; doc.buffers().len()];
    for view in doc.views() {
        if compressed.get(view.index()).is_some_and(Option::is_some) {
            targets[view.buffer().index()] = true;
        }
    }
    // The first buffer without a URI is the GLB BIN chunk, where there is one.
    let mut blob = has_blob;
    doc.buffers()
        .map(|b| {
            let tagged = extension_of(root, "buffers", b.index(), "EXT_meshopt_compression")
                .and_then(|(_, e)| e.get("fallback"))
                .and_then(|f| f.as_bool())
                .unwrap_or(false);
            let uri_less = matches!(b.source(), gltf::buffer::Source::Bin);
            let is_blob = uri_less && std::mem::take(&mut blob);
            tagged || (uri_less && !is_blob && targets[b.index()])
        })
        .collect()
}

/// The [`RawInstancing`] of each of the first `count` nodes of `root`; an attribute that is not
/// an accessor index is an error naming the node.
fn raw_instancing(
    path: &Path,
    root: &serde_json::Value,
    count: usize,
) -> Result<Vec<Option<RawInstancing>>> {
    (0..count)
        .map(|i| {
            let Some((node, ext)) = extension_of(root, "nodes", i, "EXT_mesh_gpu_instancing")
            else {
                return Ok(None);
            };
            let name = node.get("name").and_then(|n| n.as_str());
            let attributes = ext.get("attributes");
            let index = |key: &str| -> Result<Option<usize>> {
                match attributes.and_then(|a| a.get(key)) {
                    None => Ok(None),
                    Some(v) => match v.as_u64() {
                        Some(a) => Ok(Some(a as usize)),
                        None => Err(Error::Invalid {
                            path: path.to_path_buf(),
                            element: label("node", i, name),
                            reason: format!(
                                "EXT_mesh_gpu_instancing attribute {key} is {v}, not an accessor \
                                 index"
                            ),
                        }),
                    },
                }
            };
            Ok(Some(RawInstancing {
                translation: index("TRANSLATION")?,
                rotation: index("ROTATION")?,
                scale: index("SCALE")?,
            }))
        })
        .collect()
}

/// The [`RawMaterial`] of each of the first `count` materials of `root`.
fn raw_materials(root: &serde_json::Value, count: usize) -> Vec<RawMaterial> {
    let keys = |v: Option<&serde_json::Value>| -> Vec<String> {
        v.and_then(|v| v.get("extensions"))
            .and_then(|e| e.as_object())
            .map(|e| e.keys().cloned().collect())
            .unwrap_or_default()
    };
    (0..count)
        .map(|i| {
            let m = root.get("materials").and_then(|list| list.get(i));
            let mut names = keys(m);
            for slot in TEXTURE_SLOTS {
                let info = slot.iter().fold(m, |v, key| v.and_then(|v| v.get(key)));
                names.extend(keys(info));
            }
            names.sort();
            names.dedup();
            let normal_texture_transform = m
                .and_then(|m| m.get("normalTexture"))
                .and_then(|t| t.get("extensions"))
                .and_then(|e| e.get("KHR_texture_transform"))
                .cloned();
            RawMaterial {
                extensions: names,
                normal_texture_transform,
            }
        })
        .collect()
}

/// Turns a relative, percent-encoded URI into a path; rejects other URI schemes.
fn relative_path(uri: &str) -> std::result::Result<PathBuf, String> {
    if uri.contains(':') {
        return Err("only data: and relative URIs are supported".into());
    }
    let bytes = percent_decode(uri);
    let s = String::from_utf8(bytes).map_err(|_| "URI is not valid UTF-8".to_string())?;
    Ok(PathBuf::from(s))
}

/// Decodes `%XX` escapes; malformed escapes are kept literally.
fn percent_decode(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    out
}

/// Shortens data URIs for messages.
fn short_uri(uri: &str) -> String {
    if uri.len() > 64 {
        let cut = (0..=48)
            .rev()
            .find(|&i| uri.is_char_boundary(i))
            .unwrap_or(0);
        format!("{}...", &uri[..cut])
    } else {
        uri.to_string()
    }
}

/// A readable message for a gltf crate error (validation errors list each JSON path).
pub(crate) fn describe_gltf_error(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Validation(list) => {
            let items: Vec<String> = list
                .iter()
                .take(8)
                .map(|(p, err)| format!("{p}: {err}"))
                .collect();
            let more = list.len().saturating_sub(8);
            let suffix = if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            };
            format!("validation failed: {}{suffix}", items.join("; "))
        }
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin"), b"a b.bin");
        assert_eq!(percent_decode("100%"), b"100%");
        assert_eq!(percent_decode("%zz%4"), b"%zz%4");
        assert!(relative_path("%FF").is_err());
        assert!(relative_path("http://x/y.bin").is_err());
    }

    #[test]
    fn data_uri_base64() {
        use base64::engine::general_purpose::STANDARD as ENCODE;
        for len in 0..20 {
            let data: Vec<u8> = (0..len).map(|i| (i * 37 + 11) as u8).collect();
            let text = ENCODE.encode(&data);
            assert_eq!(BASE64.decode(&text).unwrap(), data);
            assert_eq!(BASE64.decode(text.trim_end_matches('=')).unwrap(), data);
        }
        assert_eq!(ENCODE.encode(b"Ma"), "TWE=");
        assert!(BASE64.decode("T").is_err());
        assert!(BASE64.decode("TW E").is_err());
        assert!(BASE64.decode("TW\nE").is_err());
    }
}
