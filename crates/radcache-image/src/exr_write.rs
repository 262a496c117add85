//! EXR output: linear RGB beauty, optional AOV layers and [`Metadata`] header attributes.
//!
//! The file is a single-part scan-line EXR, ZIP-compressed (lossless, 16 lines per block), with
//! the beauty in channels `R`, `G`, `B` and each AOV layer as prefixed channels in the same part
//! (`albedo.R`, `normal.X`, `depth.Z`, ...), which is the OpenEXR naming convention for layers and
//! what Nuke, Blender and `exrheader` show as layers. Samples are `f32`, or `f16` for every
//! channel when [`ExrOptions::half`] is set. Chromaticities are the Rec.709/sRGB primaries with a D65 white point, since the
//! renderer works in linear sRGB. The write is atomic (see [`crate::atomic`]).
//!
//! # No NaN or infinity in the output
//!
//! The renderer guards against non-finite radiance at its source; the writer is the last line of
//! defence. By default a sample that would be stored as NaN or ±inf — a non-finite value in the
//! beauty or any written AOV, or with `half` a finite value beyond ±65504 (f16's largest finite
//! value) — makes [`write_exr`] fail with [`Error::NonFinite`], naming the file, the channel and
//! the first such pixel (in channel order, then row-major), and nothing is written. With
//! [`ExrOptions::sanitize`] such values are replaced instead: NaN and ±inf by 0, and (for `f16`)
//! finite values beyond the range by ±65504; the number of replaced samples is logged as a
//! warning. The caller's [`Image`] is never modified.

use std::path::Path;

use exr::image::{AnyChannel, AnyChannels, Encoding, FlatSamples, Layer as ExrLayer};
use exr::math::Vec2;
use exr::meta::attribute::Chromaticities;
use exr::meta::header::{ImageAttributes, LayerAttributes};
use exr::prelude::{f16, IntegerBounds, SmallVec, WritableImage};

use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::image::Image;
use crate::metadata::{text, Metadata};

/// Options for [`write_exr`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExrOptions {
    /// Store every channel as `f16` instead of `f32`.
    pub half: bool,
    /// Write the image's AOV layers; `false` writes the beauty only.
    pub aovs: bool,
    /// Replace values that cannot be stored finitely instead of failing (see the module docs).
    pub sanitize: bool,
}

impl Default for ExrOptions {
    /// `f32` samples, AOV layers included, non-finite values refused.
    fn default() -> Self {
        Self {
            half: false,
            aovs: true,
            sanitize: false,
        }
    }
}

/// Writes `image` and `metadata` to `path` atomically.
///
/// Fails, writing nothing, on an empty image, unwritable metadata, or (unless
/// [`ExrOptions::sanitize`]) a value that cannot be stored finitely ([`Error::NonFinite`]).
pub fn write_exr(
    path: impl AsRef<Path>,
    image: &Image,
    metadata: &Metadata,
    options: &ExrOptions,
) -> Result<()> {
    let path = path.as_ref();
    if image.pixel_count() == 0 {
        return Err(Error::InvalidImage(format!(
            "cannot write empty {}x{} image to '{}'",
            image.width(),
            image.height(),
            path.display()
        )));
    }

    let mut converter = Converter {
        path,
        width: image.width() as usize,
        options,
        replaced: 0,
    };
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (index, name) in ["R", "G", "B"].into_iter().enumerate() {
        channels.push(converter.channel(name.to_owned(), image.rgb(), 3, index)?);
    }
    if options.aovs {
        for layer in image.layers() {
            let stride = layer.channels().len();
            for (index, name) in layer.channels().iter().enumerate() {
                let full = format!("{}.{name}", layer.name());
                channels.push(converter.channel(full, layer.data(), stride, index)?);
            }
        }
    }
    if converter.replaced > 0 {
        log::warn!(
            "'{}': replaced {} sample(s) that cannot be stored finitely",
            path.display(),
            converter.replaced
        );
    }

    let mut layer_attributes = LayerAttributes::default();
    if let Some(version) = &metadata.radcache_version {
        layer_attributes.software_name = Some(text(&format!("radcache {version}")));
    }
    layer_attributes.other.extend(metadata.to_attributes(path)?);

    let size = Vec2(image.width() as usize, image.height() as usize);
    let layer = ExrLayer::new(
        size,
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let mut image_attributes = ImageAttributes::new(IntegerBounds::from_dimensions(size));
    image_attributes.chromaticities = Some(rec709_chromaticities());
    let exr_image = exr::image::Image::new(image_attributes, layer);

    write_atomic(path, |file| {
        exr_image
            .write()
            .to_buffered(file)
            .map_err(|e| Error::exr_write(path, e))
    })?;
    log::debug!(
        "wrote {}x{} EXR '{}'",
        image.width(),
        image.height(),
        path.display()
    );
    Ok(())
}

/// Largest finite `f16` value.
const F16_MAX: f32 = 65504.0;

/// De-interleaves channels and applies the non-finite policy (see the module docs).
struct Converter<'a> {
    path: &'a Path,
    width: usize,
    options: &'a ExrOptions,
    /// Samples replaced so far (with `sanitize`).
    replaced: u64,
}

impl Converter<'_> {
    /// Channel `name`, de-interleaved from `data` (`stride` values per pixel, this one at
    /// `index`).
    fn channel(
        &mut self,
        name: String,
        data: &[f32],
        stride: usize,
        index: usize,
    ) -> Result<AnyChannel<FlatSamples>> {
        let limit = if self.options.half { F16_MAX } else { f32::MAX };
        let mut values = Vec::with_capacity(data.len() / stride);
        for (pixel, &value) in data.iter().skip(index).step_by(stride).enumerate() {
            let problem = if !value.is_finite() {
                "which is not finite"
            } else if value.abs() > limit {
                "which overflows f16 (largest finite value 65504)"
            } else {
                values.push(value);
                continue;
            };
            if !self.options.sanitize {
                return Err(Error::NonFinite {
                    path: self.path.to_owned(),
                    channel: name,
                    x: (pixel % self.width) as u32,
                    y: (pixel / self.width) as u32,
                    value,
                    problem,
                });
            }
            self.replaced += 1;
            values.push(if value.is_finite() {
                limit.copysign(value)
            } else {
                0.0
            });
        }
        let samples = if self.options.half {
            FlatSamples::F16(values.into_iter().map(f16::from_f32).collect())
        } else {
            FlatSamples::F32(values)
        };
        Ok(AnyChannel::new(text(&name), samples))
    }
}

/// Rec.709 / sRGB primaries with D65 white (ITU-R BT.709).
fn rec709_chromaticities() -> Chromaticities {
    Chromaticities {
        red: Vec2(0.64, 0.33),
        green: Vec2(0.30, 0.60),
        blue: Vec2(0.15, 0.06),
        white: Vec2(0.3127, 0.3290),
    }
}
