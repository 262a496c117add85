//! In-memory images: linear RGB `f32` beauty plus optional named AOV layers.
//!
//! Layout: pixels are row-major, top row first; a pixel's channels are interleaved
//! (`rgb[3 * (y * width + x) + c]`). Every [`Layer`] uses the same layout with its own channel
//! count. Channel names follow the OpenEXR convention (`R`, `G`, `B` for colour, `X`, `Y`, `Z` for
//! vectors, `Z` for depth); when written to EXR a layer's channels become `<layer>.<channel>`.

use crate::error::{Error, Result};

/// Name of the standard albedo AOV (channels `R`, `G`, `B`).
pub const ALBEDO: &str = "albedo";
/// Name of the standard normal AOV (channels `X`, `Y`, `Z`).
pub const NORMAL: &str = "normal";
/// Name of the standard depth AOV (channel `Z`).
pub const DEPTH: &str = "depth";

/// A named AOV layer: `channels.len()` interleaved `f32` values per pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    name: String,
    channels: Vec<String>,
    data: Vec<f32>,
}

impl Layer {
    /// A layer from its name, channel names and interleaved data.
    ///
    /// Names must be non-empty, printable ASCII without `.`; channel names must be unique. The
    /// data length is checked against the image when the layer is added ([`Image::add_layer`]).
    pub fn new(name: impl Into<String>, channels: Vec<String>, data: Vec<f32>) -> Result<Self> {
        let name = name.into();
        check_name(&name, "layer name")?;
        if channels.is_empty() {
            return Err(Error::InvalidImage(format!(
                "layer '{name}' has no channels"
            )));
        }
        for (i, channel) in channels.iter().enumerate() {
            check_name(channel, "channel name")?;
            if channels[..i].contains(channel) {
                return Err(Error::InvalidImage(format!(
                    "layer '{name}' has channel '{channel}' twice"
                )));
            }
        }
        Ok(Self {
            name,
            channels,
            data,
        })
    }

    /// The standard albedo layer ([`ALBEDO`], channels `R`, `G`, `B`).
    pub fn albedo(data: Vec<f32>) -> Self {
        Self::standard(ALBEDO, &["R", "G", "B"], data)
    }

    /// The standard normal layer ([`NORMAL`], channels `X`, `Y`, `Z`).
    pub fn normal(data: Vec<f32>) -> Self {
        Self::standard(NORMAL, &["X", "Y", "Z"], data)
    }

    /// The standard depth layer ([`DEPTH`], channel `Z`).
    pub fn depth(data: Vec<f32>) -> Self {
        Self::standard(DEPTH, &["Z"], data)
    }

    fn standard(name: &str, channels: &[&str], data: Vec<f32>) -> Self {
        Self {
            name: name.to_owned(),
            channels: channels.iter().map(|c| (*c).to_owned()).collect(),
            data,
        }
    }

    /// The layer name (e.g. `albedo`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The channel names in storage order.
    pub fn channels(&self) -> &[String] {
        &self.channels
    }

    /// Interleaved samples, `channels().len()` per pixel.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Mutable interleaved samples (the length cannot change).
    pub fn data_mut(&mut self) -> &mut [f32] {
        &mut self.data
    }

    /// Samples of one channel by name, in pixel order; `None` if there is no such channel.
    pub fn channel(&self, channel: &str) -> Option<Vec<f32>> {
        let stride = self.channels.len();
        let index = self.channels.iter().position(|c| c == channel)?;
        Some(
            self.data
                .iter()
                .skip(index)
                .step_by(stride)
                .copied()
                .collect(),
        )
    }
}

fn check_name(name: &str, what: &str) -> Result<()> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name.bytes().all(|b| b.is_ascii_graphic() && b != b'.');
    if ok {
        Ok(())
    } else {
        Err(Error::InvalidImage(format!(
            "{what} '{name}' must be 1-64 printable ASCII characters without '.'"
        )))
    }
}

