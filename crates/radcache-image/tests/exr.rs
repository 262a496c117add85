//! EXR round trips (f32 bit-identical, f16 within half precision, metadata, AOV layers),
//! atomic writes, and clear errors on missing, corrupt or unsupported files.

mod common;

use std::path::Path;

use common::{entries, scratch_dir};
use exr::prelude::SampleType;
use radcache_image::{
    read_exr, write_atomic, write_exr, Error, ExrOptions, Image, Layer, Metadata,
};

/// A 5×3 image with awkward (finite) values and all three standard AOVs.
fn test_image() -> Image {
    let (w, h) = (5, 3);
    let special = [
        0.0,
        -0.0,
        1.0,
        -2.5,
        1.0e-40, // subnormal
        3.0e38,
        f32::MAX,
        -f32::MAX,
        f32::MIN_POSITIVE,
        0.1,
    ];
    let rgb = (0..w * h * 3)
        .map(|i| special.get(i).copied().unwrap_or(i as f32 * 0.37 - 4.0))
        .collect();
    let pixels = w * h;
    Image::from_rgb(w as u32, h as u32, rgb)
        .unwrap()
        .with_layer(Layer::albedo(
            (0..pixels * 3).map(|i| i as f32 / 45.0).collect(),
        ))
        .unwrap()
        .with_layer(Layer::normal(
            (0..pixels * 3).map(|i| (i as f32).sin()).collect(),
        ))
        .unwrap()
        .with_layer(Layer::depth((0..pixels).map(|i| 1.5 + i as f32).collect()))
        .unwrap()
}

fn test_metadata() -> Metadata {
    let mut meta = Metadata::new();
    meta.method = Some("ircache".into());
    meta.spp = Some(256);
    meta.render_time_s = Some(12.345_678_9);
    meta.scene_file = Some("assets/scènes/cornell_box.gltf".into());
    meta.world_from_camera = Some(std::array::from_fn(|i| i as f32 * 0.5 - 3.0));
    meta.projection = Some(std::array::from_fn(|i| 1.0 / (i as f32 + 1.0)));
    meta.extra.insert("frame".into(), "7".into());
    meta.extra.insert("cache.records".into(), "123456".into());
    meta
}

fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn f32_round_trip_is_bit_identical_with_metadata_and_aovs() {
    let dir = scratch_dir("f32_round_trip");
    let path = dir.join("frame.exr");
    let (image, meta) = (test_image(), test_metadata());
    write_exr(&path, &image, &meta, &ExrOptions::default()).unwrap();

    let (back, back_meta) = read_exr(&path).unwrap();
    assert_eq!((back.width(), back.height()), (5, 3));
    assert_eq!(bits(back.rgb()), bits(image.rgb()));
    assert_eq!(back.layers().len(), 3);
    for layer in image.layers() {
        let read = back.layer(layer.name()).unwrap();
        assert_eq!(read.channels(), layer.channels(), "{}", layer.name());
        assert_eq!(bits(read.data()), bits(layer.data()), "{}", layer.name());
    }
    assert_eq!(back_meta, meta);
    assert_eq!(back_meta.spp, Some(256));
    assert_eq!(back_meta.extra["cache.records"], "123456");
    assert_eq!(
        back_meta.radcache_version.as_deref(),
        Some(env!("CARGO_PKG_VERSION"))
    );
    // Only the final file remains: no temporary file left behind.
    assert_eq!(entries(&dir), ["frame.exr"]);
}

#[test]
fn header_holds_expected_attributes_and_channels() {
    let dir = scratch_dir("header");
    let path = dir.join("frame.exr");
    write_exr(
        &path,
        &test_image(),
        &test_metadata(),
        &ExrOptions::default(),
    )
    .unwrap();

    let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    let header = &meta.headers[0];
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let expected = [
        "B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "normal.X", "normal.Y",
        "normal.Z",
    ];
    assert_eq!(names, expected);
    assert!(header
        .channels
        .list
        .iter()
        .all(|c| c.sample_type == SampleType::F32));
    let other = &header.own_attributes.other;
    for key in [
        "radcache.method",
        "radcache.spp",
        "radcache.renderTime",
        "radcache.sceneFile",
        "radcache.worldFromCamera",
        "radcache.projection",
        "radcache.version",
        "radcache.extra.frame",
    ] {
        assert!(other.contains_key(&exr::prelude::Text::from(key)), "{key}");
    }
}

