//! PNG encoding of the writer's embedded test textures (RGBA8), with the `png` crate.

/// Encodes `rgba` (`4 * width * height` bytes, rows top to bottom) as a PNG file.
/// Returns `None` when the size is zero or the pixel count does not match.
pub(crate) fn encode_rgba8(width: u32, height: u32, rgba: &[u8]) -> Option<Vec<u8>> {
    let expected = 4 * u64::from(width) * u64::from(height);
    if width == 0 || height == 0 || rgba.len() as u64 != expected {
        return None;
    }
    let mut out = Vec::new();
    let mut encoder = ::png::Encoder::new(&mut out, width, height);
    encoder.set_color(::png::ColorType::Rgba);
    encoder.set_depth(::png::BitDepth::Eight);
    // Writing into a `Vec` of checked size cannot fail.
    let mut writer = encoder.write_header().ok()?;
    writer.write_image_data(rgba).ok()?;
    writer.finish().ok()?;
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::encode_rgba8;

    /// Decodes a PNG written by [`encode_rgba8`] back to (width, height, RGBA8 pixels).
    fn decode(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
        let mut reader = ::png::Decoder::new(bytes).read_info().unwrap();
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).unwrap();
        assert_eq!(
            (info.color_type, info.bit_depth),
            (::png::ColorType::Rgba, ::png::BitDepth::Eight)
        );
        pixels.truncate(info.buffer_size());
        (info.width, info.height, pixels)
    }

    #[test]
    fn decoded_pixels_are_the_encoded_ones() {
        for (width, height) in [(1, 1), (1, 2), (3, 2), (4, 4), (97, 61)] {
            let rgba: Vec<u8> = (0..4 * width * height)
                .map(|i| (i * 37 + i / 7) as u8)
                .collect();
            let png = encode_rgba8(width, height, &rgba).unwrap();
            assert_eq!(decode(&png), (width, height, rgba), "{width}x{height}");
        }
    }

    #[test]
    fn rejects_wrong_sizes() {
        assert!(encode_rgba8(2, 2, &[0; 16]).is_some());
        assert!(encode_rgba8(2, 2, &[0; 15]).is_none());
        assert!(encode_rgba8(0, 2, &[]).is_none());
    }
}
