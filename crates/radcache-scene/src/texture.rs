//! Textures and decoded images.
//!
//! Images are kept as RGBA8 with an `srgb` flag (true for base-colour and emissive textures, whose
//! texels are sRGB-encoded per the glTF spec): the GPU side can upload them as `R8G8B8A8_SRGB` and
//! let the sampler decode, while [`Image::texel_linear`] is the CPU twin. Samplers keep the wrap
//! modes and whether `magFilter` is NEAREST. A material's [`TextureRef`] names the texture, the
//! texture coordinate set it samples and its `KHR_texture_transform` ([`TextureTransform`]).

use std::collections::HashMap;

use glam::{Vec2, Vec4};

use crate::error::{label, Result, WarningKind, Warnings};
use crate::math::srgb_to_linear;
use crate::resources::Source;
use crate::texture_transform::parse_transform;
pub use crate::texture_transform::TextureTransform;

/// Texture coordinate wrap mode (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WrapMode {
    /// `REPEAT` (glTF default).
    #[default]
    Repeat,
    /// `CLAMP_TO_EDGE`.
    ClampToEdge,
    /// `MIRRORED_REPEAT`.
    MirroredRepeat,
}

/// A texture: an image plus wrap modes.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// glTF texture name.
    pub name: Option<String>,
    /// Index into `Scene::images`.
    pub image: usize,
    /// Wrap mode along u.
    pub wrap_s: WrapMode,
    /// Wrap mode along v.
    pub wrap_t: WrapMode,
    /// The sampler's `magFilter` is NEAREST: lookups take the texel the point falls in (at
    /// every scale: there are no mipmaps); otherwise bilinear.
    pub nearest: bool,
}

/// A material's reference to a texture: which texture, which set of texture coordinates and
/// which `KHR_texture_transform` (docs/materials.md §13). The set and the transform belong to
/// the reference, not to the [`Texture`]: two materials may sample one texture differently.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `Scene::textures`.
    pub texture: usize,
    /// The texture coordinate set: 0 (TEXCOORD_0) or 1 (TEXCOORD_1); the transform's `texCoord`
    /// already applied.
    pub tex_coord: u32,
    /// The reference's `KHR_texture_transform` (identity without the extension).
    pub transform: TextureTransform,
}

impl TextureRef {
    /// A reference to `texture` through TEXCOORD_0 without a transform.
    pub fn new(texture: usize) -> TextureRef {
        TextureRef {
            texture,
            tex_coord: 0,
            transform: TextureTransform::IDENTITY,
        }
    }

    /// The texture coordinates this reference samples at a point whose TEXCOORD_0 is `uv0` and
    /// TEXCOORD_1 is `uv1`: its set, then its transform.
    pub fn map(&self, uv0: Vec2, uv1: Vec2) -> Vec2 {
        let uv = if self.tex_coord == 1 { uv1 } else { uv0 };
        self.transform.apply(uv)
    }
}

/// A decoded image, RGBA8, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// glTF image name.
    pub name: Option<String>,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `4 * width * height` bytes, RGBA.
    pub rgba8: Vec<u8>,
    /// True when the RGB channels are sRGB-encoded (colour data); alpha is always linear.
    pub srgb: bool,
}

impl Image {
    /// Texel `(x, y)` in linear RGBA (sRGB decoded when `srgb`); coordinates are clamped.
    pub fn texel_linear(&self, x: u32, y: u32) -> Vec4 {
        if self.width == 0 || self.height == 0 {
            return Vec4::ZERO;
        }
        let x = x.min(self.width - 1) as usize;
        let y = y.min(self.height - 1) as usize;
        let i = 4 * (y * self.width as usize + x);
        let c = |k: usize| f32::from(self.rgba8.get(i + k).copied().unwrap_or(0)) / 255.0;
        let d = |v: f32| if self.srgb { srgb_to_linear(v) } else { v };
        Vec4::new(d(c(0)), d(c(1)), d(c(2)), c(3))
    }

    /// All texels as linear RGBA `f32` (`4 · width · height` values, rows top to bottom), sRGB
    /// decoded when `srgb`: for uploading as `R32G32B32A32_SFLOAT` instead of `R8G8B8A8_SRGB`.
    pub fn to_linear_f32(&self) -> Vec<f32> {
        let lut: Vec<f32> = (0..=255u8)
            .map(|b| {
                let v = f32::from(b) / 255.0;
                if self.srgb {
                    srgb_to_linear(v)
                } else {
                    v
                }
            })
            .collect();
        self.rgba8
            .chunks_exact(4)
            .flat_map(|t| {
                [
                    lut[t[0] as usize],
                    lut[t[1] as usize],
                    lut[t[2] as usize],
                    f32::from(t[3]) / 255.0,
                ]
            })
            .collect()
    }