/// A linear RGB `f32` image with optional AOV layers.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    rgb: Vec<f32>,
    layers: Vec<Layer>,
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            rgb: vec![0.0; pixel_count(width, height) * 3],
            layers: Vec::new(),
        }
    }

    /// An image from interleaved linear RGB data (`3 * width * height` values).
    pub fn from_rgb(width: u32, height: u32, rgb: Vec<f32>) -> Result<Self> {
        let expected = pixel_count(width, height) * 3;
        if rgb.len() != expected {
            return Err(Error::InvalidImage(format!(
                "{width}x{height} RGB image needs {expected} values, got {}",
                rgb.len()
            )));
        }
        Ok(Self {
            width,
            height,
            rgb,
            layers: Vec::new(),
        })
    }

    /// An image from RGB pixels (`width * height` of them), row-major, top row first.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<[f32; 3]>) -> Result<Self> {
        let expected = pixel_count(width, height);
        if pixels.len() != expected {
            return Err(Error::InvalidImage(format!(
                "{width}x{height} image needs {expected} pixels, got {}",
                pixels.len()
            )));
        }
        Self::from_rgb(width, height, pixels.into_iter().flatten().collect())
    }

    /// An image from interleaved RGBA data (`4 * width * height` values, e.g. a GPU read-back
    /// of an `R32G32B32A32_SFLOAT` target); the fourth channel is dropped.
    pub fn from_rgba(width: u32, height: u32, rgba: &[f32]) -> Result<Self> {
        let expected = pixel_count(width, height) * 4;
        if rgba.len() != expected {
            return Err(Error::InvalidImage(format!(
                "{width}x{height} RGBA image needs {expected} values, got {}",
                rgba.len()
            )));
        }
        let rgb = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]);
        Self::from_rgb(width, height, rgb.collect())
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// `width * height`.
    pub fn pixel_count(&self) -> usize {
        pixel_count(self.width, self.height)
    }

    /// Interleaved linear RGB, row-major, top row first.
    pub fn rgb(&self) -> &[f32] {
        &self.rgb
    }

    /// Mutable interleaved linear RGB.
    pub fn rgb_mut(&mut self) -> &mut [f32] {
        &mut self.rgb
    }

    /// The RGB pixels in order (row-major, top row first).
    pub fn pixels(&self) -> impl ExactSizeIterator<Item = [f32; 3]> + '_ {
        self.rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]])
    }

    /// The RGB value at (`x`, `y`), `y = 0` being the top row. Panics when out of bounds.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        let i = self.index(x, y);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Sets the RGB value at (`x`, `y`). Panics when out of bounds.
    pub fn set_pixel(&mut self, x: u32, y: u32, value: [f32; 3]) {
        let i = self.index(x, y);
        self.rgb[i..i + 3].copy_from_slice(&value);
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{} image",
            self.width,
            self.height
        );
        3 * (y as usize * self.width as usize + x as usize)
    }

    /// The AOV layers, in the order they were added.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// The AOV layer called `name`.
    pub fn layer(&self, name: &str) -> Option<&Layer> {
        self.layers.iter().find(|l| l.name == name)
    }

    /// The AOV layer called `name`, mutably.
    pub fn layer_mut(&mut self, name: &str) -> Option<&mut Layer> {
        self.layers.iter_mut().find(|l| l.name == name)
    }

    /// Adds an AOV layer; its data must hold `channels * width * height` values and its name
    /// must not be taken.
    pub fn add_layer(&mut self, layer: Layer) -> Result<()> {
        let expected = self.pixel_count() * layer.channels.len();
        if layer.data.len() != expected {
            return Err(Error::InvalidImage(format!(
                "layer '{}' with {} channels on a {}x{} image needs {expected} values, got {}",
                layer.name,
                layer.channels.len(),
                self.width,
                self.height,
                layer.data.len()
            )));
        }
        if self.layer(&layer.name).is_some() {
            return Err(Error::InvalidImage(format!(
                "layer '{}' added twice",
                layer.name
            )));
        }
        self.layers.push(layer);
        Ok(())
    }

    /// Builder form of [`Image::add_layer`].
    pub fn with_layer(mut self, layer: Layer) -> Result<Self> {
        self.add_layer(layer)?;
        Ok(self)
    }

    /// Removes and returns all AOV layers.
    pub fn take_layers(&mut self) -> Vec<Layer> {
        std::mem::take(&mut self.layers)
    }
}

fn pixel_count(width: u32, height: u32) -> usize {
    width as usize * height as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_layout_is_row_major_top_first() {
        let mut image = Image::new(3, 2);
        image.set_pixel(2, 1, [1.0, 2.0, 3.0]);
        assert_eq!(&image.rgb()[15..18], &[1.0, 2.0, 3.0]);
        assert_eq!(image.pixel(2, 1), [1.0, 2.0, 3.0]);
    }

    #[test]
    fn pixel_and_rgba_constructors() {
        let pixels = vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
        let image = Image::from_pixels(2, 1, pixels.clone()).unwrap();
        assert_eq!(image.rgb(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(image.pixels().collect::<Vec<_>>(), pixels);
        let rgba = [1.0, 2.0, 3.0, 9.0, 4.0, 5.0, 6.0, 9.0];
        assert_eq!(Image::from_rgba(2, 1, &rgba).unwrap(), image);
        assert!(Image::from_pixels(2, 2, pixels).is_err());
        assert!(Image::from_rgba(2, 1, &rgba[..7]).is_err());
    }

    #[test]
    fn bad_sizes_and_names_are_errors() {
        assert!(Image::from_rgb(2, 2, vec![0.0; 11]).is_err());
        let mut image = Image::new(2, 2);
        assert!(image.add_layer(Layer::depth(vec![0.0; 3])).is_err());
        assert!(image.add_layer(Layer::depth(vec![0.0; 4])).is_ok());
        assert!(image.add_layer(Layer::depth(vec![0.0; 4])).is_err());
        assert!(Layer::new("a.b", vec!["R".into()], vec![]).is_err());
        assert!(Layer::new("a", vec!["R".into(), "R".into()], vec![]).is_err());
        assert!(Layer::new("a", vec![], vec![]).is_err());
    }

    #[test]
    fn channel_extraction() {
        let layer = Layer::normal(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(layer.channel("Y"), Some(vec![2.0, 5.0]));
        assert_eq!(layer.channel("W"), None);
    }
}
