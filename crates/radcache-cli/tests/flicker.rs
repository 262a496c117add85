//! `radcache flicker` end to end on small EXR sequences with hand-computed answers: frames found
//! on disk, `--frames`, `--reference`, AOV-based static pixels, JSON and table output, and bad
//! input giving one clear error.

use std::path::{Path, PathBuf};

use radcache_image::{write_exr, ExrOptions, Image, Layer, Metadata};
use serde_json::Value;

mod common;
use common::{fresh_dir, radcache, text};

/// A fresh, empty directory for one test.
fn out_dir(name: &str) -> PathBuf {
    fresh_dir("flicker", name)
}

/// Writes a 2×1 frame with grey pixels `values` and, when given, a depth AOV.
fn write_frame(path: &Path, values: [f32; 2], depth: Option<[f32; 2]>) {
    let mut image = Image::from_pixels(2, 1, values.iter().map(|&v| [v; 3]).collect()).unwrap();
    if let Some(depth) = depth {
        image.add_layer(Layer::depth(depth.to_vec())).unwrap();
    }
    write_exr(path, &image, &Metadata::default(), &ExrOptions::default()).unwrap();
}

/// Runs `radcache flicker ARGS --json` and parses its output.
fn flicker_json(args: &[&str]) -> Value {
    let out = radcache(&[&["flicker"], args, &["--json"]].concat());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "radcache failed: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

/// Runs `radcache flicker ARGS`, which must fail with one clear error; returns stderr.
fn flicker_error(args: &[&str]) -> String {
    let out = radcache(&[&["flicker"], args].concat());
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "radcache succeeded: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

fn assert_close(value: &Value, expected: f64) {
    let v = value
        .as_f64()
        .unwrap_or_else(|| panic!("{value} is not a number"));
    assert!((v - expected).abs() < 1e-9, "{v} != {expected}");
}

/// `[[from, to], ...]` of the report.
fn pair_frames(report: &Value) -> Vec<[u64; 2]> {
    let pairs = report["pairs"].as_array().unwrap();
    let frame = |p: &Value, k: &str| p[k].as_u64().unwrap();
    pairs
        .iter()
        .map(|p| [frame(p, "from"), frame(p, "to")])
        .collect()
}

#[test]
fn static_flicker_of_the_frames_on_disk() {
    let dir = out_dir("static");
    // Grey frames 1, 7, 7 (as frames 2, 9, 10): pair 2→9 has E = 6·6², S = 6·(1+49)/2 → 1.2;
    // 9→10 is 0; overall sqrt(216 / (150 + 294)) = 6/√74.
    for (frame, value) in [(2, 1.0), (9, 7.0), (10, 7.0)] {
        write_frame(&dir.join(format!("seq_{frame}.exr")), [value; 2], None);
    }
    // Not frames of `seq_#.exr`; they are not EXRs either, so reading one would fail.
    for name in [
        "seq_x.exr",
        "seq_03.exr",
        "seq_4.exr.tmp",
        ".seq_5.exr.1.0.tmp",
        "q_6.exr",
    ] {
        std::fs::write(dir.join(name), "not an EXR").unwrap();
    }
    let pattern = text(&dir.join("seq_#.exr"));
    let report = flicker_json(&[&pattern]);
    assert_eq!(report["mode"], "static");
    assert_eq!(report["frames"], serde_json::json!([2, 9, 10]));
    assert_eq!(pair_frames(&report), [[2, 9], [9, 10]]);
    assert_close(&report["pairs"][0]["flicker"], 1.2);
    assert_close(&report["pairs"][1]["flicker"], 0.0);
    assert_close(&report["flicker"], 6.0 / 74.0_f64.sqrt());
    assert_close(&report["pairs"][0]["static_fraction"], 1.0);
    assert_eq!(report["pairs"][0]["nonfinite"], 0);

    let report = flicker_json(&[&pattern, "--frames", "9..10"]);
    assert_eq!(report["frames"], serde_json::json!([9, 10]));
    assert_close(&report["flicker"], 0.0);

    let out = radcache(&["flicker", &pattern]);
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("mode static") && table.contains("1.200000"),
        "{table}"
    );
    assert!(table.lines().last().unwrap().contains("overall"), "{table}");
}

#[test]
fn reference_flicker_with_and_without_frame_range() {
    let dir = out_dir("reference");
    // The reference's pixels swap 1 and 3 every frame (motion); the candidate adds offsets
    // o = 0, 0.5, 0.25, 5 per frame: E_t = 6·(Δo)², S_t = 3·(1+9+9+1)/2 = 30, so
    // flicker_t = |Δo|/√5 and, over frames 1..3, overall sqrt(6·(0.25+0.0625)/60).
    for (frame, offset) in [(1, 0.0), (2, 0.5), (3, 0.25), (4, 5.0)] {
        let r = if frame % 2 == 1 {
            [1.0, 3.0]
        } else {
            [3.0, 1.0]
        };
        write_frame(&dir.join(format!("ref_{frame:02}.exr")), r, None);
        let c = r.map(|v| v + offset);
        write_frame(&dir.join(format!("cand_{frame:02}.exr")), c, None);
    }
    let candidate = text(&dir.join("cand_##.exr"));
    let reference = text(&dir.join("ref_##.exr"));
    let sqrt5 = 5.0_f64.sqrt();

    let report = flicker_json(&[&candidate, "--reference", &reference, "--frames", "1..3"]);
    assert_eq!(report["mode"], "reference");
    assert_eq!(report["frames"], serde_json::json!([1, 2, 3]));
    assert_eq!(pair_frames(&report), [[1, 2], [2, 3]]);
    assert_close(&report["pairs"][0]["flicker"], 0.5 / sqrt5);
    assert_close(&report["pairs"][1]["flicker"], 0.25 / sqrt5);
    assert_close(&report["flicker"], 0.03125_f64.sqrt());
    assert_close(&report["static_fraction"], 1.0);

    // Without --frames all four frames are found; the last pair adds |5 − 0.25|/√5.
    let report = flicker_json(&[&candidate, "--reference", &reference]);
    assert_eq!(report["frames"], serde_json::json!([1, 2, 3, 4]));
    assert_close(&report["pairs"][2]["flicker"], 4.75 / sqrt5);
    let total: f64 = 6.0 * (0.25 + 0.0625 + 4.75 * 4.75) / 90.0;
    assert_close(&report["flicker"], total.sqrt());

    // The reference against itself: motion is not flicker.
    let report = flicker_json(&[&reference, "--reference", &reference]);
    assert_close(&report["flicker"], 0.0);
}

#[test]
fn pixels_whose_depth_changes_are_left_out() {
    let dir = out_dir("aov");
    // Pixel 0: same depth, 1 → 3; pixel 1: depth 1 → 2 (another surface), 5 → 0. Only pixel 0
    // counts: E = 3·4, S = 3·(1+9)/2, flicker = sqrt(0.8).
    write_frame(&dir.join("f_0.exr"), [1.0, 5.0], Some([1.0, 1.0]));
    write_frame(&dir.join("f_1.exr"), [3.0, 0.0], Some([1.0, 2.0]));
    let report = flicker_json(&[&text(&dir.join("f_#.exr"))]);
    assert_close(&report["flicker"], 0.8_f64.sqrt());
    assert_close(&report["pairs"][0]["static_fraction"], 0.5);
    assert_close(&report["static_fraction"], 0.5);
}

#[test]
fn bad_input_is_one_clear_error() {
    let dir = out_dir("errors");
    write_frame(&dir.join("seq_1.exr"), [1.0; 2], None);
    write_frame(&dir.join("seq_2.exr"), [2.0; 2], None);
    let pattern = text(&dir.join("seq_#.exr"));

    // Frame 3 of 1..3 is missing: the message names its file.
    let err = flicker_error(&[&pattern, "--frames", "1..3"]);
    assert!(err.contains(&text(&dir.join("seq_3.exr"))), "{err}");
    // A reference frame is missing.
    let err = flicker_error(&[&pattern, "--reference", &text(&dir.join("r_#.exr"))]);
    assert!(err.contains(&text(&dir.join("r_1.exr"))), "{err}");
    // A single frame on disk.
    write_frame(&dir.join("one_7.exr"), [1.0; 2], None);
    let single = text(&dir.join("one_#.exr"));
    let err = flicker_error(&[&single]);
    assert!(err.contains(&single) && err.contains("at least 2"), "{err}");
    // Frames of different sizes.
    let big = Image::new(3, 3);
    write_exr(
        dir.join("seq_5.exr"),
        &big,
        &Metadata::default(),
        &ExrOptions::default(),
    )
    .unwrap();
    let err = flicker_error(&[&pattern]);
    assert!(err.contains("seq_5.exr") && err.contains("3x3"), "{err}");
    // Malformed options and patterns.
    let err = flicker_error(&[&pattern, "--frames", "5..x"]);
    assert!(err.contains("--frames") && err.contains("5..x"), "{err}");
    let err = flicker_error(&[&text(&dir.join("seq.exr"))]);
    assert!(err.contains("seq.exr") && err.contains('#'), "{err}");
}
