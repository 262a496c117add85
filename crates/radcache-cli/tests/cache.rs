//! Cache files end to end on lavapipe: `render --cache-out` then `--cache-in` of the same view
//! creates (nearly) no record; `cache info` prints the header; a file of another scene or other
//! parameters is refused with one error naming the file; `cache build` refuses a scene whose
//! geometry moves; and the prepass over the static Cornell box fly-through cuts the records
//! created while rendering by at least 80 % at no worse error against a path-traced reference.

use std::path::{Path, PathBuf};
use std::process::Output;

use radcache_image::{compare, read_exr};
use serde_json::Value;

mod common;
use common::{cornell, fresh_dir, radcache, repo, text};

fn out_dir(name: &str) -> PathBuf {
    fresh_dir("cache", name)
}

fn assert_ok(out: &Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "radcache failed: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// The one error line of a failed run (no panic).
fn error_of(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "expected a failure: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    errors[0].to_string()
}

fn fly() -> String {
    text(&repo().join("assets/cornell_fly/cornell_fly.gltf"))
}

fn stats_frames(path: &Path) -> Vec<Value> {
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v["frames"].as_array().unwrap().clone()
}

fn created(frames: &[Value]) -> u64 {
    frames
        .iter()
        .map(|f| f["records_created"].as_u64().unwrap())
        .sum()
}

const SMALL: [&str; 4] = ["--resolution", "40x40", "--quality", "draft"];

#[test]
fn a_cache_file_round_trips_through_render_and_info() {
    let dir = out_dir("roundtrip");
    let cache = dir.join("cornell.rcache");
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    let (sa, sb) = (dir.join("a.json"), dir.join("b.json"));
    let scene = cornell();
    let render = |out: &Path, stats: &Path, extra: &[&str]| {
        let mut args = vec!["render", &scene, "-q"];
        let (o, s) = (text(out), text(stats));
        args.extend(["-o", &o, "--stats", &s]);
        args.extend(SMALL);
        args.extend(extra);
        radcache(&args)
    };
    assert_ok(&render(&a, &sa, &["--cache-out", &text(&cache)]));
    assert_ok(&render(&b, &sb, &["--cache-in", &text(&cache)]));
    let (first, second) = (stats_frames(&sa), stats_frames(&sb));
    let records = first[0]["records"].as_u64().unwrap();
    assert!(records > 50, "{records}");
    // The same view from the file's records: they are re-clamped to it, which may uncover a
    // pixel or two, and nothing else is created.
    let again = created(&second);
    assert!(
        again * 50 <= records,
        "{again} records created over {records} loaded"
    );
    assert_eq!(second[0]["records_kept"].as_u64(), Some(records));

    let out = radcache(&["cache", "info", &text(&cache)]);
    assert_ok(&out);
    let info = String::from_utf8_lossy(&out.stdout);
    assert!(info.contains(&format!("records: {records}")), "{info}");
    assert!(
        info.contains("settings: 40x40") && info.contains("checksums: ok"),
        "{info}"
    );
    let out = radcache(&["cache", "info", &text(&cache), "--json"]);
    assert_ok(&out);
    let json: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["records"].as_u64(), Some(records));
    assert_eq!(json["params"]["accuracy"].as_f64(), Some(0.3));
    assert_eq!(json["format_version"].as_u64(), Some(4));
    // Draft: the same strata at every level.
    assert_eq!(json["params"]["fine_strata_m"].as_u64(), Some(8));
    assert_eq!(json["params"]["strata_falloff"].as_u64(), Some(0));
    // The Cornell box has no glossy lobe from the cache: no radiance blocks.
    assert_eq!(json["radiance"].as_bool(), Some(false));
    assert!(info.contains("radiance coefficients: no"), "{info}");
}

