//! Reading plain RGB(A) EXRs written by other software (here: the `exr` crate directly), and the
//! writer's refusal or sanitising of values that cannot be stored finitely.

mod common;

use common::{entries, scratch_dir};
use exr::prelude::{f16, AnyChannel, AnyChannels, FlatSamples, SmallVec, WritableImage};
use radcache_image::{read_exr, write_exr, Error, ExrOptions, Image, Layer, Metadata};

/// A value that differs per pixel and channel, exactly representable in f16.
fn value(x: usize, y: usize, c: usize) -> f32 {
    (x as f32 + 10.0 * y as f32) * 0.25 + c as f32 * 0.125
}

#[test]
fn reads_plain_rgb_f32_file_from_simple_api() {
    let dir = scratch_dir("generic_rgb_f32");
    let path = dir.join("env.exr");
    let (w, h) = (7, 5);
    exr::prelude::write_rgb_file(&path, w, h, |x, y| {
        (value(x, y, 0), value(x, y, 1), value(x, y, 2))
    })
    .unwrap();

    let (image, meta) = read_exr(&path).unwrap();
    assert_eq!((image.width(), image.height()), (7, 5));
    assert!(image.layers().is_empty());
    assert_eq!(meta, Metadata::default());
    for y in 0..h {
        for x in 0..w {
            let expected = [value(x, y, 0), value(x, y, 1), value(x, y, 2)];
            assert_eq!(image.pixel(x as u32, y as u32), expected, "({x}, {y})");
        }
    }
}

#[test]
fn reads_plain_rgba_f16_file_ignoring_alpha() {
    let dir = scratch_dir("generic_rgba_f16");
    let path = dir.join("env_half.exr");
    let (w, h) = (4, 6);
    exr::prelude::write_rgba_file(&path, w, h, |x, y| {
        (
            f16::from_f32(value(x, y, 0)),
            f16::from_f32(value(x, y, 1)),
            f16::from_f32(value(x, y, 2)),
            f16::from_f32(0.5),
        )
    })
    .unwrap();

    let (image, _) = read_exr(&path).unwrap();
    assert_eq!((image.width(), image.height()), (4, 6));
    // Alpha is not an AOV layer: it has no '.' in its name.
    assert!(image.layers().is_empty());
    assert_eq!(
        image.pixel(3, 5),
        [value(3, 5, 0), value(3, 5, 1), value(3, 5, 2)]
    );
    assert_eq!(image.pixel(0, 0), [0.0, 0.125, 0.25]);
}

#[test]
fn single_part_name_is_not_a_channel_prefix() {
    let dir = scratch_dir("generic_named_part");
    let path = dir.join("named.exr");
    let channels = ["R", "G", "B"]
        .into_iter()
        .enumerate()
        .map(|(c, name)| AnyChannel::new(name, FlatSamples::F32(vec![c as f32 + 1.0; 6])))
        .collect();
    let layer = exr::image::Layer::new(
        (3, 2),
        exr::meta::header::LayerAttributes::named("beauty"),
        exr::image::Encoding::FAST_LOSSLESS,
        AnyChannels::sort(channels),
    );
    exr::image::Image::from_layer(layer)
        .write()
        .to_file(&path)
        .unwrap();

    let (image, _) = read_exr(&path).unwrap();
    assert_eq!(image.pixels().collect::<Vec<_>>(), vec![[1.0, 2.0, 3.0]; 6]);
}

#[test]
fn missing_blue_channel_is_a_content_error() {
    let dir = scratch_dir("generic_rg_only");
    let path = dir.join("rg.exr");
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = ["R", "G"]
        .into_iter()
        .map(|name| AnyChannel::new(name, FlatSamples::F32(vec![0.5; 4])))
        .collect();
    exr::image::Image::from_channels((2, 2), AnyChannels::sort(channels))
        .write()
        .to_file(&path)
        .unwrap();
    let err = read_exr(&path).unwrap_err();
    assert!(matches!(err, Error::ExrContent { .. }), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("rg.exr") && message.contains("found: G, R"),
        "{message}"
    );
}

/// A 3×2 image, all 1, with the given value at beauty (x, y, channel).
fn image_with(x: u32, y: u32, channel: usize, bad: f32) -> Image {
    let mut image = Image::from_rgb(3, 2, vec![1.0; 18]).unwrap();
    let mut pixel = image.pixel(x, y);
    pixel[channel] = bad;
    image.set_pixel(x, y, pixel);
    image
}

