//! Run-time GLSL compilation with shaderc.
//!
//! Shaders live under one root folder (the repository's `shaders/`). `#include "x.glsl"` resolves
//! relative to the including file first, then to the root. Defines are passed per compile. The
//! target is Vulkan 1.3 / SPIR-V 1.6 (ray queries need SPIR-V 1.4+). Errors carry `file:line`
//! relative to the root. Results are cached in memory by (path, defines); a cached entry is reused
//! only while the contents of every file it read are unchanged, so edits are picked up on the next
//! compile (hot reload without a watcher).

use std::cell::RefCell;
use std::collections::hash_map::DefaultHasher;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};

/// Shader stage, from the file extension (`.comp`, `.vert`, `.frag`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShaderStage {
    /// Compute shader.
    Compute,
    /// Vertex shader.
    Vertex,
    /// Fragment shader.
    Fragment,
}

impl ShaderStage {
    /// The stage of a shader file, by extension.
    pub fn from_path(path: &str) -> Option<Self> {
        match Path::new(path).extension()?.to_str()? {
            "comp" => Some(ShaderStage::Compute),
            "vert" => Some(ShaderStage::Vertex),
            "frag" => Some(ShaderStage::Fragment),
            _ => None,
        }
    }

    fn kind(self) -> shaderc::ShaderKind {
        match self {
            ShaderStage::Compute => shaderc::ShaderKind::Compute,
            ShaderStage::Vertex => shaderc::ShaderKind::Vertex,
            ShaderStage::Fragment => shaderc::ShaderKind::Fragment,
        }
    }
}

type Key = (String, Vec<(String, String)>);

struct Entry {
    /// (path relative to root, hash of its contents) of every file read.
    files: Vec<(String, u64)>,
    spirv: Arc<Vec<u32>>,
}

/// The shader compiler: one shaderc instance (the first compile in a process is slow), a root
/// folder and the in-memory cache.
pub struct ShaderCompiler {
    compiler: shaderc::Compiler,
    root: PathBuf,
    debug_info: bool,
    cache: Mutex<HashMap<Key, Entry>>,
}

impl std::fmt::Debug for ShaderCompiler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShaderCompiler")
            .field("root", &self.root)
            .finish()
    }
}

fn hash_text(s: &str) -> u64 {
    let mut h = DefaultHasher::new();
    s.hash(&mut h);
    h.finish()
}

impl ShaderCompiler {
    /// A compiler for the shaders under `root`. Debug info is emitted in debug builds.
    pub fn new(root: impl Into<PathBuf>) -> Result<Self> {
        let compiler = shaderc::Compiler::new().map_err(|e| Error::Shader {
            path: "<compiler>".into(),
            message: e.to_string(),
        })?;
        Ok(ShaderCompiler {
            compiler,
            root: root.into(),
            debug_info: cfg!(debug_assertions),
            cache: Mutex::new(HashMap::new()),
        })
    }

    /// The shader root folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    fn read(&self, rel: &str) -> std::result::Result<String, String> {
        let full = self.root.join(rel);
        let text =
            std::fs::read_to_string(&full).map_err(|e| format!("{}: {e}", full.display()))?;
        if text.contains('\0') {
            return Err(format!("{}: contains a NUL byte", full.display()));
        }
        Ok(text)
    }

    /// Compiles `path` (relative to the root) with `defines`, or returns the cached SPIR-V.
    pub fn compile(&self, path: &str, defines: &[(&str, &str)]) -> Result<Arc<Vec<u32>>> {
        let shader_err = |message: String| Error::Shader {
            path: path.to_string(),
            message,
        };
        let stage = ShaderStage::from_path(path)
            .ok_or_else(|| shader_err("unknown stage (expected .comp, .vert or .frag)".into()))?;
        let mut defs: Vec<(String, String)> = defines
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        defs.sort();
        let key = (path.to_string(), defs);
        if let Some(spirv) = self.cached(&key) {
            return Ok(spirv);
        }
        let source = self.read(path).map_err(shader_err)?;
        let read_files = RefCell::new(vec![(path.to_string(), hash_text(&source))]);
        let mut options = shaderc::CompileOptions::new().map_err(|e| shader_err(e.to_string()))?;
        options.set_target_env(
            shaderc::TargetEnv::Vulkan,
            shaderc::EnvVersion::Vulkan1_3 as u32,
        );
        options.set_target_spirv(shaderc::SpirvVersion::V1_6);
        options.set_source_language(shaderc::SourceLanguage::GLSL);
        options.set_optimization_level(shaderc::OptimizationLevel::Performance);
        if self.debug_info {
            options.set_generate_debug_info();
        }
        for (k, v) in &key.1 {
            options.add_macro_definition(k, Some(v));
        }
        options.set_include_callback(|requested, kind, requester, _depth| {
            let candidates = match kind {
                shaderc::IncludeType::Relative => {
                    let dir = Path::new(requester).parent().unwrap_or(Path::new(""));
                    vec![dir.join(requested), PathBuf::from(requested)]
                }
                shaderc::IncludeType::Standard => vec![PathBuf::from(requested)],
            };
            for c in candidates {
                let rel = c.to_string_lossy().replace('\\', "/");
                if self.root.join(&rel).is_file() {
                    let content = self.read(&rel)?;
                    read_files
                        .borrow_mut()
                        .push((rel.clone(), hash_text(&content)));
                    return Ok(shaderc::ResolvedInclude {
                        resolved_name: rel,
                        content,
                    });
                }
            }
            Err(format!(
                "cannot find include {requested:?} (from {requester})"
            ))
        });
        let artifact = self
            .compiler
            .compile_into_spirv(&source, stage.kind(), path, "main", Some(&options))
            .map_err(|e| match e {
                shaderc::Error::CompilationError(_, msg) => shader_err(msg.trim_end().to_string()),
                other => shader_err(other.to_string()),
            })?;
        if artifact.get_num_warnings() > 0 {
            log::warn!(
                "shader {path}: {}",
                artifact.get_warning_messages().trim_end()
            );
        }
        let spirv = Arc::new(artifact.as_binary().to_vec());
        drop(options);
        let files = read_files.into_inner();
        self.cache.lock().unwrap_or_else(|p| p.into_inner()).insert(
            key,
            Entry {
                files,
                spirv: spirv.clone(),
            },
        );
        Ok(spirv)
    }

    fn cached(&self, key: &Key) -> Option<Arc<Vec<u32>>> {
        let cache = self.cache.lock().unwrap_or_else(|p| p.into_inner());
        let entry = cache.get(key)?;
        let fresh = entry
            .files
            .iter()
            .all(|(rel, h)| self.read(rel).is_ok_and(|t| hash_text(&t) == *h));
        fresh.then(|| entry.spirv.clone())
    }
}
