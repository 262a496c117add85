//! A render's configuration on the command line, end to end on lavapipe: technique switches
//! through `--set KEY=VALUE` (listed by `--set help`; the flags they replaced are refused by
//! name), the resolved configuration in every EXR's metadata and the stats, and
//! `--config-from F.exr` rendering the same configuration and image again.

use std::path::Path;
use std::process::Output;

use radcache_image::read_exr;

mod common;
use common::{cornell, fresh_dir, radcache, text};

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_ok(out: &Output) {
    assert!(out.status.success(), "radcache failed: {}", stderr(out));
    assert!(!stderr(out).contains("panicked"), "{}", stderr(out));
}

/// One clear error (exit 1, no panic) whose text holds every one of `needles`.
fn assert_error(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "no {needle:?} in: {err}");
    }
}

fn config(path: &Path) -> String {
    let (_, meta) = read_exr(path).unwrap();
    meta.extra
        .get("config")
        .cloned()
        .expect("radcache.extra.config")
}

#[test]
fn set_help_lists_every_switch_with_its_default() {
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        "/tmp/unused.exr",
        "--set",
        "help",
    ]);
    assert_ok(&out);
    let help = String::from_utf8_lossy(&out.stdout);
    for line in [
        "sky              records (or direct)",
        "emitters         analytic (or sampled)",
        "emitter_shadows  adaptive (or fixed)",
        "glossy           records (or records-no-gradients, paths)",
        "glossy_spacing   lobe (or irradiance)",
        "splat            once (or per-sub-frame)",
        "path_grid        on (or off)",
        "specular_paths   pooled (or per-pixel)",
    ] {
        assert!(help.contains(line), "no {line:?} in:\n{help}");
    }
}

#[test]
fn bad_switches_and_removed_flags_are_one_clear_error() {
    let scene = cornell();
    let render = |extra: &[&str]| {
        let mut args = vec!["render", scene.as_str(), "-o", "/tmp/unused.exr"];
        args.extend_from_slice(extra);
        radcache(&args)
    };
    assert_error(
        &render(&["--sky", "direct"]),
        &["`--sky`", "--set sky=VALUE"],
    );
    assert_error(
        &render(&["--emitter-shadows=fixed"]),
        &["`--emitter-shadows`", "--set emitter_shadows=VALUE"],
    );
    assert_error(
        &render(&["--set", "sky=nowhere"]),
        &[
            "--set sky=nowhere",
            "`sky` has no value `nowhere`",
            "records, direct",
        ],
    );
    assert_error(
        &render(&["--set", "skies=direct"]),
        &["no technique switch `skies`", "specular_paths"],
    );
    assert_error(&render(&["--set", "sky"]), &["--set \"sky\"", "KEY=VALUE"]);
    // The same switches reach `convergence` and `cache build`, checked before any work.
    let dir = fresh_dir("config", "others");
    let out = radcache(&[
        "convergence",
        &scene,
        "-o",
        &text(&dir),
        "--set",
        "splat=twice",
    ]);
    assert_error(&out, &["--set splat=twice", "once, per-sub-frame"]);
    let cache = text(&dir.join("c.rcache"));
    let out = radcache(&[
        "cache",
        "build",
        &scene,
        "-o",
        &cache,
        "--set",
        "glossy=mirror",
    ]);
    assert_error(&out, &["--set glossy=mirror", "records-no-gradients"]);
    let missing = fresh_dir("config", "missing").join("none.exr");
    assert_error(
        &render(&["--config-from", &text(&missing)]),
        &["--config-from", "none.exr"],
    );
}

#[test]
fn config_from_an_exr_renders_the_same_configuration_and_image() {
    let dir = fresh_dir("config", "round-trip");
    let (first, again, later) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("c.exr"));
    let stats = dir.join("a.json");
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&first),
        "--resolution",
        "24x16",
        "--quality",
        "high",
        "--sub-frames",
        "2",
        "--aa-target",
        "0",
        "--set",
        "emitters=sampled",
        "--set",
        "emitter_shadows=fixed",
        "--set",
        "specular_paths=per-pixel",
        "--seed",
        "3",
        "--stats",
        &text(&stats),
        "-q",
    ]);
    assert_ok(&out);
    let stored = config(&first);
    for part in [
        "--method ic",
        "--resolution 24x16",
        "--seed 3",
        "--quality high",
        "--sub-frames 2",
        "--aa-target 0",
        "--set emitters=sampled",
        "--set emitter_shadows=fixed",
        "--set specular_paths=per-pixel",
        "--set sky=records",
        "--set splat=once",
    ] {
        assert!(stored.contains(part), "no {part:?} in {stored:?}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(json["config"].as_str(), Some(stored.as_str()));

    // The same configuration from the file alone: the same metadata and the same image.
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&again),
        "--config-from",
        &text(&first),
        "-q",
    ]);
    assert_ok(&out);
    assert_eq!(config(&again), stored);
    let (a, meta_a) = read_exr(&first).unwrap();
    let (b, meta_b) = read_exr(&again).unwrap();
    assert_eq!((b.width(), b.height()), (24, 16));
    assert_eq!(meta_a.extra.get("seed"), meta_b.extra.get("seed"));
    let m = radcache_image::compare(&a, &b).unwrap();
    assert!(m.relmse < 1e-9, "the image differs: relMSE {}", m.relmse);

    // Options after it override it.
    let out = radcache(&[
        "render",
        &cornell(),
        "-o",
        &text(&later),
        "--config-from",
        &text(&first),
        "--set",
        "emitters=analytic",
        "--seed",
        "4",
        "-q",
    ]);
    assert_ok(&out);
    let overridden = config(&later);
    assert!(overridden.contains("--seed 4"), "{overridden}");
    assert!(
        overridden.contains("--set emitters=analytic"),
        "{overridden}"
    );
    assert!(
        overridden.contains("--set emitter_shadows=fixed"),
        "{overridden}"
    );
}
