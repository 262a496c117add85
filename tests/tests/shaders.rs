//! Every entry shader under `shaders/` compiles with the run-time options and passes `spirv-val`.

use std::collections::BTreeSet;

use radcache_tests::shader_check::{check_all, coverage_errors, files_under, has_spirv_val};
use radcache_tests::shader_root;

/// The extensions of entry shaders (compute, vertex, fragment); `.glsl` files are includes.
const ENTRY_EXTENSIONS: [&str; 3] = ["comp", "vert", "frag"];

#[test]
fn every_shader_compiles_and_validates() {
    assert!(
        has_spirv_val(),
        "spirv-val not found: install spirv-tools (scripts/setup.sh does)"
    );
    let root = shader_root();
    // The expected set, from the directory listing: every file is an entry shader or an include.
    let mut expected = BTreeSet::new();
    for path in files_under(&root).unwrap() {
        let ext = path.rsplit_once('.').map_or("", |(_, e)| e);
        if ENTRY_EXTENSIONS.contains(&ext) {
            expected.insert(path);
        } else {
            assert_eq!(
                ext, "glsl",
                "shaders/{path}: neither an entry shader ({ENTRY_EXTENSIONS:?}) nor an include"
            );
        }
    }
    for dir in ["passes/", "tests/"] {
        assert!(
            expected.iter().any(|p| p.starts_with(dir)),
            "no entry shader found under shaders/{dir}: {expected:?}"
        );
    }
    let out = std::env::temp_dir().join(format!("radcache-spv-{}", std::process::id()));
    let results = check_all(&root, &out, true).unwrap();
    std::fs::remove_dir_all(&out).ok();
    let errors = coverage_errors(&expected, &results);
    assert!(
        errors.is_empty(),
        "{} problem(s) with the {} entry shaders:\n{}",
        errors.len(),
        expected.len(),
        errors.join("\n")
    );
}
