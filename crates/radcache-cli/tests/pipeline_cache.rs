//! `radcache render` twice over one `RADCACHE_PIPELINE_CACHE` folder: the second run's stats
//! find every pipeline of the first in the cache's index (compiled from scratch only where the
//! driver's cache keeps nothing, as on lavapipe) and read every shader from the SPIR-V cache;
//! `RADCACHE_PIPELINE_CACHE=off` keeps nothing between runs.

use std::path::Path;

use serde_json::Value;

mod common;
use common::{bin, cornell, fresh_dir, text};

/// Bytes of Vulkan's pipeline cache header: a driver's data of this size holds no pipeline.
const VK_HEADER: u64 = 32;

/// Renders the Cornell box at 16² with the pipeline cache in `cache` and returns the stats'
/// `pipelines` entry.
fn render(dir: &Path, cache: &str, run: u32) -> Value {
    let stats = dir.join(format!("stats{run}.json"));
    let out = bin()
        .env("RADCACHE_PIPELINE_CACHE", cache)
        .args([
            "render",
            &cornell(),
            "-o",
            &text(&dir.join("frame.exr")),
            "--quality",
            "draft",
            "--resolution",
            "16x16",
            "--stats",
            &text(&stats),
            "-q",
        ])
        .output()
        .expect("running radcache");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "radcache failed: {stderr}");
    assert!(!stderr.contains("pipeline cache"), "no warning: {stderr}");
    let json: Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    json["pipelines"].clone()
}

fn count(v: &Value, field: &str) -> u64 {
    v[field]
        .as_u64()
        .unwrap_or_else(|| panic!("{field} in {v}"))
}

#[test]
fn a_second_render_finds_its_pipelines_and_shaders_in_the_cache() {
    let dir = fresh_dir("pcache", "twice");
    let cache = dir.join("cache");
    let first = render(&dir, &text(&cache), 1);
    let created = count(&first, "created");
    assert!(created >= 5, "{first}");
    assert_eq!(count(&first, "compiled_from_scratch"), created, "{first}");
    assert_eq!(count(&first, "indexed"), 0, "{first}");
    assert!(first["creation_s"].as_f64().unwrap() > 0.0);
    assert!(count(&first["shaders"], "compiled") >= created, "{first}");
    assert_eq!(count(&first["shaders"], "from_disk"), 0);
    let file = first["cache_file"].as_str().expect("a cache file");
    assert!(Path::new(file).starts_with(&cache), "{file}");
    assert!(Path::new(file).is_file(), "saved at exit: {file}");

    let second = render(&dir, &text(&cache), 2);
    assert_eq!(count(&second, "created"), created, "{second}");
    assert_eq!(count(&second, "indexed"), created, "{second}");
    let from_scratch = count(&second, "compiled_from_scratch");
    if count(&second, "driver_cache_bytes") > VK_HEADER {
        assert_eq!(from_scratch, 0, "{second}");
    } else {
        // Lavapipe's pipeline cache keeps nothing: its pipelines are compiled every run.
        assert_eq!(from_scratch, created, "{second}");
    }
    assert_eq!(count(&second["shaders"], "compiled"), 0, "{second}");
    assert_eq!(
        count(&second["shaders"], "from_disk"),
        count(&first["shaders"], "compiled")
    );
}

#[test]
fn the_cache_can_be_turned_off() {
    let dir = fresh_dir("pcache", "off");
    for run in 1..=2 {
        let stats = render(&dir, "off", run);
        assert_eq!(stats["cache_file"], Value::Null, "{stats}");
        assert_eq!(count(&stats, "indexed"), 0, "{stats}");
        assert_eq!(count(&stats["shaders"], "from_disk"), 0, "{stats}");
        assert!(count(&stats["shaders"], "compiled") > 0, "{stats}");
    }
}
