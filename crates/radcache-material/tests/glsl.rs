//! Checks that `shaders/common/brdf.glsl` stays the twin of this crate (`docs/materials.md`: a
//! GLSL twin mirrors the crate function by function, same names, argument order and guards):
//! * every top-level function of `src/` has a GLSL function of the same name and the same number
//!   of arguments, and vice versa (the exceptions are listed with their reasons); the values are
//!   compared on the GPU by `tests/tests/brdf_glsl.rs`;
//! * the constants come from the generated `shaders/shared/constants.glsl`, none is hand-copied;
//! * the file compiles with `glslangValidator` (Vulkan 1.2 target; `scripts/setup.sh` installs
//!   it with `glslang-tools`), included twice (its guard): a machine without the tool fails.

use std::collections::BTreeMap;
use std::path::PathBuf;

use radcache_shared::glsl_twin::{
    assert_compiles_with_glslang, assert_compiles_with_glslang_after, assert_constants_generated,
    glsl_functions,
};

/// Rust functions whose GLSL twin has another name, and why.
const RENAMED: [(&str, &str, &str); 1] = [(
    "reflect",
    "brdf_reflect",
    "GLSL's built-in reflect(I, N) = I − 2(N·I)N is the negative of the Rust one",
)];

/// GLSL helpers with no function of their own in the crate, and what they mirror.
const GLSL_ONLY: [(&str, &str); 1] = [("brdf_normalize_or_z", "glam's `normalize_or(Vec3::Z)`")];

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn glsl_path() -> PathBuf {
    crate_dir().join("../../shaders/common/brdf.glsl")
}

/// The twin of `src/polygon.rs`.
fn polygon_glsl_path() -> PathBuf {
    crate_dir().join("../../shaders/common/polygon.glsl")
}

/// The twin of `src/normal_map.rs`.
fn normal_map_glsl_path() -> PathBuf {
    crate_dir().join("../../shaders/common/normal_map.glsl")
}

fn arity(args: &str) -> usize {
    args.split(',').filter(|a| !a.trim().is_empty()).count()
}

/// The modules twinned by `sh.glsl` and `glossy.glsl` (checked by
/// [`sh_and_glossy_have_glsl_twins`]); the others by `brdf.glsl`, `polygon.glsl`, `normal_map.glsl`.
const SH_MODULES: [&str; 2] = ["sh.rs", "glossy.rs"];

/// Top-level functions (public or not) of `src/*.rs` and their argument counts: of the
/// [`SH_MODULES`] when `sh`, of the other modules otherwise.
fn rust_functions_of(sh: bool) -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(crate_dir().join("src")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if SH_MODULES.contains(&name.as_str()) != sh {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        // Test modules hold no twins.
        let text = text.split("\n#[cfg(test)]").next().unwrap_or_default();
        for prefix in ["\npub fn ", "\nfn "] {
            for (pos, _) in text.match_indices(prefix) {
                let sig = &text[pos + prefix.len()..];
                let open = sig.find('(').unwrap();
                let close = open + sig[open..].find(')').unwrap();
                out.insert(sig[..open].to_string(), arity(&sig[open + 1..close]));
            }
        }
    }
    out
}