    /// Mean linear RGBA over all texels (used to estimate textured emitters' power).
    pub fn mean_linear(&self) -> Vec4 {
        let n = u64::from(self.width) * u64::from(self.height);
        if n == 0 {
            return Vec4::ZERO;
        }
        let mut sum = glam::DVec4::ZERO;
        for y in 0..self.height {
            for x in 0..self.width {
                sum += self.texel_linear(x, y).as_dvec4();
            }
        }
        (sum / n as f64).as_vec4()
    }
}

/// Converts decoded pixels of any gltf image format to RGBA8.
fn to_rgba8(data: &gltf::image::Data) -> Option<Vec<u8>> {
    use gltf::image::Format as F;
    let p = &data.pixels;
    let u16s = || {
        p.chunks_exact(2)
            .map(|b| (u16::from_ne_bytes([b[0], b[1]]) >> 8) as u8)
    };
    let f32s = || {
        p.chunks_exact(4).map(|b| {
            (f32::from_ne_bytes([b[0], b[1], b[2], b[3]]).clamp(0.0, 1.0) * 255.0 + 0.5) as u8
        })
    };
    let expand = |vals: Vec<u8>, ch: usize| -> Vec<u8> {
        vals.chunks_exact(ch)
            .flat_map(|c| match ch {
                1 => [c[0], c[0], c[0], 255],
                2 => [c[0], c[0], c[0], c[1]],
                3 => [c[0], c[1], c[2], 255],
                _ => [c[0], c[1], c[2], c[3]],
            })
            .collect()
    };
    let out = match data.format {
        F::R8 => expand(p.clone(), 1),
        F::R8G8 => expand(p.clone(), 2),
        F::R8G8B8 => expand(p.clone(), 3),
        F::R8G8B8A8 => p.clone(),
        F::R16 => expand(u16s().collect(), 1),
        F::R16G16 => expand(u16s().collect(), 2),
        F::R16G16B16 => expand(u16s().collect(), 3),
        F::R16G16B16A16 => expand(u16s().collect(), 4),
        F::R32G32B32FLOAT => expand(f32s().collect(), 3),
        F::R32G32B32A32FLOAT => expand(f32s().collect(), 4),
    };
    let expected = 4 * data.width as usize * data.height as usize;
    (out.len() == expected).then_some(out)
}

fn wrap(mode: gltf::texture::WrappingMode) -> WrapMode {
    match mode {
        gltf::texture::WrappingMode::ClampToEdge => WrapMode::ClampToEdge,
        gltf::texture::WrappingMode::MirroredRepeat => WrapMode::MirroredRepeat,
        gltf::texture::WrappingMode::Repeat => WrapMode::Repeat,
    }
}

/// Loads textures and images on demand, de-duplicated by glTF index.
#[derive(Debug, Default)]
pub(crate) struct TextureLoader {
    pub(crate) textures: Vec<Texture>,
    pub(crate) images: Vec<Image>,
    texture_map: HashMap<usize, usize>,
    image_map: HashMap<usize, usize>,
}

impl TextureLoader {
    /// Resolves a material's texture slot, with its texture coordinate set and its
    /// `KHR_texture_transform`; `None` (with a warning) when it cannot be used.
    pub(crate) fn get(
        &mut self,
        src: &Source,
        info: Option<gltf::texture::Info<'_>>,
        srgb: bool,
        user: &str,
        warnings: &mut Warnings,
    ) -> Result<Option<TextureRef>> {
        let Some(info) = info else { return Ok(None) };
        let ext = info.texture_transform();
        let mapping = Mapping {
            tex_coord: ext
                .as_ref()
                .and_then(|t| t.tex_coord())
                .unwrap_or(info.tex_coord()),
            transform: ext.map(|t| TextureTransform {
                offset: Vec2::from(t.offset()),
                rotation: t.rotation(),
                scale: Vec2::from(t.scale()),
            }),
        };
        self.resolve(src, info.texture(), mapping, srgb, user, warnings)
    }

