//! The `radcache` binary end to end on lavapipe: render with metadata, AOVs and stats; compare
//! with limits and JSON; info; bad input gives one clear error and no panic.

use std::path::PathBuf;
use std::process::Output;

use radcache_image::read_exr;

mod common;
use common::{cornell, fresh_dir, radcache, text};

fn out_dir(name: &str) -> PathBuf {
    fresh_dir("cli", name)
}

fn assert_ok(out: &Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "radcache failed: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn render_writes_exr_with_metadata_aovs_png_and_stats() {
    let dir = out_dir("render");
    let exr = dir.join("frame_####.exr");
    let stats = dir.join("stats.json");
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&exr),
        "--method",
        "path",
        "--resolution",
        "24x16",
        "--spp",
        "3",
        "--seed",
        "5",
        "--frame",
        "7",
        "--aov",
        "--png",
        "--stats",
        &text(&stats),
        "-q",
    ]);
    assert_ok(&out);
    let written = dir.join("frame_0007.exr");
    let (image, meta) = read_exr(&written).unwrap();
    assert_eq!((image.width(), image.height()), (24, 16));
    assert_eq!(meta.method.as_deref(), Some("path"));
    assert_eq!(meta.spp, Some(3));
    assert!(meta.render_time_s.is_some_and(|t| t > 0.0));
    assert!(meta.scene_file.unwrap().ends_with("cornell.gltf"));
    assert!(meta.world_from_camera.is_some() && meta.projection.is_some());
    assert!(meta.radcache_version.is_some());
    for layer in ["albedo", "normal", "depth"] {
        assert!(image.layer(layer).is_some(), "missing AOV layer {layer}");
    }
    assert!(image
        .pixels()
        .all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
    assert!(dir.join("frame_0007.png").exists());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let frame = &json["frames"][0];
    assert_eq!(frame["frame"], 7);
    assert!(frame["time_s"].as_f64().unwrap() > 0.0);
    // At least one camera ray per pixel sample.
    assert!(frame["rays"]["path_trace"].as_u64().unwrap() >= 24 * 16 * 3);
    assert!(frame["passes_ms"]["path_trace"].as_f64().unwrap() > 0.0);
    // Device memory by category: at least the scene's buffers (vertices, BVH inputs, ...).
    let memory = frame["device_memory_bytes"].as_object().unwrap();
    assert!(memory["scene"].as_u64().unwrap() > 0, "{memory:?}");
}

#[test]
fn compare_reports_json_and_enforces_limits() {
    let dir = out_dir("compare");
    let a = dir.join("a.exr");
    let b = dir.join("b.exr");
    for (path, seed) in [(&a, "1"), (&b, "2")] {
        let out = radcache(&[
            "render",
            &cornell(),
            "-o",
            &text(path),
            "--method",
            "path",
            "--resolution",
            "16x16",
            "--spp",
            "2",
            "--seed",
            seed,
            "-q",
        ]);
        assert_ok(&out);
    }
    let same = radcache(&["compare", &text(&a), &text(&a), "--json", "--max-rmse", "0"]);
    assert_ok(&same);
    let json: serde_json::Value = serde_json::from_slice(&same.stdout).unwrap();
    assert_eq!(json["metrics"]["rmse"].as_f64(), Some(0.0));
    assert_eq!(json["exceeded"].as_array().map(Vec::len), Some(0));

    let differ = radcache(&["compare", &text(&a), &text(&b), "--json", "--max-rmse", "0"]);
    assert!(
        !differ.status.success(),
        "different seeds should exceed RMSE 0"
    );
    let json: serde_json::Value = serde_json::from_slice(&differ.stdout).unwrap();
    assert!(json["metrics"]["rmse"].as_f64().unwrap() > 0.0);
    assert_eq!(json["exceeded"].as_array().map(Vec::len), Some(1));
}

#[test]
fn info_prints_the_plan() {
    let out = radcache(&["info", &cornell()]);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout).to_lowercase();
    assert!(stdout.contains("triangles"), "{stdout}");
    assert!(stdout.contains("emissive"), "{stdout}");
    assert!(stdout.contains("plan"), "{stdout}");
}

#[test]
fn bad_input_is_one_clear_error() {
    let dir = out_dir("bad");
    let missing = dir.join("nope.gltf");
    let out = radcache(&[
        "render",
        &text(&missing),
        "-o",
        &text(&dir.join("x.exr")),
        "-q",
    ]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("nope.gltf") && !stderr.contains("panicked"),
        "{stderr}"
    );

    let garbage = dir.join("garbage.gltf");
    std::fs::write(&garbage, b"{ not json").unwrap();
    let out = radcache(&[
        "render",
        &text(&garbage),
        "-o",
        &text(&dir.join("y.exr")),
        "-q",
    ]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("garbage.gltf") && !stderr.contains("panicked"),
        "{stderr}"
    );
    assert!(!dir.join("y.exr").exists());

    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&dir.join("z.exr")),
        "--resolution",
        "0x10",
        "-q",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--resolution"));
}

#[test]
fn profile_writes_a_chrome_trace_and_prints_the_pass_table() {
    let dir = out_dir("profile");
    let trace = dir.join("trace.json");
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&dir.join("f_####.exr")),
        "--frames",
        "1..2",
        "--resolution",
        "24x24",
        "--quality",
        "draft",
        "--sub-frames",
        "2",
        "--profile",
        &text(&trace),
    ]);
    assert_ok(&out);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let events = json["traceEvents"].as_array().unwrap();
    let named = |n: &str| events.iter().filter(|e| e["name"] == n).count();
    // Track names, host work outside and inside frames, GPU passes of both frames.
    assert_eq!(named("thread_name"), 2);
    for host in [
        "scene load",
        "upload + acceleration structures",
        "write",
        "frame 1",
    ] {
        assert!(named(host) >= 1, "no {host:?} event");
    }
    let gpu: Vec<&serde_json::Value> = events.iter().filter(|e| e["cat"] == "gpu").collect();
    for pass in ["gbuffer", "records", "splat", "composite"] {
        assert!(
            gpu.iter().any(|e| e["name"] == pass),
            "no GPU {pass:?} span"
        );
    }
    assert!(gpu.iter().any(|e| e["args"]["frame"] == 2));
    assert!(events
        .iter()
        .filter(|e| e["ph"] == "X")
        .all(|e| e["ts"].as_f64().unwrap() >= 0.0 && e["dur"].as_f64().unwrap() >= 0.0));
    // Frame 2 starts after frame 1 ends.
    let start = |n: &str| {
        let e = events.iter().find(|e| e["name"] == n).unwrap();
        (e["ts"].as_f64().unwrap(), e["dur"].as_f64().unwrap())
    };
    let ((t1, d1), (t2, _)) = (start("frame 1"), start("frame 2"));
    assert!(
        t2 >= t1 + d1,
        "frame 2 at {t2} µs, frame 1 ends at {}",
        t1 + d1
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("Mrays/s") && stderr.contains("records "),
        "{stderr}"
    );
}