#[test]
fn every_rust_function_has_a_glsl_twin() {
    let brdf = std::fs::read_to_string(glsl_path()).expect("shaders/common/brdf.glsl");
    assert!(
        brdf.starts_with("// common/brdf.glsl — Rust: crates/radcache-material/src/*.rs"),
        "brdf.glsl must name its CPU twin on its first line"
    );
    let polygon = std::fs::read_to_string(polygon_glsl_path()).expect("common/polygon.glsl");
    assert!(
        polygon
            .starts_with("// common/polygon.glsl — Rust: crates/radcache-material/src/polygon.rs"),
        "polygon.glsl must name its CPU twin on its first line"
    );
    let normal_map = std::fs::read_to_string(normal_map_glsl_path()).expect("normal_map.glsl");
    assert!(
        normal_map.starts_with(
            "// common/normal_map.glsl — Rust: crates/radcache-material/src/normal_map.rs"
        ),
        "normal_map.glsl must name its CPU twin on its first line"
    );
    let text = format!("{brdf}\n{polygon}\n{normal_map}");
    let types = [
        "float",
        "vec3",
        "vec4",
        "uint",
        "bool",
        "void",
        "BrdfLobes",
        "BrdfSample",
    ];
    let glsl = glsl_functions(&text, &types);
    let rust = rust_functions_of(false);
    assert!(
        rust.len() >= 20 && glsl.len() >= 20,
        "parsers found too little: {} / {}",
        rust.len(),
        glsl.len()
    );
    for (name, arity) in &rust {
        let twin = RENAMED
            .iter()
            .find(|(r, _, _)| r == name)
            .map_or(name.as_str(), |(_, g, _)| g);
        let g = glsl
            .get(twin)
            .unwrap_or_else(|| panic!("no GLSL twin `{twin}` for `{name}`"));
        assert_eq!(g, arity, "`{name}`: GLSL takes {g} arguments, Rust {arity}");
    }
    for name in glsl.keys() {
        let known = rust.contains_key(name)
            || RENAMED.iter().any(|(_, g, _)| g == name)
            || GLSL_ONLY.iter().any(|(g, _)| g == name);
        assert!(known, "GLSL `{name}` has no Rust reference");
    }
    for (rust_name, glsl_name, _) in RENAMED {
        assert!(rust.contains_key(rust_name) && !glsl.contains_key(rust_name));
        assert!(glsl.contains_key(glsl_name));
    }
}

/// The constants are generated into `shaders/shared/constants.glsl` from
/// `radcache_shared::consts` (which this crate re-exports): the twin includes that file and
/// hand-copies none of them.
#[test]
fn constants_are_generated_not_copied() {
    let text = std::fs::read_to_string(glsl_path()).unwrap();
    let names = [
        "ALPHA_MIN",
        "COS_MIN",
        "SMITH_LAMBDA_MASKED",
        "SCHLICK_MEAN_C0",
        "SCHLICK_MEAN_C1",
        "SCHLICK_MEAN_C2",
        "SCHLICK_MEAN_C3",
        "SCHLICK_MEAN_C4",
    ];
    assert_constants_generated("brdf.glsl", &text, &names);
    for name in names {
        assert!(text.contains(name), "brdf.glsl does not use {name}");
    }
    assert_eq!(radcache_material::ggx::ALPHA_MIN, 1.0e-3);
    assert_eq!(radcache_material::brdf::COS_MIN, 1.0e-6);
}

#[test]
fn normal_map_glsl_compiles_and_uses_the_generated_limit() {
    let text = std::fs::read_to_string(normal_map_glsl_path()).unwrap();
    assert_constants_generated("normal_map.glsl", &text, &["NORMAL_MAP_COS_MIN"]);
    assert!(text.contains("NORMAL_MAP_COS_MIN"));
    assert_compiles_with_glslang(
        normal_map_glsl_path().parent().unwrap(),
        "normal_map.glsl",
        "o.v[0] = vec4(normal_map_normal(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), \
         vec4(1.0, 0.0, 0.0, 1.0), vec3(0.6, 0.5, 0.9), 1.0), 0.0);",
    );
}

#[test]
fn polygon_glsl_compiles() {
    assert_compiles_with_glslang(
        polygon_glsl_path().parent().unwrap(),
        "polygon.glsl",
        "vec3 t[3] = vec3[3](vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0)); \
         o.v[0] = vec4(triangle_projected_solid_angle(vec3(0.0), vec3(0.0, 0.0, 1.0), t));",
    );
}

#[test]
fn glsl_compiles() {
    assert_compiles_with_glslang(
        glsl_path().parent().unwrap(),
        "brdf.glsl",
        "Material m = Material(vec3(1.0), 1.0, 0.5, 1.5, 1.0, vec3(1.0)); \
         BrdfSample s = brdf_sample(m, vec3(0.0, 0.6, 0.8), vec3(0.3, 0.7, 0.1)); \
         o.v[0] = vec4(s.weight, s.pdf);",
    );
}

