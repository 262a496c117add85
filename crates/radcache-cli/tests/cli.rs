//! The `radcache` binary end to end on lavapipe: render with metadata, AOVs and stats; compare
//! with limits and JSON; info; bad input gives one clear error (each cause once) and no panic; a
//! warning is printed once; a failed write keeps the frames before it and leaves no partial file.

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
    // The frame's write time is in its entry and in the run's total.
    let write_s = frame["write_s"].as_f64().unwrap();
    assert!(write_s > 0.0, "{frame}");
    assert_eq!(json["cpu_s"]["write"].as_f64(), Some(write_s), "{json}");
    // Device memory by category: at least the scene's buffers (vertices, BVH inputs, ...).
    let memory = frame["device_memory_bytes"].as_object().unwrap();
    assert!(memory["scene"].as_u64().unwrap() > 0, "{memory:?}");
    // The upload's planned peak, its parts adding up to it, and the host's peak.
    let run = &json["memory"];
    let peak = run["upload_peak_device_bytes"].as_u64().unwrap();
    let parts: u64 = run["upload_peak_by_part"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert!(peak > 0 && parts == peak, "{run}");
    assert!(run["peak_host_bytes"].as_u64().unwrap() > 0, "{run}");
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
fn info_names_the_material_model_and_unused_occlusion_once() {
    let out = radcache(&["info", &cornell()]);
    assert_ok(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("materials: lambertian only (no specular code compiled)"),
        "{stdout}"
    );
    assert!(!stdout.contains("occlusion"), "{stdout}");

    let helmet = common::shared_model("DamagedHelmet/glTF-Binary/DamagedHelmet.glb");
    let out = radcache(&["info", &text(&helmet), "--env-radiance", "1,1,1"]);
    assert_ok(&out);
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        all.contains("materials: metallic-roughness BRDF (specular lobes compiled in)"),
        "{all}"
    );
    assert_eq!(occurrences(&all, "occlusion textures"), 1, "{all}");
    assert!(
        all.contains("occlusion textures: not used (1 material; a global-illumination renderer computes occlusion itself)"),
        "{all}"
    );
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

/// How often `needle` occurs in `haystack`.
fn occurrences(haystack: &str, needle: &str) -> usize {
    haystack.matches(needle).count()
}

#[test]
fn a_missing_scene_is_named_with_its_cause_once() {
    let dir = out_dir("missing");
    let out = radcache(&[
        "render",
        "/nonexistent.gltf",
        "-o",
        &text(&dir.join("x.exr")),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("/nonexistent.gltf"), "{stderr}");
    assert_eq!(
        occurrences(&stderr, "No such file or directory"),
        1,
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!dir.join("x.exr").exists());
}

#[test]
fn a_loader_warning_is_printed_once() {
    // The Cornell box without its camera: the loader warns and frames the scene itself.
    let dir = out_dir("warning");
    let source = common::repo().join("assets/cornell");
    let mut gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(source.join("cornell.gltf")).unwrap())
            .unwrap();
    for node in gltf["nodes"].as_array_mut().unwrap() {
        node.as_object_mut().unwrap().remove("camera");
    }
    let scene = dir.join("no_camera.gltf");
    std::fs::write(&scene, serde_json::to_string(&gltf).unwrap()).unwrap();
    std::fs::copy(source.join("cornell.bin"), dir.join("cornell.bin")).unwrap();
    let warning = "has no camera";

    let out = radcache(&[
        "render",
        &text(&scene),
        "-o",
        &text(&dir.join("x.exr")),
        "--method",
        "path",
        "--resolution",
        "8x8",
        "--spp",
        "1",
    ]);
    assert_ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(occurrences(&stderr, warning), 1, "{stderr}");

    let out = radcache(&["info", &text(&scene)]);
    assert_ok(&out);
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(occurrences(&all, warning), 1, "{all}");
}

#[test]
fn a_failed_write_keeps_the_frames_before_it_and_no_partial_file() {
    let dir = out_dir("write_failure");
    // Frame 2's output path is a folder: its EXR cannot be put there.
    let blocked = dir.join("f_0002.exr");
    std::fs::create_dir(&blocked).unwrap();
    let stats = dir.join("stats.json");
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&dir.join("f_####.exr")),
        "--frames",
        "1..3",
        "--overwrite",
        "--method",
        "path",
        "--resolution",
        "8x8",
        "--spp",
        "1",
        "--stats",
        &text(&stats),
        "-q",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("f_0002.exr"), "{stderr}");
    assert_eq!(occurrences(&stderr, "Is a directory"), 1, "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // Frame 1 is whole, frame 3 was not started, nothing else is left in the folder.
    let (image, _) = read_exr(dir.join("f_0001.exr")).unwrap();
    assert_eq!((image.width(), image.height()), (8, 8));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["f_0001.exr", "f_0002.exr", "stats.json"]);
    assert!(std::fs::read_dir(&blocked).unwrap().next().is_none());
    // The stats file describes the frame written, its write time included in the total.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let frames = json["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 1, "{json}");
    let write_s = frames[0]["write_s"].as_f64().unwrap();
    assert!(
        write_s > 0.0 && json["cpu_s"]["write"].as_f64() == Some(write_s),
        "{json}"
    );
}
