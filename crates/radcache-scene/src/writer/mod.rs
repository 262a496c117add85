//! A small builder that writes valid glTF 2.0 (checked with the Khronos validator).
//!
//! Add materials, meshes, cameras, punctual lights, nodes, animations, textures and scenes (each
//! `add_*` returns the glTF index), then [`GltfBuilder::write`] a `.gltf` with either an external
//! `.bin` next to it or an embedded base64 data URI ([`BufferLayout`]). Every accessor gets its own
//! 4-byte-aligned buffer view; float accessors carry `min`/`max`. Emission is given as radiance and
//! split into `emissiveFactor` × `KHR_materials_emissive_strength` when it exceeds 1; a specular
//! factor other than 1 (0 for the Lambertian [`MaterialDesc::diffuse`]) is written as
//! `KHR_materials_specular`, an ior as `KHR_materials_ior`, a texture reference's transform as
//! `KHR_texture_transform` ([`TexCoordDesc`]). The JSON is
//! written with serde_json; [`GltfBuilder::to_json`] exposes it so tests can mutate it.

mod desc;
mod png;

use std::collections::BTreeSet;
use std::path::Path;

use base64::Engine as _;
use serde_json::{json, Map, Value};

use crate::animation::{Interpolation, Property};
use crate::error::{Error, Result};
use crate::light::LightKind;

pub use desc::{
    ChannelDesc, IndexFormat, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc, TexCoordDesc,
};

/// Where the binary buffer goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BufferLayout {
    /// `<stem>.bin` next to the `.gltf`.
    External,
    /// A `data:application/octet-stream;base64,` URI inside the JSON.
    Embedded,
}

/// Builds a glTF document; see the module docs.
#[derive(Clone, Debug, Default)]
pub struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    materials: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    cameras: Vec<Value>,
    lights: Vec<Value>,
    animations: Vec<Value>,
    scenes: Vec<Value>,
    images: Vec<Value>,
    textures: Vec<Value>,
    samplers: Vec<Value>,
    extensions_used: BTreeSet<String>,
}

/// A JSON number from an f32, written in its shortest round-tripping decimal form.
fn num(x: f32) -> Value {
    let shortest: f64 = format!("{x}").parse().unwrap_or(f64::from(x));
    serde_json::Number::from_f64(shortest).map_or(Value::Null, Value::Number)
}

fn nums(xs: &[f32]) -> Value {
    Value::Array(xs.iter().map(|&x| num(x)).collect())
}

fn push(list: &mut Vec<Value>, v: Value) -> usize {
    list.push(v);
    list.len() - 1
}