#[test]
fn non_finite_beauty_is_refused_and_nothing_is_written() {
    let dir = scratch_dir("refuse_nan");
    let path = dir.join("frame.exr");
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let image = image_with(2, 1, 1, bad);
        let err = write_exr(&path, &image, &Metadata::new(), &ExrOptions::default()).unwrap_err();
        let message = err.to_string();
        assert!(
            matches!(err, Error::NonFinite { x: 2, y: 1, ref channel, .. } if channel == "G"),
            "{message}"
        );
        assert!(
            message.contains("frame.exr") && message.contains("(2, 1)"),
            "{message}"
        );
        assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    }
}

#[test]
fn non_finite_aov_is_refused_unless_aovs_are_left_out() {
    let dir = scratch_dir("refuse_aov");
    let path = dir.join("frame.exr");
    let mut depth = vec![2.0; 6];
    depth[4] = f32::INFINITY; // pixel (1, 1)
    let image = Image::new(3, 2).with_layer(Layer::depth(depth)).unwrap();
    let err = write_exr(&path, &image, &Metadata::new(), &ExrOptions::default()).unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { x: 1, y: 1, ref channel, .. } if channel == "depth.Z"),
        "{err}"
    );
    let beauty_only = ExrOptions {
        aovs: false,
        ..ExrOptions::default()
    };
    write_exr(&path, &image, &Metadata::new(), &beauty_only).unwrap();
    assert!(read_exr(&path).unwrap().0.layers().is_empty());
}

#[test]
fn sanitize_replaces_non_finite_values_by_zero() {
    let dir = scratch_dir("sanitize");
    let path = dir.join("frame.exr");
    let mut image = image_with(0, 0, 0, f32::NAN);
    image.set_pixel(1, 1, [f32::INFINITY, f32::NEG_INFINITY, 3.0e38]);
    let original = image.clone();
    let options = ExrOptions {
        sanitize: true,
        ..ExrOptions::default()
    };
    write_exr(&path, &image, &Metadata::new(), &options).unwrap();
    // The caller's image is untouched (NaN != NaN, so compare bits).
    let bits = |i: &Image| i.rgb().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&image), bits(&original));

    let (back, _) = read_exr(&path).unwrap();
    assert_eq!(back.pixel(0, 0), [0.0, 1.0, 1.0]);
    assert_eq!(back.pixel(1, 1), [0.0, 0.0, 3.0e38]);
    assert!(back.rgb().iter().all(|v| v.is_finite()));
}

#[test]
fn half_output_refuses_or_clamps_values_beyond_f16_range() {
    let dir = scratch_dir("half_range");
    let path = dir.join("half.exr");
    let mut image = image_with(1, 0, 2, 70_000.0);
    image.set_pixel(0, 1, [-1.0e6, 65_504.0, f32::NAN]);
    let half = ExrOptions {
        half: true,
        ..ExrOptions::default()
    };
    // Checked channel by channel (R, G, B), each row-major: R at (0, 1) is found first.
    let err = write_exr(&path, &image, &Metadata::new(), &half).unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { x: 0, y: 1, ref channel, .. } if channel == "R"),
        "{err}"
    );
    image.set_pixel(0, 1, [-1.0, 65_504.0, 0.5]);
    let err = write_exr(&path, &image, &Metadata::new(), &half).unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { x: 1, y: 0, ref channel, .. } if channel == "B"),
        "{err}"
    );
    image.set_pixel(0, 1, [-1.0e6, 65_504.0, f32::NAN]);
    assert!(err.to_string().contains("f16"), "{err}");
    // In f32 the same large values are fine; only the NaN is refused.
    let err = write_exr(&path, &image, &Metadata::new(), &ExrOptions::default()).unwrap_err();
    assert!(
        matches!(err, Error::NonFinite { x: 0, y: 1, ref channel, .. } if channel == "B"),
        "{err}"
    );
    assert!(entries(&dir).is_empty());

    let sanitized = ExrOptions {
        sanitize: true,
        ..half
    };
    write_exr(&path, &image, &Metadata::new(), &sanitized).unwrap();
    let (back, _) = read_exr(&path).unwrap();
    assert_eq!(back.pixel(1, 0), [1.0, 1.0, 65_504.0]);
    assert_eq!(back.pixel(0, 1), [-65_504.0, 65_504.0, 0.0]);
    assert!(back.rgb().iter().all(|v| v.is_finite()));
}
