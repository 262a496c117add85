//! Compiles every entry shader under `shaders/` with the run-time compiler's options and validates
//! the SPIR-V with `spirv-val --target-env vulkan1.3`. Used by the `shaders` test and by
//! `cargo xtask shaders`.

use std::path::{Path, PathBuf};
use std::process::Command;

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

fn entry_shaders(root: &Path, dir: &Path, out: &mut Vec<String>) -> std::io::Result<()> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            entry_shaders(root, &p, out)?;
        } else if let Some(rel) = p.strip_prefix(root).ok().and_then(|r| r.to_str()) {
            if ShaderStage::from_path(rel).is_some() {
                out.push(rel.replace('\\', "/"));
            }
        }
    }
    Ok(())
}

/// Whether `spirv-val` is on the PATH.
pub fn has_spirv_val() -> bool {
    Command::new("spirv-val").arg("--version").output().is_ok()
}

/// Compiles and validates every entry shader under `root`; SPIR-V files go to `out_dir`.
pub fn check_all(root: &Path, out_dir: &Path, validate: bool) -> std::io::Result<Vec<ShaderCheck>> {
    let mut paths = Vec::new();
    entry_shaders(root, root, &mut paths)?;
    std::fs::create_dir_all(out_dir)?;
    let compiler = ShaderCompiler::new(root).map_err(std::io::Error::other)?;
    let mut results = Vec::new();
    for path in paths {
        let mut check = ShaderCheck {
            path: path.clone(),
            error: None,
            words: 0,
        };
        match compiler.compile(&path, &[]) {
            Err(e) => check.error = Some(e.to_string()),
            Ok(spirv) => {
                check.words = spirv.len();
                let spv = out_dir.join(format!("{}.spv", path.replace('/', "_")));
                std::fs::write(&spv, bytemuck::cast_slice::<u32, u8>(&spirv))?;
                if validate {
                    let out = Command::new("spirv-val")
                        .args(["--target-env", "vulkan1.3"])
                        .arg(&spv)
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
        results.push(check);
    }
    Ok(results)
}
