//! Checks that `shaders/common/ircache_math.glsl` stays the twin of this crate
//! (`docs/irradiance-cache.md`: every formula has a Rust reference in this crate and a GLSL twin of
//! the same name):
//! * every top-level `pub fn` of `src/` has a GLSL function of the same name and vice versa, with
//!   the same arity once Rust's `[Vec3; 3]` arguments count as three `vec3`, a `WeightRecord` as
//!   its three values and a `HessianCell` as its twelve, and tuple/struct results as `out`
//!   parameters (value comparison on the GPU is the lead's `radcache-tests`);
//! * every `pub const` scalar of the crate has the same value in GLSL;
//! * the file compiles with `glslangValidator` (Vulkan 1.2 target; `scripts/setup.sh` installs
//!   it with `glslang-tools`): a machine without the tool fails the test.

use std::collections::BTreeMap;
use std::path::PathBuf;

use radcache_shared::glsl_twin::{
    assert_compiles_with_glslang, assert_constants_generated, glsl_functions,
};

/// Rust functions with no GLSL twin (slices / test helpers) and their reason.
const RUST_ONLY: [(&str, &str); 5] = [
    (
        "compute_record",
        "takes slices; the GPU pass reduces the per-stratum terms",
    ),
    (
        "compute_hessian",
        "takes slices; the GPU pass sums the per-cell terms",
    ),
    (
        "compute_radiance",
        "takes slices; the GPU pass sums coefficients and walls per invocation",
    ),
    (
        "glossy_gradient_limit",
        "takes a record's estimate; the GPU pass sums it in shared memory and calls the twin of glossy_gradient_limit_from_sums",
    ),
    ("stratum_contains", "test helper"),
];

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn glsl_path() -> PathBuf {
    crate_dir().join("../../shaders/common/ircache_math.glsl")
}

/// Number of GLSL-side values a Rust signature maps to: arguments plus `out` results.
fn rust_arity(args: &str, ret: &str) -> usize {
    let args: Vec<&str> = args
        .split(',')
        .map(str::trim)
        .filter(|a| !a.is_empty())
        .collect();
    let mut n = args
        .iter()
        .map(|a| {
            if a.contains("[Vec3; 3]") || a.contains("WeightRecord") {
                3 // three vec3, or a record's p_i, n_i, r_i
            } else if a.contains("HessianCell") {
                12 // the cell's vertices, luminances and flags, in order
            } else {
                1
            }
        })
        .sum::<usize>();
    let ret = ret.trim();
    if ret.starts_with('(') {
        n += ret.matches(',').count() + 1;
    } else if ret == "FinalRadius" {
        n += 5;
    }
    n
}

fn rust_functions() -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    // The formula modules are the files of `src/`; its folder `cache_file/` (the cache file
    // format) holds no formula.
    for entry in std::fs::read_dir(crate_dir().join("src")).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        for (pos, _) in text.match_indices("\npub fn ") {
            let sig = &text[pos + 8..];
            let sig = &sig[..sig.find('{').unwrap()];
            let open = sig.find('(').unwrap();
            let name = &sig[..open];
            // The ')' matching the argument list's '('.
            let mut depth = 0;
            let close = open
                + sig[open..]
                    .char_indices()
                    .find(|&(_, c)| {
                        depth += match c {
                            '(' => 1,
                            ')' => -1,
                            _ => 0,
                        };
                        depth == 0
                    })
                    .unwrap()
                    .0;
            let ret = sig[close + 1..].trim().trim_start_matches("->");
            out.insert(name.to_string(), rust_arity(&sig[open + 1..close], ret));
        }
    }
    out
}

#[test]
fn every_rust_function_has_a_glsl_twin() {
    let text = std::fs::read_to_string(glsl_path()).expect("shaders/common/ircache_math.glsl");
    let glsl = glsl_functions(&text, &["float", "vec3", "vec4", "uint", "bool", "void"]);
    let rust = rust_functions();
    assert!(
        rust.len() > 50 && glsl.len() > 50,
        "parsers found too little: {} / {}",
        rust.len(),
        glsl.len()
    );
    for (name, arity) in &rust {
        if RUST_ONLY.iter().any(|(n, _)| n == name) {
            assert!(!glsl.contains_key(name));
            continue;
        }
        let g = glsl
            .get(name)
            .unwrap_or_else(|| panic!("no GLSL twin for `{name}`"));
        assert_eq!(
            g, arity,
            "`{name}`: GLSL takes {g} values, Rust maps to {arity}"
        );
    }
    for name in glsl.keys() {
        assert!(
            rust.contains_key(name),
            "GLSL `{name}` has no Rust reference"
        );
    }
}

/// The shared constants are generated into `shaders/shared/constants.glsl` from
/// `radcache_shared::consts` (which this crate re-exports): the twin includes that file and
/// hand-copies none of them.
#[test]
fn constants_are_generated_not_copied() {
    let text = std::fs::read_to_string(glsl_path()).unwrap();
    let names = [
        "IC_FAR",
        "R_FLOOR",
        "WARD_MIN_ERROR",
        "TL_NORMAL_SCALE",
        "KAPPA_MIN",
        "ELEVATION_MIN_SIN2",
        "EXTRAPOLATION_MAX_FACTOR",
        "HESSIAN_ERROR",
        "HESSIAN_SERIES_TAU",
        "WEIGHT_WARD",
        "WEIGHT_TL",
    ];
    assert_constants_generated("ircache_math.glsl", &text, &names);
    // Derived constants hold what their names say.
    assert!(
        (radcache_cache::TL_NORMAL_SCALE - (1.0 - 10f32.to_radians().cos()).sqrt()).abs() < 1e-6
    );
    assert!((radcache_cache::ELEVATION_MIN_SIN2 - 10f32.to_radians().sin().powi(2)).abs() < 1e-7);
    assert_eq!(
        radcache_cache::weight::WEIGHT_WARD,
        radcache_cache::WeightKind::Ward as u32
    );
}

#[test]
fn glsl_compiles() {
    assert_compiles_with_glslang(
        glsl_path().parent().unwrap(),
        "ircache_math.glsl",
        "vec3 t, b; basis_from_normal(vec3(0.0, 0.0, -1.0), t, b); \
         o.v[0] = vec4(t, stratum_tan_mean(3u, 16u));",
    );
}
