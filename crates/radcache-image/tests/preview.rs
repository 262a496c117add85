//! sRGB encoding against known values, the PNG preview, and output path patterns.

mod common;

use std::path::Path;

use common::{entries, scratch_dir};
use radcache_image::{
    display_u8, frame_path, output_path, png_beside, srgb_encode, srgb_to_u8, to_srgb8, write_png,
    Error, Image, PngOptions, ToneMap,
};

#[test]
fn srgb_known_values() {
    assert_eq!(srgb_to_u8(0.0), 0);
    assert_eq!(srgb_to_u8(1.0), 255);
    // Linear segment: 12.92 · 0.001 · 255 = 3.29 → 3.
    assert_eq!(srgb_to_u8(0.001), 3);
    // Boundary L = 0.0031308: 12.92 · L = 0.04044994; the power branch gives the same value there.
    assert!((srgb_encode(0.003_130_8) - 0.040_449_94).abs() < 1e-7);
    let power = 1.055 * 0.003_130_8_f32.powf(1.0 / 2.4) - 0.055;
    assert!((srgb_encode(0.003_130_8) - power).abs() < 1e-6);
    assert_eq!(srgb_to_u8(0.003_130_8), 10); // 0.04045 · 255 = 10.31
                                             // 1.055 · 0.5^(1/2.4) − 0.055 = 0.735357 → 187.52 → 188.
    assert_eq!(srgb_to_u8(0.5), 188);
    // Linear 0.2140411 is the sRGB mid-grey 0.5: ((0.5 + 0.055) / 1.055)^2.4 = 0.21404114.
    assert!((srgb_encode(0.214_041_14) - 0.5).abs() < 1e-6);
    // 18 % grey: 1.055 · 0.18^(1/2.4) − 0.055 = 0.461356 → 117.65 → 118.
    assert_eq!(srgb_to_u8(0.18), 118);
    // 1.055 · 0.2^(1/2.4) − 0.055 = 0.484529 → 123.55 → 124.
    assert_eq!(srgb_to_u8(0.2), 124);
}

#[test]
fn non_finite_and_out_of_range_values_never_panic() {
    assert_eq!(srgb_to_u8(f32::NAN), 0);
    assert_eq!(srgb_to_u8(f32::INFINITY), 255);
    assert_eq!(srgb_to_u8(f32::NEG_INFINITY), 0);
    assert_eq!(srgb_to_u8(-0.5), 0);
    assert_eq!(srgb_to_u8(7.0), 255);
    for curve in [ToneMap::None, ToneMap::Filmic] {
        assert_eq!(display_u8(f32::NAN, 1.0, curve), 0);
        assert_eq!(display_u8(f32::INFINITY, 1.0, curve), 255);
        assert_eq!(display_u8(f32::MAX, 4.0, curve), 255);
    }
}

#[test]
fn exposure_and_filmic_curve() {
    let image = Image::from_rgb(1, 1, vec![0.125, 0.25, 1.0]).unwrap();
    // +2 stops: 0.5, 1.0, 4.0 → 188, 255, 255 (clamped).
    let bright = PngOptions {
        exposure: 2.0,
        tone_map: ToneMap::None,
    };
    assert_eq!(to_srgb8(&image, &bright), [188, 255, 255]);
    // Filmic at 0 stops: f(1) = 2.54 / 3.16 = 0.80380 → sRGB 0.90823 → 231.6 → 232.
    let filmic = PngOptions {
        exposure: 0.0,
        tone_map: ToneMap::Filmic,
    };
    assert_eq!(to_srgb8(&image, &filmic)[2], 232);
}

#[test]
fn png_round_trip() {
    let dir = scratch_dir("png");
    let path = dir.join("preview.png");
    let mut image = Image::new(3, 2);
    image.set_pixel(0, 0, [1.0, 0.5, 0.0]);
    image.set_pixel(2, 1, [f32::NAN, f32::INFINITY, -1.0]);
    let options = PngOptions::default();
    write_png(&path, &image, &options).unwrap();
    assert_eq!(entries(&dir), ["preview.png"]);

    let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buffer).unwrap();
    assert_eq!((info.width, info.height), (3, 2));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    assert_eq!(&buffer[..info.buffer_size()], to_srgb8(&image, &options));
    assert_eq!(&buffer[..3], [255, 188, 0]);
    assert_eq!(&buffer[15..18], [0, 255, 0]);
}

#[test]
fn png_into_missing_directory_is_a_clear_error() {
    let dir = scratch_dir("png_missing_dir");
    let path = dir.join("nope/preview.png");
    let err = write_png(&path, &Image::new(1, 1), &PngOptions::default()).unwrap_err();
    assert!(err.to_string().contains("nope/preview.png"), "{err}");
}

#[test]
fn frame_pattern_is_zero_padded() {
    assert_eq!(
        frame_path("frame_####.exr", 7).unwrap(),
        Path::new("frame_0007.exr")
    );
    assert_eq!(
        frame_path("out/seq/f#.exr", 12).unwrap(),
        Path::new("out/seq/f12.exr")
    );
}

#[test]
fn sequence_without_hashes_is_an_error() {
    let err = frame_path("frame.exr", 7).unwrap_err();
    assert!(matches!(err, Error::PathPattern { .. }));
    assert!(err.to_string().contains("frame.exr"), "{err}");
    assert!(output_path("frame.exr", 7, true).is_err());
    // A single image may use a plain path, or a pattern.
    assert_eq!(
        output_path("frame.exr", 7, false).unwrap(),
        Path::new("frame.exr")
    );
    assert_eq!(
        output_path("frame_###.exr", 7, false).unwrap(),
        Path::new("frame_007.exr")
    );
}

#[test]
fn png_path_beside_exr() {
    assert_eq!(png_beside("out.exr"), Path::new("out.png"));
    assert_eq!(
        png_beside("dir/frame_0007.exr"),
        Path::new("dir/frame_0007.png")
    );
    assert_eq!(png_beside("dir/out"), Path::new("dir/out.png"));
}