#[test]
fn f16_round_trip_is_within_half_precision() {
    let dir = scratch_dir("f16_round_trip");
    let path = dir.join("half.exr");
    let rgb: Vec<f32> = (0..4 * 4 * 3).map(|i| (i as f32 - 10.0) * 0.731).collect();
    let image = Image::from_rgb(4, 4, rgb.clone())
        .unwrap()
        .with_layer(Layer::depth(
            (0..16).map(|i| 100.0 + i as f32 * 0.01).collect(),
        ))
        .unwrap();
    let options = ExrOptions {
        half: true,
        ..ExrOptions::default()
    };
    write_exr(&path, &image, &Metadata::new(), &options).unwrap();

    let header = &exr::meta::MetaData::read_from_file(&path, false)
        .unwrap()
        .headers[0];
    assert!(header
        .channels
        .list
        .iter()
        .all(|c| c.sample_type == SampleType::F16));
    let (back, meta) = read_exr(&path).unwrap();
    assert_eq!(meta, Metadata::new());
    // f16 has an 11-bit significand: rounding error ≤ 2^-11 relative (normal range).
    let close = |a: f32, b: f32| (a - b).abs() <= a.abs() * 2f32.powi(-11);
    for (a, b) in rgb.iter().zip(back.rgb()) {
        assert!(close(*a, *b), "{a} vs {b}");
    }
    let depth = image.layer("depth").unwrap().data();
    for (a, b) in depth.iter().zip(back.layer("depth").unwrap().data()) {
        assert!(close(*a, *b), "{a} vs {b}");
    }
}

#[test]
fn aovs_can_be_left_out() {
    let dir = scratch_dir("no_aovs");
    let path = dir.join("beauty.exr");
    let options = ExrOptions {
        aovs: false,
        ..ExrOptions::default()
    };
    write_exr(&path, &test_image(), &Metadata::default(), &options).unwrap();
    let (back, meta) = read_exr(&path).unwrap();
    assert!(back.layers().is_empty());
    assert_eq!(meta, Metadata::default());
}

#[test]
fn write_into_missing_directory_is_a_clear_error() {
    let dir = scratch_dir("missing_dir");
    let path = dir.join("no/such/dir/frame.exr");
    let err = write_exr(
        &path,
        &test_image(),
        &Metadata::new(),
        &ExrOptions::default(),
    )
    .unwrap_err();
    let message = err.to_string();
    assert!(matches!(err, Error::Io { .. }), "{message}");
    assert!(message.contains("no/such/dir/frame.exr"), "{message}");
    assert!(!path.exists());
    assert!(entries(&dir).is_empty());
}

#[test]
fn final_path_appears_only_after_success() {
    let dir = scratch_dir("atomic");
    let path = dir.join("out.bin");
    write_atomic(&path, |file| {
        use std::io::Write;
        file.write_all(b"partial").unwrap();
        // Mid-write: the final path does not exist yet, only a hidden temporary file does.
        assert!(!path.exists());
        let names = entries(&dir);
        assert_eq!(names.len(), 1);
        assert!(names[0].starts_with(".out.bin.") && names[0].ends_with(".tmp"));
        file.write_all(b" and complete").unwrap();
        Ok(())
    })
    .unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"partial and complete");
    assert_eq!(entries(&dir), ["out.bin"]);

    // A failing write leaves the previous file untouched and no temporary file behind.
    let failed = write_atomic(&path, |file| {
        use std::io::Write;
        file.write_all(b"garbage").unwrap();
        Err(Error::InvalidImage("simulated failure".into()))
    });
    assert!(failed.is_err());
    assert_eq!(std::fs::read(&path).unwrap(), b"partial and complete");
    assert_eq!(entries(&dir), ["out.bin"]);
}

#[test]
fn failed_rename_names_the_destination_and_removes_the_temporary_file() {
    let dir = scratch_dir("rename_fails");
    // A non-empty directory at the destination: the final rename fails.
    let path = dir.join("frame.exr");
    std::fs::create_dir(&path).unwrap();
    std::fs::write(path.join("keep"), b"x").unwrap();
    let err = write_atomic(&path, |file| {
        use std::io::Write;
        file.write_all(b"complete").map_err(|source| Error::Io {
            op: "cannot write",
            path: path.clone(),
            source,
        })
    })
    .unwrap_err();
    let message = err.to_string();
    assert!(matches!(err, Error::Io { .. }), "{message}");
    assert!(message.contains("cannot rename"), "{message}");
    assert!(message.contains(&path.display().to_string()), "{message}");
    assert_eq!(entries(&dir), ["frame.exr"]);
    assert_eq!(entries(&path), ["keep"]);
}