impl GltfBuilder {
    /// An empty document.
    pub fn new() -> GltfBuilder {
        GltfBuilder::default()
    }

    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        push(&mut self.views, v)
    }

    /// Adds a float accessor of `comps` components (with min/max); returns its index.
    pub fn add_float_accessor(&mut self, data: &[f32], comps: usize, target: Option<u32>) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let count = data.len() / comps.max(1);
        let mut min = vec![f32::INFINITY; comps];
        let mut max = vec![f32::NEG_INFINITY; comps];
        for e in data.chunks_exact(comps) {
            for c in 0..comps {
                min[c] = min[c].min(e[c]);
                max[c] = max[c].max(e[c]);
            }
        }
        let ty = ["SCALAR", "VEC2", "VEC3", "VEC4"][comps.clamp(1, 4) - 1];
        let mut a = json!({"bufferView": view, "componentType": 5126, "count": count, "type": ty});
        if count > 0 && min.iter().chain(&max).all(|x| x.is_finite()) {
            a["min"] = nums(&min);
            a["max"] = nums(&max);
        }
        push(&mut self.accessors, a)
    }

    fn add_index_accessor(&mut self, indices: &[u32], format: IndexFormat) -> usize {
        let max = indices.iter().copied().max().unwrap_or(0);
        let format = match format {
            IndexFormat::Auto if max < 65_535 => IndexFormat::U16,
            IndexFormat::Auto => IndexFormat::U32,
            f => f,
        };
        let (bytes, ct): (Vec<u8>, u32) = match format {
            IndexFormat::U8 => (indices.iter().map(|&i| i as u8).collect(), 5121),
            IndexFormat::U16 => (
                indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect(),
                5123,
            ),
            _ => (
                indices.iter().flat_map(|&i| i.to_le_bytes()).collect(),
                5125,
            ),
        };
        let view = self.view(&bytes, Some(34963));
        push(
            &mut self.accessors,
            json!({"bufferView": view, "componentType": ct, "count": indices.len(), "type": "SCALAR"}),
        )
    }

    /// A textureInfo of texture `index` mapped by `uv` (`texCoord`, `KHR_texture_transform`).
    fn texture_info(&mut self, index: usize, uv: &TexCoordDesc) -> Value {
        let mut info = json!({"index": index});
        if uv.tex_coord != 0 {
            info["texCoord"] = json!(uv.tex_coord);
        }
        if uv.transform.is_some() || uv.transform_tex_coord.is_some() {
            let t = uv.transform.unwrap_or_default();
            let mut ext = json!({
                "offset": nums(&t.offset.to_array()),
                "rotation": num(t.rotation),
                "scale": nums(&t.scale.to_array()),
            });
            if let Some(set) = uv.transform_tex_coord {
                ext["texCoord"] = json!(set);
            }
            info["extensions"] = json!({ "KHR_texture_transform": ext });
            self.extensions_used.insert("KHR_texture_transform".into());
        }
        info
    }

    /// Adds a material; returns its index.
    pub fn add_material(&mut self, m: &MaterialDesc) -> usize {
        let mut pbr = json!({"baseColorFactor": nums(&m.base_color), "metallicFactor": num(m.metallic), "roughnessFactor": num(m.roughness)});
        if let Some(t) = m.base_color_texture {
            pbr["baseColorTexture"] = self.texture_info(t, &m.base_color_uv);
        }
        if let Some(t) = m.metallic_roughness_texture {
            pbr["metallicRoughnessTexture"] = self.texture_info(t, &m.metallic_roughness_uv);
        }
        let mut v = json!({"name": m.name, "pbrMetallicRoughness": pbr});
        let mut extensions = Map::new();
        let peak = m.emissive.iter().copied().fold(0.0f32, f32::max);
        if peak > 0.0 {
            let strength = peak.max(1.0);
            v["emissiveFactor"] = nums(&m.emissive.map(|e| e / strength));
            if strength > 1.0 {
                extensions.insert(
                    "KHR_materials_emissive_strength".into(),
                    json!({"emissiveStrength": num(strength)}),
                );
            }
        }
        if m.specular != 1.0 {
            extensions.insert(
                "KHR_materials_specular".into(),
                json!({"specularFactor": num(m.specular)}),
            );
        }
        if let Some(ior) = m.ior {
            extensions.insert("KHR_materials_ior".into(), json!({"ior": num(ior)}));
        }
        if !extensions.is_empty() {
            self.extensions_used.extend(extensions.keys().cloned());
            v["extensions"] = Value::Object(extensions);
        }
        if let Some(t) = m.emissive_texture {
            v["emissiveTexture"] = self.texture_info(t, &m.emissive_uv);
        }
        if let Some((t, scale)) = m.normal_texture {
            let mut info = self.texture_info(t, &m.normal_uv);
            info["scale"] = num(scale);
            v["normalTexture"] = info;
        }
        if m.double_sided {
            v["doubleSided"] = json!(true);
        }
        if let Some(mode) = &m.alpha_mode {
            v["alphaMode"] = json!(mode);
        }
        if let Some(c) = m.alpha_cutoff {
            v["alphaCutoff"] = num(c);
        }
        push(&mut self.materials, v)
    }

    /// Adds a mesh with the given primitives; returns its index.
    pub fn add_mesh(&mut self, name: &str, prims: &[PrimitiveDesc]) -> usize {
        let mut out = Vec::new();
        for p in prims {
            let flat: Vec<f32> = p.positions.iter().flatten().copied().collect();
            let mut attrs = Map::new();
            attrs.insert(
                "POSITION".into(),
                json!(self.add_float_accessor(&flat, 3, Some(34962))),
            );
            if let Some(n) = &p.normals {
                let flat: Vec<f32> = n.iter().flatten().copied().collect();
                attrs.insert(
                    "NORMAL".into(),
                    json!(self.add_float_accessor(&flat, 3, Some(34962))),
                );
            }
            for (name, set) in [("TEXCOORD_0", &p.texcoords), ("TEXCOORD_1", &p.texcoords1)] {
                if let Some(t) = set {
                    let flat: Vec<f32> = t.iter().flatten().copied().collect();
                    attrs.insert(
                        name.into(),
                        json!(self.add_float_accessor(&flat, 2, Some(34962))),
                    );
                }
            }
            if let Some(t) = &p.tangents {
                let flat: Vec<f32> = t.iter().flatten().copied().collect();
                attrs.insert(
                    "TANGENT".into(),
                    json!(self.add_float_accessor(&flat, 4, Some(34962))),
                );
            }
            let mut prim = json!({"attributes": attrs});
            if let Some(i) = &p.indices {
                prim["indices"] = json!(self.add_index_accessor(i, p.index_format));
            }
            if let Some(m) = p.material {
                prim["material"] = json!(m);
            }
            if p.mode != 4 {
                prim["mode"] = json!(p.mode);
            }
            out.push(prim);
        }
        push(&mut self.meshes, json!({"name": name, "primitives": out}))
    }

    /// Adds a perspective camera; returns its index.
    pub fn add_perspective_camera(
        &mut self,
        name: &str,
        yfov: f32,
        aspect: Option<f32>,
        znear: f32,
        zfar: Option<f32>,
    ) -> usize {
        let mut p = json!({"yfov": num(yfov), "znear": num(znear)});
        if let Some(a) = aspect {
            p["aspectRatio"] = num(a);
        }
        if let Some(f) = zfar {
            p["zfar"] = num(f);
        }
        push(
            &mut self.cameras,
            json!({"name": name, "type": "perspective", "perspective": p}),
        )
    }

    /// Adds an orthographic camera (for tests; the loader rejects it); returns its index.
    pub fn add_orthographic_camera(&mut self, name: &str, xmag: f32, ymag: f32) -> usize {
        let o = json!({"xmag": num(xmag), "ymag": num(ymag), "znear": 0.01, "zfar": 100.0});
        push(
            &mut self.cameras,
            json!({"name": name, "type": "orthographic", "orthographic": o}),
        )
    }

    /// Adds a KHR_lights_punctual light; returns its index.
    pub fn add_light(&mut self, l: &LightDesc) -> usize {
        self.extensions_used.insert("KHR_lights_punctual".into());
        let mut v = json!({"color": nums(&l.color), "intensity": num(l.intensity)});
        v["type"] = json!(match l.kind {
            LightKind::Point => "point",
            LightKind::Spot { .. } => "spot",
            LightKind::Directional => "directional",
        });
        if let LightKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } = l.kind
        {
            v["spot"] = json!({"innerConeAngle": num(inner_cone_angle), "outerConeAngle": num(outer_cone_angle)});
        }
        if let Some(r) = l.range {
            v["range"] = num(r);
        }
        if let Some(n) = &l.name {
            v["name"] = json!(n);
        }
        push(&mut self.lights, v)
    }

    /// Adds a node; returns its index.
    pub fn add_node(&mut self, n: &NodeDesc) -> usize {
        let mut v = json!({});
        if let Some(s) = &n.name {
            v["name"] = json!(s);
        }
        for (key, val) in [
            ("translation", n.translation.map(|x| nums(&x))),
            ("rotation", n.rotation.map(|x| nums(&x))),
            ("scale", n.scale.map(|x| nums(&x))),
            ("matrix", n.matrix.map(|x| nums(&x))),
        ] {
            if let Some(val) = val {
                v[key] = val;
            }
        }
        for (key, val) in [("mesh", n.mesh), ("camera", n.camera)] {
            if let Some(val) = val {
                v[key] = json!(val);
            }
        }
        if let Some(l) = n.light {
            v["extensions"] = json!({"KHR_lights_punctual": {"light": l}});
        }
        if !n.children.is_empty() {
            v["children"] = json!(n.children);
        }
        push(&mut self.nodes, v)
    }

    /// Adds an animation, one sampler per channel; returns its index.
    pub fn add_animation(&mut self, name: &str, channels: &[ChannelDesc]) -> usize {
        let (mut chans, mut samplers) = (Vec::new(), Vec::new());
        for (i, c) in channels.iter().enumerate() {
            let comps = if c.property == Property::Rotation {
                4
            } else {
                3
            };
            let input = self.add_float_accessor(&c.times, 1, None);
            let output = self.add_float_accessor(&c.values, comps, None);
            let interp = match c.interpolation {
                Interpolation::Linear => "LINEAR",
                Interpolation::Step => "STEP",
                Interpolation::CubicSpline => "CUBICSPLINE",
            };
            let path = match c.property {
                Property::Translation => "translation",
                Property::Rotation => "rotation",
                Property::Scale => "scale",
            };
            samplers.push(json!({"input": input, "output": output, "interpolation": interp}));
            chans.push(json!({"sampler": i, "target": {"node": c.node, "path": path}}));
        }
        push(
            &mut self.animations,
            json!({"name": name, "channels": chans, "samplers": samplers}),
        )
    }

    /// Adds an RGBA8 image (embedded PNG) and a texture using it; returns the texture index.
    /// `wrap` is the glTF wrap mode for both axes (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT).
    pub fn add_texture_rgba8(
        &mut self,
        width: u32,
        height: u32,
        rgba: &[u8],
        wrap: u32,
    ) -> Option<usize> {
        let png = png::encode_rgba8(width, height, rgba)?;
        let view = self.view(&png, None);
        let image = push(
            &mut self.images,
            json!({"bufferView": view, "mimeType": "image/png"}),
        );
        let sampler = push(&mut self.samplers, json!({"wrapS": wrap, "wrapT": wrap}));
        Some(push(
            &mut self.textures,
            json!({"source": image, "sampler": sampler}),
        ))
    }

    /// Sets the magnification filter (`magFilter`, e.g. 9728 NEAREST) of texture `texture`'s
    /// sampler (one sampler per texture: [`GltfBuilder::add_texture_rgba8`]).
    pub fn set_mag_filter(&mut self, texture: usize, filter: u32) {
        let sampler = self.textures[texture]["sampler"].as_u64().unwrap_or(0) as usize;
        self.samplers[sampler]["magFilter"] = json!(filter);
    }

    /// Adds a scene with `roots` and optional `extras`; the first scene is the default one.
    pub fn add_scene(&mut self, name: &str, roots: &[usize], extras: Option<Value>) -> usize {
        let mut v = json!({"name": name, "nodes": roots});
        if let Some(e) = extras {
            v["extras"] = e;
        }
        push(&mut self.scenes, v)
    }

    /// The glTF JSON and the binary buffer. `bin_uri` is the buffer's URI, or `None` to embed it.
    pub fn to_json(&self, bin_uri: Option<&str>) -> (Value, Vec<u8>) {
        let mut root = json!({"asset": {"version": "2.0", "generator": "radcache-scene writer"}});
        if !self.bin.is_empty() {
            let uri = match bin_uri {
                Some(u) => u.to_string(),
                None => format!(
                    "data:application/octet-stream;base64,{}",
                    base64::engine::general_purpose::STANDARD.encode(&self.bin)
                ),
            };
            root["buffers"] = json!([{"byteLength": self.bin.len(), "uri": uri}]);
        }
        let lists = [
            ("bufferViews", &self.views),
            ("accessors", &self.accessors),
            ("materials", &self.materials),
            ("meshes", &self.meshes),
            ("nodes", &self.nodes),
            ("cameras", &self.cameras),
            ("animations", &self.animations),
            ("scenes", &self.scenes),
            ("images", &self.images),
            ("textures", &self.textures),
            ("samplers", &self.samplers),
        ];
        for (key, list) in lists {
            if !list.is_empty() {
                root[key] = Value::Array(list.clone());
            }
        }
        if !self.scenes.is_empty() {
            root["scene"] = json!(0);
        }
        if !self.lights.is_empty() {
            root["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.extensions_used.is_empty() {
            root["extensionsUsed"] = json!(self.extensions_used);
        }
        (root, self.bin.clone())
    }

    /// Writes `path` (a `.gltf`), plus `<stem>.bin` next to it for [`BufferLayout::External`].
    pub fn write(&self, path: &Path, layout: BufferLayout) -> Result<()> {
        let bin_name = format!(
            "{}.bin",
            path.file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("buffer")
        );
        let (root, bin) =
            self.to_json((layout == BufferLayout::External).then_some(bin_name.as_str()));
        write_files(
            path,
            &root,
            (layout == BufferLayout::External).then_some((&bin_name, &bin)),
        )
    }
}

/// Writes a glTF JSON value (pretty-printed) and optionally a binary file next to it.
pub fn write_files(path: &Path, root: &Value, bin: Option<(&str, &[u8])>) -> Result<()> {
    let io = |p: &Path| {
        let p = p.to_path_buf();
        move |source| Error::Write { path: p, source }
    };
    let text = serde_json::to_string_pretty(root).map_err(|e| Error::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })?;
    std::fs::write(path, text + "\n").map_err(io(path))?;
    if let Some((name, data)) = bin {
        let bin_path = path.with_file_name(name);
        std::fs::write(&bin_path, data).map_err(io(&bin_path))?;
    }
    Ok(())
}