    /// Resolves a material's normal texture (linear data), like [`TextureLoader::get`]. The gltf
    /// crate gives `normalTexture` no `texture_transform()`: `raw_transform` is the reference's
    /// `KHR_texture_transform` object from the file's JSON.
    pub(crate) fn get_normal(
        &mut self,
        src: &Source,
        info: Option<gltf::material::NormalTexture<'_>>,
        raw_transform: Option<&serde_json::Value>,
        user: &str,
        warnings: &mut Warnings,
    ) -> Result<Option<TextureRef>> {
        let Some(info) = info else { return Ok(None) };
        let mut mapping = Mapping {
            tex_coord: info.tex_coord(),
            transform: None,
        };
        if let Some(raw) = raw_transform {
            match parse_transform(raw) {
                Ok((transform, tex_coord)) => {
                    mapping.transform = Some(transform);
                    mapping.tex_coord = tex_coord.unwrap_or(mapping.tex_coord);
                }
                Err(why) => {
                    let tex = info.texture();
                    let msg = format!(
                        "{}: {user} {}: KHR_texture_transform {why}; sampled without the transform",
                        src.path.display(),
                        label("texture", tex.index(), tex.name())
                    );
                    warnings.push(WarningKind::TextureIgnored, 1, msg);
                }
            }
        }
        self.resolve(src, info.texture(), mapping, false, user, warnings)
    }

    fn resolve(
        &mut self,
        src: &Source,
        tex: gltf::Texture<'_>,
        mapping: Mapping,
        srgb: bool,
        user: &str,
        warnings: &mut Warnings,
    ) -> Result<Option<TextureRef>> {
        let tex_label = label("texture", tex.index(), tex.name());
        let file = src.path.display();
        let tex_coord = mapping.tex_coord;
        if tex_coord > 1 {
            let msg = format!("{file}: {user} {tex_label}: texCoord {tex_coord} unsupported (only TEXCOORD_0 and TEXCOORD_1); texture ignored");
            warnings.push(WarningKind::TextureIgnored, 1, msg);
            return Ok(None);
        }
        let transform = match mapping.transform {
            Some(t) if !(t.matrix().iter().flatten().all(|v| v.is_finite())) => {
                let msg = format!("{file}: {user} {tex_label}: KHR_texture_transform has a non-finite value; sampled without the transform");
                warnings.push(WarningKind::TextureIgnored, 1, msg);
                TextureTransform::IDENTITY
            }
            Some(t) => t,
            None => TextureTransform::IDENTITY,
        };
        let reference = |texture| TextureRef {
            texture,
            tex_coord,
            transform,
        };
        if let Some(&t) = self.texture_map.get(&tex.index()) {
            return Ok(Some(reference(t)));
        }
        let img = tex.source();
        let image = match self.image_map.get(&img.index()) {
            Some(&i) => {
                if self.images[i].srgb != srgb {
                    let msg = format!("{file}: {user} {tex_label}: image {} used as both colour and non-colour data; keeping the first use's encoding", img.index());
                    warnings.push(WarningKind::TextureIgnored, 1, msg);
                }
                i
            }
            None => {
                let data = src.decode_image(&img)?;
                let Some(rgba8) = to_rgba8(&data) else {
                    let msg = format!("{file}: {user} {tex_label}: image {} has an unexpected pixel layout; texture ignored", img.index());
                    warnings.push(WarningKind::TextureIgnored, 1, msg);
                    return Ok(None);
                };
                self.images.push(Image {
                    name: img.name().map(str::to_string),
                    width: data.width,
                    height: data.height,
                    rgba8,
                    srgb,
                });
                self.image_map.insert(img.index(), self.images.len() - 1);
                self.images.len() - 1
            }
        };
        let sampler = tex.sampler();
        self.textures.push(Texture {
            name: tex.name().map(str::to_string),
            image,
            wrap_s: wrap(sampler.wrap_s()),
            wrap_t: wrap(sampler.wrap_t()),
            nearest: sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest),
        });
        self.texture_map
            .insert(tex.index(), self.textures.len() - 1);
        Ok(Some(reference(self.textures.len() - 1)))
    }
}

/// A reference's texture coordinate set (the transform's `texCoord` applied) and transform, as
/// the file gives them.
#[derive(Clone, Copy, Debug)]
struct Mapping {
    tex_coord: u32,
    transform: Option<TextureTransform>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) {
        assert!((a - b).abs().max_element() < 1e-6, "{a} against {b}");
    }

    #[test]
    fn a_reference_maps_its_own_set() {
        let r = TextureRef {
            texture: 0,
            tex_coord: 1,
            transform: TextureTransform {
                offset: Vec2::new(1.0, 2.0),
                ..TextureTransform::IDENTITY
            },
        };
        close(
            r.map(Vec2::ZERO, Vec2::new(0.5, 0.25)),
            Vec2::new(1.5, 2.25),
        );
        close(
            TextureRef::new(3).map(Vec2::new(0.1, 0.2), Vec2::ONE),
            Vec2::new(0.1, 0.2),
        );
    }
}
