//! The persistent pipeline cache on lavapipe: a second context over the same folder finds every
//! pipeline the first one created, counted honestly for the driver; a corrupt, truncated or
//! foreign file is ignored with exactly one warning naming it, and replaced.

mod common;

use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use radcache_vk::{Context, ContextOptions, PipelineStats};

/// Bytes of Vulkan's pipeline cache header: a driver's data of this size holds no pipeline.
const VK_HEADER: u64 = 32;

/// Every warning logged by this test binary (tests run in parallel: filter by file name).
static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata<'_>) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record<'_>) {
        if self.enabled(r.metadata()) {
            WARNINGS.lock().unwrap().push(r.args().to_string());
        }
    }
    fn flush(&self) {}
}

fn capture_warnings() {
    static ONCE: OnceLock<()> = OnceLock::new();
    ONCE.get_or_init(|| {
        log::set_logger(&Capture).expect("no other logger in this test binary");
        log::set_max_level(log::LevelFilter::Warn);
    });
}

/// The warnings logged so far that mention `path`.
fn warnings_about(path: &Path) -> Vec<String> {
    let name = path.display().to_string();
    let all = WARNINGS.lock().unwrap();
    all.iter().filter(|w| w.contains(&name)).cloned().collect()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radcache-pcache-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn context_in(dir: &Path) -> Context {
    capture_warnings();
    let mut opts = ContextOptions::from_env();
    opts.validation = !matches!(
        std::env::var("RADCACHE_VALIDATION").as_deref(),
        Ok("0") | Ok("false") | Ok("off") | Ok("no")
    );
    opts.pipeline_cache_dir = Some(dir.to_path_buf());
    Context::with_options(&opts).expect("context")
}

/// A context over `dir` that creates the test pipelines and shuts down: its pipeline counts,
/// its cache file and the warning it gave about the file.
fn run(dir: &Path) -> (PipelineStats, PathBuf, Option<String>) {
    let ctx = context_in(dir);
    let compiler = common::compiler();
    let fill = common::fill_pipeline(&ctx, &compiler);
    let tri = common::tri_pipeline(&ctx, &compiler);
    let stats = ctx.pipeline_stats();
    let file = ctx
        .pipeline_cache_file()
        .expect("a cache file")
        .to_path_buf();
    let warning = ctx.pipeline_cache_warning().map(str::to_string);
    drop((fill, tri));
    common::finish(ctx);
    (stats, file, warning)
}

/// What a context that found both pipelines in its cache reports: hits where the driver's cache
/// holds pipelines, compiled from scratch where it is a stub (lavapipe).
fn assert_found_both(stats: &PipelineStats) {
    assert_eq!(stats.created, 2);
    assert_eq!(stats.indexed, 2, "{stats:?}");
    if stats.driver_cache_bytes > VK_HEADER {
        assert_eq!(stats.compiled_from_scratch, 0, "{stats:?}");
        assert_eq!(stats.cache_hits, 2, "{stats:?}");
    } else {
        assert_eq!(stats.compiled_from_scratch, 2, "{stats:?}");
    }
}

#[test]
fn a_second_context_finds_every_pipeline_the_first_one_created() {
    let dir = temp_dir("second");
    let (first, file, warning) = run(&dir);
    assert_eq!(warning, None, "a missing file is no warning");
    assert_eq!(first.created, 2);
    assert_eq!(first.compiled_from_scratch, 2);
    assert_eq!(first.indexed, 0);
    assert!(first.creation_s > 0.0);
    assert!(file.is_file(), "saved at shutdown: {}", file.display());
    assert!(file.starts_with(&dir));
    let (second, _, warning) = run(&dir);
    assert_eq!(warning, None);
    assert_found_both(&second);
    assert!(warnings_about(&file).is_empty());
}

#[test]
fn a_pipeline_created_twice_in_one_context_is_indexed_the_second_time() {
    let dir = temp_dir("twice");
    let ctx = context_in(&dir);
    let compiler = common::compiler();
    drop(common::fill_pipeline(&ctx, &compiler));
    drop(common::fill_pipeline(&ctx, &compiler));
    let stats = ctx.pipeline_stats();
    common::finish(ctx);
    assert_eq!((stats.created, stats.indexed), (2, 1), "{stats:?}");
    assert_eq!(stats.compiled_from_scratch + stats.cache_hits, 2);
}

/// Writes `bytes` over the cache file of a folder, then checks that a context ignores it with
/// exactly one warning naming the file and a reason containing `reason`, creates its pipelines,
/// and replaces the file with one the next context uses.
fn check_ignored(name: &str, reason: &str, spoil: impl FnOnce(Vec<u8>) -> Vec<u8>) {
    let dir = temp_dir(name);
    let (_, file, _) = run(&dir);
    let good = std::fs::read(&file).unwrap();
    std::fs::write(&file, spoil(good)).unwrap();
    let (stats, _, warning) = run(&dir);
    let warning = warning.expect("a warning about the file");
    assert!(warning.contains(&file.display().to_string()), "{warning}");
    assert!(warning.contains(reason), "{warning} lacks {reason:?}");
    assert_eq!(warnings_about(&file), vec![warning], "one warning");
    assert_eq!((stats.created, stats.compiled_from_scratch), (2, 2));
    assert_eq!(stats.indexed, 0, "nothing of the ignored file is used");
    let (again, _, warning) = run(&dir);
    assert_eq!(warning, None, "the file was replaced at shutdown");
    assert_found_both(&again);
}

#[test]
fn a_garbage_file_is_ignored_with_one_warning() {
    check_ignored("garbage", "not a radcache pipeline cache", |_| {
        b"GIF89a and then some bytes that are no cache".to_vec()
    });
}

#[test]
fn an_empty_file_is_ignored_with_one_warning() {
    check_ignored("empty", "not a radcache pipeline cache", |_| Vec::new());
}

#[test]
fn a_truncated_file_is_ignored_with_one_warning() {
    check_ignored("truncated", "truncated", |mut b| {
        b.truncate(b.len() - 5);
        b
    });
}

#[test]
fn a_file_with_a_bad_checksum_is_ignored_with_one_warning() {
    check_ignored("checksum", "checksum", |mut b| {
        let last = b.len() - 1;
        b[last] ^= 0x5a;
        b
    });
}

#[test]
fn another_devices_file_is_ignored_with_one_warning() {
    // Bytes 24..40 of radcache's header hold the device's pipelineCacheUUID.
    check_ignored("foreign", "another device or driver", |mut b| {
        b[30] ^= 0xff;
        b
    });
}

#[test]
fn an_unusable_folder_costs_warnings_not_errors() {
    let dir = temp_dir("unusable");
    let not_a_dir = dir.join("plain-file");
    std::fs::write(&not_a_dir, b"x").unwrap();
    let (stats, file, warning) = run(&not_a_dir);
    assert_eq!((stats.created, stats.compiled_from_scratch), (2, 2));
    assert!(warning.is_some_and(|w| w.contains(&file.display().to_string())));
    // The failed save at shutdown is a warning as well.
    let about = warnings_about(&file);
    assert!(
        about.iter().any(|w| w.starts_with("not saving")),
        "{about:?}"
    );
}
