//! The on-disk SPIR-V cache: a second compiler over the same folder reads its modules from disk;
//! an edited include recompiles; a corrupt entry is ignored with one warning naming it and
//! rewritten.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use radcache_vk::ShaderCompiler;

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

fn warnings_about(dir: &Path) -> Vec<String> {
    static ONCE: OnceLock<()> = OnceLock::new();
    ONCE.get_or_init(|| {
        log::set_logger(&Capture).expect("no other logger in this test binary");
        log::set_max_level(log::LevelFilter::Warn);
    });
    let name = dir.display().to_string();
    let all = WARNINGS.lock().unwrap();
    all.iter().filter(|w| w.contains(&name)).cloned().collect()
}

/// A shader root with `main.comp` including `inc.glsl`, and an empty cache folder.
fn setup(name: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("radcache-spirv-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let root = dir.join("shaders");
    std::fs::create_dir_all(&root).unwrap();
    std::fs::write(
        root.join("main.comp"),
        "#version 460\n#include \"inc.glsl\"\nlayout(local_size_x = 1) in;\n\
         layout(binding = 0) buffer B { uint v[]; };\nvoid main() { v[0] = VALUE + N; }\n",
    )
    .unwrap();
    std::fs::write(root.join("inc.glsl"), "#define VALUE 1u\n").unwrap();
    (root, dir.join("cache"))
}

fn compiler(root: &Path, cache: &Path) -> ShaderCompiler {
    warnings_about(cache);
    ShaderCompiler::new(root)
        .unwrap()
        .with_disk_cache(Some(cache))
}

#[test]
fn a_second_compiler_reads_the_module_from_disk() {
    let (root, cache) = setup("second");
    let first = compiler(&root, &cache);
    let a = first.compile("main.comp", &[("N", "2")]).unwrap();
    assert_eq!((first.stats().compiled, first.stats().from_disk), (1, 0));
    let second = compiler(&root, &cache);
    let b = second.compile("main.comp", &[("N", "2")]).unwrap();
    assert_eq!((second.stats().compiled, second.stats().from_disk), (0, 1));
    assert_eq!(a, b);
    // Other defines are another module.
    second.compile("main.comp", &[("N", "3")]).unwrap();
    assert_eq!(second.stats().compiled, 1);
    // In memory the next time.
    second.compile("main.comp", &[("N", "2")]).unwrap();
    assert_eq!(second.stats().reused, 1);
    assert!(warnings_about(&cache).is_empty());
}

#[test]
fn an_edited_include_is_recompiled() {
    let (root, cache) = setup("edited");
    let a = compiler(&root, &cache)
        .compile("main.comp", &[("N", "0")])
        .unwrap();
    std::fs::write(root.join("inc.glsl"), "#define VALUE 7u\n").unwrap();
    let second = compiler(&root, &cache);
    let b = second.compile("main.comp", &[("N", "0")]).unwrap();
    assert_eq!((second.stats().compiled, second.stats().from_disk), (1, 0));
    assert_ne!(a, b);
    // The fresh compile replaced the entry.
    let third = compiler(&root, &cache);
    assert_eq!(third.compile("main.comp", &[("N", "0")]).unwrap(), b);
    assert_eq!(third.stats().from_disk, 1);
}

#[test]
fn a_corrupt_entry_is_ignored_with_one_warning_and_rewritten() {
    let (root, cache) = setup("corrupt");
    let good = compiler(&root, &cache)
        .compile("main.comp", &[("N", "1")])
        .unwrap();
    let entries: Vec<PathBuf> = std::fs::read_dir(cache.join("spirv"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let mut bytes = std::fs::read(&entries[0]).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0xff;
    std::fs::write(&entries[0], &bytes).unwrap();
    let second = compiler(&root, &cache);
    assert_eq!(second.compile("main.comp", &[("N", "1")]).unwrap(), good);
    assert_eq!((second.stats().compiled, second.stats().from_disk), (1, 0));
    let warnings = warnings_about(&cache);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains(&entries[0].display().to_string()));
    assert!(warnings[0].contains("checksum"), "{}", warnings[0]);
    let third = compiler(&root, &cache);
    third.compile("main.comp", &[("N", "1")]).unwrap();
    assert_eq!(
        third.stats().from_disk,
        1,
        "rewritten by the second compile"
    );
    assert_eq!(warnings_about(&cache).len(), 1);
}
