//! 8-bit sRGB PNG previews of linear images.
//!
//! Each channel goes through [`crate::color::display_u8`] (exposure, tone curve, clamp, exact
//! sRGB OETF, rounding); NaN displays as 0 and +inf as 255, so previews never fail on bad pixels
//! (count them with [`crate::compare`]). The PNG is 8-bit RGB with an `sRGB` chunk (perceptual
//! intent), written atomically. AOV layers are not part of the preview.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::atomic::write_atomic;
use crate::color::{display_u8, exposure_scale, ToneMap};
use crate::error::{Error, Result};
use crate::image::Image;

/// Options for [`write_png`] and [`to_srgb8`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PngOptions {
    /// Exposure in stops: values are multiplied by `2^exposure`.
    pub exposure: f32,
    /// Tone curve applied after exposure.
    pub tone_map: ToneMap,
}

/// The image as interleaved 8-bit sRGB, row-major, top row first.
pub fn to_srgb8(image: &Image, options: &PngOptions) -> Vec<u8> {
    let scale = exposure_scale(options.exposure);
    image
        .rgb()
        .iter()
        .map(|&v| display_u8(v, scale, options.tone_map))
        .collect()
}

/// Writes an 8-bit sRGB PNG preview of `image` to `path` atomically.
pub fn write_png(path: impl AsRef<Path>, image: &Image, options: &PngOptions) -> Result<()> {
    let path = path.as_ref();
    let pixels = to_srgb8(image, options);
    let png_error = |e| Error::png_write(path, e);
    write_atomic(path, |file| {
        let mut encoder = png::Encoder::new(file, image.width(), image.height());
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut writer = encoder.write_header().map_err(png_error)?;
        writer.write_image_data(&pixels).map_err(png_error)?;
        writer.finish().map_err(png_error)
    })?;
    log::debug!(
        "wrote {}x{} PNG '{}'",
        image.width(),
        image.height(),
        path.display()
    );
    Ok(())
}
