//! Every entry shader under `shaders/` compiles with the run-time options and passes `spirv-val`.

use radcache_tests::shader_check::{check_all, has_spirv_val};
use radcache_tests::shader_root;

#[test]
fn every_shader_compiles_and_validates() {
    assert!(
        has_spirv_val(),
        "spirv-val not found: install spirv-tools (scripts/setup.sh does)"
    );
    let out = std::env::temp_dir().join(format!("radcache-spv-{}", std::process::id()));
    let results = check_all(&shader_root(), &out, true).unwrap();
    assert!(results.len() >= 4, "found only {} shaders", results.len());
    let failures: Vec<String> = results
        .iter()
        .filter_map(|r| r.error.as_ref().map(|e| format!("{}: {e}", r.path)))
        .collect();
    std::fs::remove_dir_all(&out).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
