//! Run-time GLSL compilation with shaderc.
//!
//! Shaders live under one root folder (the repository's `shaders/`). `#include "x.glsl"` resolves
//! relative to the including file first, then to the root. Defines are passed per compile. The
//! target is Vulkan 1.3 / SPIR-V 1.6 (ray queries need SPIR-V 1.4+). Errors carry `file:line`
//! relative to the root. Results are cached in memory by (path, defines), and on disk as well with
//! [`ShaderCompiler::with_disk_cache`] (`crate::spirv_cache`, keyed by path, defines and compiler
//! options); a cached entry is reused only while the contents of every file it read are
//! unchanged, so edits are picked up on the next compile (hot reload without a watcher).

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};
use crate::spirv_cache::{self, hash_source as hash_text, Compiled, DiskCache};

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

/// What a [`ShaderCompiler`] did since it was created.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ShaderStats {
    /// Modules compiled by shaderc.
    pub compiled: u32,
    /// Modules returned from the in-memory cache.
    pub reused: u32,
    /// Modules read from the on-disk cache.
    pub from_disk: u32,
    /// Seconds spent compiling (shaderc, reading the sources included).
    pub compile_s: f64,
}

/// The shader compiler: one shaderc instance (the first compile in a process is slow), a root
/// folder and the in-memory cache.
pub struct ShaderCompiler {
    compiler: shaderc::Compiler,
    root: PathBuf,
    debug_info: bool,
    cache: Mutex<HashMap<Key, Entry>>,
    disk: Option<DiskCache>,
    stats: Mutex<ShaderStats>,
}

impl std::fmt::Debug for ShaderCompiler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShaderCompiler")
            .field("root", &self.root)
            .finish()
    }
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
            disk: None,
            stats: Mutex::new(ShaderStats::default()),
        })
    }

    /// Keeps compiled modules on disk as well, under `dir/spirv/` (`dir` is the pipeline cache's
    /// folder, e.g. [`crate::pipeline_cache_dir_from_env`]; `None` keeps them in memory only).
    pub fn with_disk_cache(mut self, dir: Option<&Path>) -> Self {
        self.disk = dir.map(DiskCache::new);
        self
    }

    fn lock_stats(&self) -> std::sync::MutexGuard<'_, ShaderStats> {
        self.stats.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn options_text(&self) -> String {
        format!(
            "vulkan1.3 spirv1.6 glsl performance debug={}",
            self.debug_info
        )
    }

    /// How many modules were compiled, reused and read from disk, and the seconds compiling took.
    pub fn stats(&self) -> ShaderStats {
        *self.stats.lock().unwrap_or_else(|p| p.into_inner())
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
            self.lock_stats().reused += 1;
            return Ok(spirv);
        }
        let disk_key = spirv_cache::key(path, &key.1, &self.options_text());
        let fresh = |rel: &str, h: u64| self.read(rel).is_ok_and(|t| hash_text(&t) == h);
        if let Some(c) = self.disk.as_ref().and_then(|d| d.load(disk_key, fresh)) {
            let spirv = Arc::new(c.spirv);
            self.remember(key, c.files, spirv.clone());
            self.lock_stats().from_disk += 1;
            return Ok(spirv);
        }
        let started = std::time::Instant::now();
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
        {
            let mut stats = self.lock_stats();
            stats.compiled += 1;
            stats.compile_s += started.elapsed().as_secs_f64();
        }
        let files = read_files.into_inner();
        if let Some(disk) = &self.disk {
            let compiled = Compiled {
                files: files.clone(),
                spirv: spirv.to_vec(),
            };
            disk.store(disk_key, &compiled);
        }
        self.remember(key, files, spirv.clone());
        Ok(spirv)
    }

    fn remember(&self, key: Key, files: Vec<(String, u64)>, spirv: Arc<Vec<u32>>) {
        let mut cache = self.cache.lock().unwrap_or_else(|p| p.into_inner());
        cache.insert(key, Entry { files, spirv });
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
