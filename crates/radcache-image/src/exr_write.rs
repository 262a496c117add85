//! EXR output: linear RGB beauty, optional AOV layers and [`Metadata`] header attributes.
//!
//! The file is a single-part scan-line EXR, ZIP-compressed (lossless, 16 lines per block), with
//! the beauty in channels `R`, `G`, `B` and each AOV layer as prefixed channels in the same part
//! (`albedo.R`, `normal.X`, `depth.Z`, ...), which is the OpenEXR naming convention for layers and
//! what Nuke, Blender and `exrheader` show as layers. Samples are `f32`, or `f16` for every
//! channel when [`ExrOptions::half`] is set (values beyond ±65504 become ±inf, as in any f16
//! conversion). Chromaticities are the Rec.709/sRGB primaries with a D65 white point, since the
//! renderer works in linear sRGB. The write is atomic (see [`crate::atomic`]).

use std::path::Path;

use exr::image::{AnyChannel, AnyChannels, Encoding, FlatSamples, Layer as ExrLayer};
use exr::math::Vec2;
use exr::meta::attribute::{Chromaticities, Text};
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
}

impl Default for ExrOptions {
    /// `f32` samples, AOV layers included.
    fn default() -> Self {
        Self {
            half: false,
            aovs: true,
        }
    }
}

/// Writes `image` and `metadata` to `path` atomically.
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

    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (index, name) in ["R", "G", "B"].into_iter().enumerate() {
        channels.push(channel(text(name), image.rgb(), 3, index, options.half));
    }
    if options.aovs {
        for layer in image.layers() {
            let stride = layer.channels().len();
            for (index, name) in layer.channels().iter().enumerate() {
                let full = text(&format!("{}.{name}", layer.name()));
                channels.push(channel(full, layer.data(), stride, index, options.half));
            }
        }
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
            .map_err(|source| Error::ExrWrite {
                path: path.to_owned(),
                source,
            })
    })?;
    log::debug!(
        "wrote {}x{} EXR '{}'",
        image.width(),
        image.height(),
        path.display()
    );
    Ok(())
}

/// One channel de-interleaved from `data` (`stride` values per pixel, this one at `index`).
fn channel(
    name: Text,
    data: &[f32],
    stride: usize,
    index: usize,
    half: bool,
) -> AnyChannel<FlatSamples> {
    let values = data.iter().skip(index).step_by(stride).copied();
    let samples = if half {
        FlatSamples::F16(values.map(f16::from_f32).collect())
    } else {
        FlatSamples::F32(values.collect())
    };
    AnyChannel::new(name, samples)
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