#[test]
fn a_file_of_another_scene_or_other_parameters_is_refused_naming_it() {
    let dir = out_dir("refuse");
    let cache = dir.join("cornell.rcache");
    let scene = cornell();
    let mut args = vec!["render", &scene, "-q", "--cache-out"];
    let c = text(&cache);
    let o = text(&dir.join("a.exr"));
    args.extend([c.as_str(), "-o", &o]);
    args.extend(SMALL);
    assert_ok(&radcache(&args));

    let furnace = text(&repo().join("assets/furnace/furnace.gltf"));
    let o = text(&dir.join("b.exr"));
    let mut args = vec!["render", &furnace, "-q", "--cache-in", &c, "-o", &o];
    args.extend(SMALL);
    let line = error_of(&radcache(&args));
    assert!(
        line.contains(&c) && line.contains("another scene"),
        "{line}"
    );
    assert!(
        !dir.join("b.exr").exists(),
        "nothing is rendered from a refused file"
    );

    // Same scene, other cache parameters and another size.
    let args = [
        "render",
        &scene,
        "-q",
        "--cache-in",
        &c,
        "-o",
        &o,
        "--resolution",
        "40x40",
    ];
    let line = error_of(&radcache(&args));
    assert!(
        line.contains(&c) && line.contains("other cache parameters"),
        "{line}"
    );
    assert!(line.contains("accuracy 0.3 (this render: 0.15)"), "{line}");
    let args = [
        "render",
        &scene,
        "-q",
        "--cache-in",
        &c,
        "-o",
        &o,
        "--resolution",
        "32x32",
        "--quality",
        "draft",
    ];
    let line = error_of(&radcache(&args));
    assert!(
        line.contains("made at 40x40, this render is 32x32"),
        "{line}"
    );

    // A file that is not a cache file, and a truncated one.
    let bogus = dir.join("bogus.rcache");
    std::fs::write(&bogus, b"not a cache").unwrap();
    let line = error_of(&radcache(&["cache", "info", &text(&bogus)]));
    assert!(line.contains("bogus.rcache") && line.contains("not a radcache cache file"));
    let bytes = std::fs::read(&cache).unwrap();
    let cut = dir.join("cut.rcache");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let line = error_of(&radcache(&["cache", "info", &text(&cut)]));
    assert!(
        line.contains("cut.rcache") && line.contains("truncated"),
        "{line}"
    );
}

#[test]
fn a_prepass_refuses_a_scene_whose_geometry_moves() {
    let dir = out_dir("moving");
    let animated = text(&repo().join("assets/animated/animated.gltf"));
    let o = text(&dir.join("x.rcache"));
    let line = error_of(&radcache(&[
        "cache", "build", &animated, "-o", &o, "--frames", "1..4", "--every", "2",
    ]));
    assert!(line.contains("animated.gltf") && line.contains("geometry or lights move"));
    assert!(!dir.join("x.rcache").exists());
}

/// The relMSE of `frame` of `dir` against the reference folder's.
fn relmse(reference: &Path, dir: &Path, frame: u32) -> f64 {
    let name = format!("f_{frame:04}.exr");
    let (r, _) = read_exr(reference.join(&name)).unwrap();
    let (c, _) = read_exr(dir.join(&name)).unwrap();
    compare(&r, &c).unwrap().relmse
}

#[test]
fn a_prepass_cuts_the_records_created_by_80_percent_at_equal_error() {
    let dir = out_dir("prepass");
    let cache = text(&dir.join("fly.rcache"));
    let size = ["--resolution", "64x64", "--quality", "draft"];
    let frames = ["--frames", "1..12"];
    let scene = fly();
    let mut build = vec!["cache", "build", &scene, "-o", &cache, "--every", "4", "-q"];
    build.extend(size);
    build.extend(frames);
    assert_ok(&radcache(&build));
    let render = |name: &str, extra: &[&str]| -> Vec<Value> {
        let out = text(&dir.join(name).join("f_####.exr"));
        let stats = text(&dir.join(format!("{name}.json")));
        let mut args = vec!["render", &scene, "-q", "-o", &out, "--stats", &stats];
        args.extend(size);
        args.extend(frames);
        args.extend(extra);
        assert_ok(&radcache(&args));
        stats_frames(&dir.join(format!("{name}.json")))
    };
    let plain = created(&render("plain", &[]));
    let cached = created(&render("cached", &["--cache-in", &cache]));
    assert!(
        cached * 5 <= plain,
        "{cached} records created with the prepass, {plain} without"
    );
    let reference = dir.join("ref");
    let mut error = [0.0, 0.0];
    for frame in [1, 6, 12] {
        let out = text(&reference.join("f_####.exr"));
        let f = frame.to_string();
        let mut args = vec!["render", &scene, "-q", "-o", &out, "--frame", &f];
        args.extend(["--resolution", "64x64", "--method", "path", "--spp", "256"]);
        assert_ok(&radcache(&args));
        error[0] += relmse(&reference, &dir.join("plain"), frame);
        error[1] += relmse(&reference, &dir.join("cached"), frame);
    }
    eprintln!(
        "records created over frames 1..12: {plain} without the prepass, {cached} with; relMSE \
         summed over frames 1, 6, 12: {:.4e} without, {:.4e} with",
        error[0], error[1]
    );
    assert!(
        error[1] <= 1.1 * error[0],
        "relMSE summed over frames 1, 6, 12: {} with the prepass, {} without",
        error[1],
        error[0]
    );
}