#[cfg(unix)]
#[test]
fn atomic_files_get_the_permissions_of_a_plain_create() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch_dir("permissions");
    let plain = dir.join("plain");
    std::fs::File::create(&plain).unwrap();
    let atomic = dir.join("atomic");
    write_atomic(&atomic, |_| Ok(())).unwrap();
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&atomic), mode(&plain));
}

/// The full error chain, cause by cause, as anyhow's `{:#}` prints it.
fn chain(e: &dyn std::error::Error) -> String {
    let mut parts = vec![e.to_string()];
    let mut cause = e.source();
    while let Some(c) = cause {
        parts.push(c.to_string());
        cause = c.source();
    }
    parts.join(": ")
}

#[test]
fn error_chains_name_each_cause_once() {
    let dir = scratch_dir("chains");
    let os = std::fs::read(dir.join("missing")).unwrap_err().to_string();

    let path = dir.join("no/such/dir/frame.exr");
    let options = ExrOptions::default();
    let err = write_exr(&path, &test_image(), &Metadata::new(), &options).unwrap_err();
    let text = chain(&err);
    assert_eq!(text.matches(&os).count(), 1, "{text}");
    assert!(text.contains("no/such/dir/frame.exr"), "{text}");

    // Through the `exr` crate's own I/O error.
    let path = dir.join("missing.exr");
    let text = chain(&read_exr(&path).unwrap_err());
    assert_eq!(text.matches(&os).count(), 1, "{text}");
    assert!(
        text.starts_with(&format!("cannot read EXR '{}'", path.display())),
        "{text}"
    );

    let path = dir.join("no/such/dir/frame.png");
    let err = radcache_image::write_png(&path, &test_image(), &Default::default()).unwrap_err();
    let text = chain(&err);
    assert_eq!(text.matches(&os).count(), 1, "{text}");
}

#[test]
fn rewriting_replaces_the_file() {
    let dir = scratch_dir("rewrite");
    let path = dir.join("frame.exr");
    let meta = Metadata::new();
    write_exr(&path, &test_image(), &meta, &ExrOptions::default()).unwrap();
    let image = Image::from_rgb(1, 1, vec![0.25, 0.5, 0.75]).unwrap();
    write_exr(&path, &image, &meta, &ExrOptions::default()).unwrap();
    assert_eq!(read_exr(&path).unwrap().0, image);
}

fn assert_read_error_names(path: &Path) -> Error {
    let err = read_exr(path).unwrap_err();
    let message = err.to_string();
    assert!(message.contains(&path.display().to_string()), "{message}");
    err
}

#[test]
fn missing_corrupt_and_truncated_files_are_errors() {
    let dir = scratch_dir("bad_files");
    assert_read_error_names(&dir.join("missing.exr"));

    let garbage = dir.join("garbage.exr");
    std::fs::write(&garbage, b"this is not an OpenEXR file at all").unwrap();
    assert_read_error_names(&garbage);

    let good = dir.join("good.exr");
    write_exr(
        &good,
        &test_image(),
        &test_metadata(),
        &ExrOptions::default(),
    )
    .unwrap();
    let bytes = std::fs::read(&good).unwrap();
    for keep in [4, 100, bytes.len() / 2, bytes.len() - 1] {
        let truncated = dir.join(format!("truncated_{keep}.exr"));
        std::fs::write(&truncated, &bytes[..keep]).unwrap();
        assert_read_error_names(&truncated);
    }
    // Flipped bytes in the pixel data and the offset table must not panic either.
    for position in [bytes.len() / 3, bytes.len() / 2, bytes.len() - 8] {
        let mut corrupt = bytes.clone();
        for byte in &mut corrupt[position..position + 8] {
            *byte ^= 0xA5;
        }
        let path = dir.join(format!("corrupt_{position}.exr"));
        std::fs::write(&path, &corrupt).unwrap();
        let _ = read_exr(&path); // an error or (if the damage is benign) an image
    }
}

#[test]
fn exr_without_rgb_is_a_content_error() {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, SmallVec, WritableImage};
    let dir = scratch_dir("no_rgb");
    let path = dir.join("luma.exr");
    let channel = AnyChannel::new("Y", FlatSamples::F32(vec![0.5; 4]));
    let image = exr::image::Image::from_channels(
        (2, 2),
        AnyChannels::sort(SmallVec::from_vec(vec![channel])),
    );
    image.write().to_file(&path).unwrap();

    let err = assert_read_error_names(&path);
    assert!(matches!(err, Error::ExrContent { .. }), "{err}");
    assert!(err.to_string().contains("found: Y"), "{err}");
}
