//! The crate's layering, checked: a module of `radcache-render` may use only the layers below
//! its own (the order in `src/lib.rs`'s doc). Every `crate::` path in code is checked, in `use`
//! declarations, `use crate::{…}` groups and inline paths alike, and so is every `super::` chain
//! that climbs out of its top-level module. Comments are not code and are not checked.

use std::path::{Path, PathBuf};

/// The top-level modules from the top down; a module may use those after it. Modules of the
/// same rank may use each other.
const LAYERS: &[(&str, u32)] = &[
    ("frame", 5),
    ("passes", 4),
    ("state", 3),
    ("scene", 2),
    ("bindings", 1),
    ("technique", 0),
    ("error", 0),
];

fn rank(module: &str) -> Option<u32> {
    LAYERS.iter().find(|(m, _)| *m == module).map(|&(_, r)| r)
}

/// The module path of a source file relative to `src/` (`passes/record/push.rs` →
/// `[passes, record, push]`; `state/mod.rs` → `[state]`; `lib.rs` → `[]`).
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if let Some(last) = parts.pop() {
        let stem = last.trim_end_matches(".rs");
        if stem != "mod" && stem != "lib" {
            parts.push(stem.to_string());
        }
    }
    parts
}

/// `text` without `//` comments (line and doc comments) and without the contents of string
/// literals, so that only code remains.
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let mut in_str = false;
        let mut prev = '\0';
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            if in_str {
                if c == '"' && prev != '\\' {
                    in_str = false;
                    out.push(c);
                }
                prev = if prev == '\\' && c == '\\' { '\0' } else { c };
                continue;
            }
            if c == '/' && chars.peek() == Some(&'/') {
                break;
            }
            if c == '"' {
                in_str = true;
            }
            out.push(c);
            prev = c;
        }
        out.push('\n');
    }
    out
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The top-level modules a `crate::` path at `rest` (the text after `crate::`) names: one, or
/// the first segment of each member of a `{…}` group.
fn crate_targets(rest: &str) -> Vec<String> {
    let rest = rest.trim_start();
    if let Some(group) = rest.strip_prefix('{') {
        let mut depth = 0;
        let mut member_start = true;
        let mut targets = Vec::new();
        for (i, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => member_start = true,
                c if member_start && !c.is_whitespace() => {
                    member_start = false;
                    targets.push(ident_at(&group[i..]).to_string());
                }
                _ => {}
            }
        }
        targets
    } else {
        vec![ident_at(rest).to_string()]
    }
}

/// Every upward or unresolvable path in one file's `code`, as messages.
fn violations(file: &str, module: &[String], code: &str) -> Vec<String> {
    let Some(own) = module.first() else {
        return Vec::new(); // the crate root declares and re-exports everything
    };
    let Some(own_rank) = rank(own) else {
        return vec![format!(
            "{file}: top-level module `{own}` has no layer in tests/layering.rs"
        )];
    };
    let mut found = Vec::new();
    let mut check = |target: &str, via: &str| {
        if target.is_empty() || target == "self" {
            return;
        }
        match rank(target) {
            Some(r) if r <= own_rank => {}
            Some(_) => found.push(format!(
                "{file}: `{via}{target}` points up from `{own}` to `{target}`"
            )),
            None => found.push(format!(
                "{file}: `{via}{target}`: not a top-level module; name the module it is in \
                 (a path through the crate root's re-exports hides its layer)"
            )),
        }
    };
    let bytes = code.as_bytes();
    for (i, _) in code.match_indices("crate::") {
        // `$crate::` in a macro, or an identifier ending in `crate`, is not this crate's root.
        let before = i.checked_sub(1).map(|j| bytes[j] as char);
        if before.is_some_and(|c| c == '$' || c.is_alphanumeric() || c == '_') {
            continue;
        }
        for target in crate_targets(&code[i + "crate::".len()..]) {
            check(&target, "crate::");
        }
    }
    for (i, _) in code.match_indices("super::") {
        let before = i.checked_sub(1).map(|j| bytes[j] as char);
        if before.is_some_and(|c| c == ':' || c.is_alphanumeric() || c == '_') {
            continue; // counted from the first `super::` of the chain
        }
        let mut rest = &code[i..];
        let mut ups = 0;
        while let Some(r) = rest.strip_prefix("super::") {
            ups += 1;
            rest = r;
        }
        if ups >= module.len() {
            for target in crate_targets(rest) {
                check(&target, &"super::".repeat(ups));
            }
        }
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn no_module_uses_a_layer_above_its_own() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 20,
        "found only {} files under src/",
        files.len()
    );
    let mut found = Vec::new();
    for path in &files {
        let rel = path.strip_prefix(&src).expect("under src/");
        let text = std::fs::read_to_string(path).expect("source file");
        found.extend(violations(
            &rel.display().to_string(),
            &module_path(rel),
            &code_only(&text),
        ));
    }
    assert!(found.is_empty(), "upward paths:\n{}", found.join("\n"));
}

#[test]
fn every_top_level_module_has_a_layer() {
    let lib = include_str!("../src/lib.rs");
    for line in lib.lines() {
        let line = line.trim_start_matches("pub ").trim();
        if let Some(name) = line.strip_prefix("mod ").and_then(|l| l.strip_suffix(';')) {
            assert!(rank(name).is_some(), "module `{name}` has no layer here");
        }
    }
}

#[test]
fn the_checker_finds_upward_paths_of_every_form() {
    let passes = module_path(Path::new("passes/record/push.rs"));
    let frame = module_path(Path::new("frame/ic.rs"));
    let up = |module: &[String], code: &str| violations("f.rs", module, &code_only(code)).len();
    assert_eq!(passes, ["passes", "record", "push"]);
    assert_eq!(module_path(Path::new("state/mod.rs")), ["state"]);
    // Upward: a `use`, a group member, an inline path, a `super::` chain out of the module.
    assert_eq!(up(&passes, "use crate::frame::settings::SkyLight;"), 1);
    assert_eq!(up(&passes, "use crate::{error::Result, frame::aa};"), 1);
    assert_eq!(up(&passes, "let x = crate::frame::aa::f(&a);"), 1);
    assert_eq!(up(&passes, "use super::super::super::frame::x;"), 1);
    assert_eq!(up(&passes, "let r: crate::IcRenderer;"), 1);
    // Downward or within the layer: allowed.
    assert_eq!(
        up(&passes, "use crate::{error::Result, state::IcState};"),
        0
    );
    assert_eq!(up(&passes, "use super::super::gbuffer::GBuffer;"), 0);
    assert_eq!(
        up(&frame, "let s = crate::passes::splat::SplatPass::new();"),
        0
    );
    // Comments, strings and `$crate` are not code.
    assert_eq!(
        up(&passes, "/// see [`crate::frame::ic`]\n// crate::frame"),
        0
    );
    assert_eq!(up(&passes, "let s = \"crate::frame\";"), 0);
    assert_eq!(up(&passes, "$crate::frame::x"), 0);
}
