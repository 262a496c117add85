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

/// The macros a shader tests with `#ifdef`, `#ifndef` or `defined(…)` in `text`.
fn tested_macros(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines().map(str::trim_start) {
        let Some(directive) = line.strip_prefix('#') else {
            continue;
        };
        let directive = directive.trim_start();
        let ident = |s: &str| -> String {
            s.trim_start()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect()
        };
        if let Some(rest) = directive
            .strip_prefix("ifdef")
            .or_else(|| directive.strip_prefix("ifndef"))
        {
            out.insert(ident(rest));
        } else if directive.starts_with("if") || directive.starts_with("elif") {
            for part in directive.split("defined").skip(1) {
                out.insert(ident(part.trim_start().trim_start_matches('(')));
            }
        }
    }
    out.remove("");
    out
}

/// The macros `text` defines itself (`#define X`).
fn defined_macros(text: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix('#'))
        .filter_map(|d| d.trim_start().strip_prefix("define"))
        .map(|rest| {
            rest.trim_start()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect()
        })
        .collect()
}

#[test]
fn macros_are_found_in_directives() {
    let text = "#ifdef A\n  #ifndef B_GLSL\n#define B_GLSL\n#if defined(C) && !defined( D )\n\
                #elif defined E\n#endif\nint defined_here;\n";
    assert_eq!(
        tested_macros(text),
        ["A", "B_GLSL", "C", "D", "E"].map(String::from).into()
    );
    assert_eq!(defined_macros(text), ["B_GLSL"].map(String::from).into());
}

/// Every macro the passes' shaders test is set by some module of some pass variant
/// (`every_shader_module`, which `cargo xtask shaders` compiles and validates), unless the
/// shaders define it themselves (include guards, a shader's own switches): a define that no
/// variant sets is a variant the validation never sees. Each module names an entry shader.
#[test]
fn every_macro_the_pass_shaders_test_is_set_by_some_variant() {
    let root = shader_root();
    let (mut tested, mut defined) = (BTreeSet::new(), BTreeSet::new());
    for path in files_under(&root).unwrap() {
        let text = std::fs::read_to_string(root.join(&path)).unwrap();
        defined.extend(defined_macros(&text));
        if !path.starts_with("tests/") {
            tested.extend(tested_macros(&text));
        }
    }
    for m in [
        "HAS_SPECULAR",
        "IC_HESSIAN",
        "DIRECT_COMPOSITE",
        "GBUFFER_REPAIR",
    ] {
        assert!(
            tested.contains(m),
            "{m} not found among the tested macros {tested:?}"
        );
    }
    eprintln!("the pass shaders test {} macros", tested.len());
    let modules = radcache_render::passes::every_shader_module();
    eprintln!("{} modules", modules.len());
    let entries: BTreeSet<String> = radcache_tests::shader_check::entry_shaders(&root)
        .unwrap()
        .into_iter()
        .collect();
    let mut set = BTreeSet::new();
    for m in &modules {
        assert!(entries.contains(m.path), "{}: not an entry shader", m.path);
        set.extend(m.defines.iter().map(|(d, _)| d.to_string()));
    }
    let unset: Vec<&String> = tested
        .iter()
        .filter(|m| !set.contains(*m) && !defined.contains(*m))
        .collect();
    assert!(
        unset.is_empty(),
        "macros the pass shaders test that no variant sets: {unset:?} (set: {set:?})"
    );
    let passes: BTreeSet<&str> = modules.iter().map(|m| m.path).collect();
    let pass_entries: Vec<&String> = entries
        .iter()
        .filter(|p| p.starts_with("passes/"))
        .collect();
    let missing: Vec<&&String> = pass_entries
        .iter()
        .filter(|p| !passes.contains(p.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "pass shaders no pass compiles: {missing:?}"
    );
}
