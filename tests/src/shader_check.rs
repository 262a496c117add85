//! Compiles every entry shader under `shaders/` with the run-time compiler's options and validates
//! the SPIR-V with `spirv-val --target-env vulkan1.3`, without defines and as every pass compiles
//! them for each of its variants ([`radcache_render::passes::every_shader_module`]). Used by the
//! `shaders` test and by `cargo xtask shaders`.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use radcache_render::scene::features::ShaderModule;
use radcache_vk::{ShaderCompiler, ShaderStage};

/// The outcome for one shader.
#[derive(Debug, Clone)]
pub struct ShaderCheck {
    /// Path relative to `shaders/`.
    pub path: String,
    /// Compilation or validation error, if any.
    pub error: Option<String>,
    /// SPIR-V words.
    pub words: usize,
}

/// Every file under `root` (recursively), relative to it with `/` separators, sorted.
pub fn files_under(root: &Path) -> std::io::Result<Vec<String>> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) -> std::io::Result<()> {
        for entry in std::fs::read_dir(dir)? {
            let p = entry?.path();
            if p.is_dir() {
                walk(root, &p, out)?;
            } else if let Some(rel) = p.strip_prefix(root).ok().and_then(|r| r.to_str()) {
                out.push(rel.replace('\\', "/"));
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    walk(root, root, &mut out)?;
    out.sort();
    Ok(out)
}

/// The entry shaders under `root` (a stage the compiler knows from the extension; includes are
/// not entry points), relative to it, sorted.
pub fn entry_shaders(root: &Path) -> std::io::Result<Vec<String>> {
    Ok(files_under(root)?
        .into_iter()
        .filter(|p| ShaderStage::from_path(p).is_some())
        .collect())
}

/// What is wrong with `results` when every shader of `expected` must have compiled to a
/// non-empty module and validated: one line per shader not compiled, failed, empty, or compiled
/// though not expected. Empty when all is well.
pub fn coverage_errors(expected: &BTreeSet<String>, results: &[ShaderCheck]) -> Vec<String> {
    let compiled: BTreeSet<&str> = results.iter().map(|r| r.path.as_str()).collect();
    let mut errors: Vec<String> = expected
        .iter()
        .filter(|p| !compiled.contains(p.as_str()))
        .map(|p| format!("{p}: not compiled"))
        .collect();
    for r in results {
        if !expected.contains(&r.path) {
            errors.push(format!(
                "{}: compiled, but not an expected entry shader",
                r.path
            ));
        } else if let Some(e) = &r.error {
            errors.push(format!("{}: {e}", r.path));
        } else if r.words == 0 {
            errors.push(format!("{}: empty SPIR-V", r.path));
        }
    }
    errors
}

/// Whether `spirv-val` is on the PATH.
pub fn has_spirv_val() -> bool {
    Command::new("spirv-val").arg("--version").output().is_ok()
}

/// Compiles `path` with `defines`, writes the SPIR-V to `spv` and, with `validate`, checks it
/// with `spirv-val`.
fn check_one(
    compiler: &ShaderCompiler,
    path: &str,
    defines: &[(&str, &str)],
    spv: &Path,
    validate: bool,
) -> std::io::Result<ShaderCheck> {
    let mut check = ShaderCheck {
        path: path.to_string(),
        error: None,
        words: 0,
    };
    match compiler.compile(path, defines) {
        Err(e) => check.error = Some(e.to_string()),
        Ok(spirv) => {
            check.words = spirv.len();
            std::fs::write(spv, bytemuck::cast_slice::<u32, u8>(&spirv))?;
            if validate {
                let out = Command::new("spirv-val")
                    .args(["--target-env", "vulkan1.3"])
                    .arg(spv)
                    .output()?;
                if !out.status.success() {
                    check.error = Some(format!(
                        "spirv-val: {}{}",
                        String::from_utf8_lossy(&out.stdout),
                        String::from_utf8_lossy(&out.stderr)
                    ));
                }
            }
        }
    }
    Ok(check)
}

/// Compiles and validates every entry shader under `root` without defines; SPIR-V files go to
/// `out_dir`.
pub fn check_all(root: &Path, out_dir: &Path, validate: bool) -> std::io::Result<Vec<ShaderCheck>> {
    let paths = entry_shaders(root)?;
    std::fs::create_dir_all(out_dir)?;
    let compiler = ShaderCompiler::new(root).map_err(std::io::Error::other)?;
    let mut results = Vec::new();
    for path in paths {
        let spv = out_dir.join(format!("{}.spv", path.replace('/', "_")));
        results.push(check_one(&compiler, &path, &[], &spv, validate)?);
    }
    Ok(results)
}

/// The name a module goes by in reports: its path and defines (`passes/direct.comp
/// [HAS_SPECULAR DIRECT_COMPOSITE]`).
pub fn module_name(module: &ShaderModule) -> String {
    let defines: Vec<String> = module
        .defines
        .iter()
        .map(|&(d, v)| {
            if v == "1" {
                d.to_string()
            } else {
                format!("{d}={v}")
            }
        })
        .collect();
    format!("{} [{}]", module.path, defines.join(" "))
}

/// Compiles and validates every module of `modules` (shaders under `root` with their defines)
/// on as many threads as the machine has cores, calling `progress` after each; SPIR-V files go
/// to `out_dir`, numbered in order. The results are in the order of `modules`, each one's path
/// its [`module_name`].
pub fn check_modules(
    root: &Path,
    out_dir: &Path,
    validate: bool,
    modules: &[ShaderModule],
    progress: impl Fn(&ShaderCheck) + Sync,
) -> std::io::Result<Vec<ShaderCheck>> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;

    std::fs::create_dir_all(out_dir)?;
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<Option<ShaderCheck>>> = Mutex::new(vec![None; modules.len()]);
    let work = || -> std::io::Result<()> {
        let compiler = ShaderCompiler::new(root).map_err(std::io::Error::other)?;
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(module) = modules.get(i) else {
                return Ok(());
            };
            let stem = module.path.replace('/', "_");
            let spv = out_dir.join(format!("{stem}.{i:03}.spv"));
            let mut check = check_one(&compiler, module.path, &module.defines, &spv, validate)?;
            check.path = module_name(module);
            progress(&check);
            done.lock().unwrap_or_else(|p| p.into_inner())[i] = Some(check);
        }
    };
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers.min(modules.len()))
            .map(|_| scope.spawn(work))
            .collect();
        handles.into_iter().try_for_each(|h| {
            h.join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        })
    })?;
    Ok(done
        .into_inner()
        .unwrap_or_else(|p| p.into_inner())
        .into_iter()
        .flatten()
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(path: &str) -> ShaderCheck {
        ShaderCheck {
            path: path.into(),
            error: None,
            words: 100,
        }
    }

    #[test]
    fn coverage_reports_every_missing_failed_or_unexpected_shader() {
        let expected: BTreeSet<String> = ["a.comp", "b.vert", "c.frag", "d.comp"]
            .map(String::from)
            .into();
        let all = [ok("a.comp"), ok("b.vert"), ok("c.frag"), ok("d.comp")];
        assert!(coverage_errors(&expected, &all).is_empty());
        // b.vert missing, c.frag failed, d.comp empty, e.comp not expected.
        let results = [
            ok("a.comp"),
            ShaderCheck {
                error: Some("syntax error".into()),
                ..ok("c.frag")
            },
            ShaderCheck {
                words: 0,
                ..ok("d.comp")
            },
            ok("e.comp"),
        ];
        let errors = coverage_errors(&expected, &results);
        assert_eq!(
            errors,
            [
                "b.vert: not compiled",
                "c.frag: syntax error",
                "d.comp: empty SPIR-V",
                "e.comp: compiled, but not an expected entry shader",
            ],
            "{errors:?}"
        );
    }

    #[test]
    fn entry_shaders_are_the_stage_files_at_any_depth() {
        let dir = std::env::temp_dir().join(format!("radcache-entry-{}", std::process::id()));
        for f in [
            "x.comp",
            "common/inc.glsl",
            "passes/p.vert",
            "passes/deep/q.frag",
        ] {
            let p = dir.join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, "").unwrap();
        }
        let entries = entry_shaders(&dir).unwrap();
        let files = files_under(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(entries, ["passes/deep/q.frag", "passes/p.vert", "x.comp"]);
        assert_eq!(files.len(), 4, "{files:?}");
    }
}