/// Rust functions of [`SH_MODULES`] with no GLSL twin: the table is built on the CPU and
/// uploaded, and the analytic fields are test references.
const SH_CPU_ONLY: [(&str, &str); 10] = [
    (
        "sh_eval",
        "any band in f64, by recurrence: the measurement and the check of sh_basis",
    ),
    (
        "sh_frame_weights",
        "folds A⁻ᵀ into the table, built on the CPU",
    ),
    ("frame_matrix", "part of sh_frame_weights"),
    ("solve", "part of sh_frame_weights"),
    ("glossy_projection", "builds the table on the CPU"),
    ("glossy_table", "builds the table on the CPU"),
    (
        "glossy_table_roughness",
        "the table's grid, used where it is built",
    ),
    (
        "glossy_table_nv",
        "the table's grid, used where it is built",
    ),
    (
        "sh_hemisphere_constant",
        "an analytic radiance field for the tests",
    ),
    (
        "sh_sphere_linear",
        "an analytic radiance field for the tests",
    ),
];

/// Twins whose GLSL signature differs from Rust's, with the GLSL arity and why.
const SH_ARITY: [(&str, usize, &str); 7] = [
    (
        "glossy_world_weights",
        4,
        "the table is the buffer glossy_table; W is an out array",
    ),
    ("sh_basis", 2, "the 16 values are an out array"),
    ("sh_frame_values", 5, "the 16 values are an out array"),
    (
        "sh_view_frame",
        4,
        "t and b are out parameters (n is the input)",
    ),
    ("glossy_weights", 2, "K1 is an out parameter"),
    (
        "glossy_lookup",
        3,
        "the table is the buffer glossy_table; the entry is an out array",
    ),
    ("glossy_radiance", 4, "the table is the buffer glossy_table"),
];

fn sh_glsl() -> String {
    let dir = crate_dir().join("../../shaders/common");
    let sh = std::fs::read_to_string(dir.join("sh.glsl")).expect("shaders/common/sh.glsl");
    let glossy = std::fs::read_to_string(dir.join("glossy.glsl")).expect("common/glossy.glsl");
    assert!(sh.starts_with("// common/sh.glsl — Rust: crates/radcache-material/src/sh.rs"));
    assert!(
        glossy.starts_with("// common/glossy.glsl — Rust: crates/radcache-material/src/glossy.rs")
    );
    format!("{sh}\n{glossy}")
}

#[test]
fn sh_and_glossy_have_glsl_twins() {
    let text = sh_glsl();
    let glsl = glsl_functions(&text, &["float", "vec3", "uint", "void"]);
    let rust = rust_functions_of(true);
    assert!(rust.len() >= 15, "parser found too little: {}", rust.len());
    let mut twins = 0;
    for (name, arity) in &rust {
        if name == "sh_delta" || SH_CPU_ONLY.iter().any(|(n, _)| n == name) {
            assert!(!glsl.contains_key(name), "{name} is listed as CPU-only");
            continue;
        }
        let g = glsl
            .get(name)
            .unwrap_or_else(|| panic!("no GLSL twin `{name}`"));
        let expected = SH_ARITY
            .iter()
            .find(|(n, _, _)| n == name)
            .map_or(*arity, |(_, a, _)| *a);
        assert_eq!(*g, expected, "`{name}`: GLSL takes {g} arguments");
        twins += 1;
    }
    assert!(twins >= 10, "{twins} twins");
    for name in glsl.keys() {
        let known = rust.contains_key(name) || name == "sh_frame_dir";
        assert!(known, "GLSL `{name}` has no Rust reference");
    }
    let names = [
        "SH_COEFFS",
        "SH_K00",
        "SH_K32B",
        "GLOSSY_TABLE_ROUGHNESS",
        "GLOSSY_TABLE_NV",
        "GLOSSY_NV_MIN",
    ];
    assert_constants_generated("sh.glsl + glossy.glsl", &text, &names);
}

#[test]
fn glossy_glsl_compiles() {
    assert_compiles_with_glslang_after(
        glsl_path().parent().unwrap(),
        "glossy.glsl",
        "#define GLOSSY_TABLE_BINDING 1",
        "vec3 c[SH_COEFFS]; for (int i = 0; i < int(SH_COEFFS); ++i) { c[i] = vec3(1.0); } \
         Material m = Material(vec3(1.0), 1.0, 0.7, 1.5, 1.0, vec3(1.0)); \
         o.v[0] = vec4(glossy_radiance(m, vec3(0.0, 0.0, 1.0), vec3(0.6, 0.0, 0.8), c), 0.0);",
    );
}
