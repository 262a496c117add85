//! What the tests that keep a GLSL twin equal to its Rust crate share (`radcache-cache`'s
//! `ircache_math.glsl`, `radcache-material`'s `brdf.glsl`): the twin's top-level functions and
//! their argument counts, the check that it hand-copies no generated constant, and its compile
//! check with `glslangValidator` (`scripts/setup.sh` installs it with `glslang-tools`).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Functions defined at the top level of GLSL `text` whose return type is one of `types`, with
/// their argument counts.
pub fn glsl_functions(text: &str, types: &[&str]) -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    for ty in types {
        for (pos, _) in text.match_indices(&format!("\n{ty} ")) {
            let rest = &text[pos + ty.len() + 2..];
            let Some(paren) = rest.find('(') else {
                continue;
            };
            let name = &rest[..paren];
            if name.contains(' ') || name.contains('=') || name.contains('\n') {
                continue; // a declaration, not a function
            }
            let Some(close) = rest[paren..].find(')') else {
                continue;
            };
            let args = &rest[paren + 1..paren + close];
            let count = args.split(',').filter(|a| !a.trim().is_empty()).count();
            out.insert(name.to_string(), count);
        }
    }
    out
}

/// Panics unless the twin `text` (called `file` in messages) includes the generated
/// `constants.glsl`, declares none of `names` itself, and the generated file declares them all.
pub fn assert_constants_generated(file: &str, text: &str, names: &[&str]) {
    assert!(
        text.contains("#include \"../shared/constants.glsl\""),
        "{file} must include the generated constants"
    );
    let generated = crate::consts::generated_glsl();
    for name in names {
        let key = format!(" {name} = ");
        assert!(!text.contains(&key), "{file} hand-copies {name}");
        assert!(generated.contains(&key), "constants.glsl lacks {name}");
    }
}

/// Panics unless a compute shader that includes `file` (from `dir`) twice, to test its guard,
/// and runs `main_body` compiles with `glslangValidator` for Vulkan 1.2. `main_body` may write
/// `o.v[i]` (a `vec4` buffer at binding 0). A machine without the tool fails.
pub fn assert_compiles_with_glslang(dir: &Path, file: &str, main_body: &str) {
    assert_compiles_with_glslang_after(dir, file, "", main_body);
}

/// [`assert_compiles_with_glslang`] with `prelude` (e.g. `#define`s the file needs) placed
/// before the includes.
pub fn assert_compiles_with_glslang_after(dir: &Path, file: &str, prelude: &str, main_body: &str) {
    let out = Command::new("glslangValidator")
        .arg("--version")
        .output()
        .unwrap_or_else(|e| {
            panic!("glslangValidator not found ({e}): install glslang-tools (run scripts/setup.sh)")
        });
    assert!(
        out.status.success(),
        "glslangValidator --version failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stem = file.trim_end_matches(".glsl");
    let tmp = std::env::temp_dir().join(format!("radcache-glsl-{stem}-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let wrapper = tmp.join("wrap.comp");
    let source = format!(
        "#version 460\n#extension GL_GOOGLE_include_directive : require\n{prelude}\n#include \"{file}\"\n\
         #include \"{file}\"\nlayout(local_size_x = 1) in;\n\
         layout(std430, binding = 0) buffer Out {{ vec4 v[]; }} o;\n\
         void main() {{ {main_body} }}\n"
    );
    std::fs::write(&wrapper, source).unwrap();
    let include = format!("-I{}", dir.display());
    let res = Command::new("glslangValidator")
        .args(["-V", "--target-env", "vulkan1.2", &include, "-o"])
        .arg(tmp.join("wrap.spv"))
        .arg(&wrapper)
        .output()
        .unwrap();
    let log =
        String::from_utf8_lossy(&res.stdout).to_string() + &String::from_utf8_lossy(&res.stderr);
    let _ = std::fs::remove_dir_all(&tmp);
    assert!(
        res.status.success(),
        "glslangValidator failed on {file}:\n{log}"
    );
}
