//! The on-disk SPIR-V cache of [`crate::ShaderCompiler`]: one file per (entry path, defines,
//! compiler options) in `<dir>/spirv/`, holding the list of every file the compile read with the
//! hash of its contents, and the SPIR-V.
//!
//! Layout (little-endian): magic `RCSPIRV\0`, format version, key (u64), number of files, SPIR-V
//! words, FNV-1a checksum of the body (u64); then the body: per file its path (u32 length, UTF-8)
//! and content hash (u64), then the words. An entry is used only while every file it lists still
//! hashes the same (an edited include recompiles); one that cannot be decoded is ignored with one
//! warning naming it and overwritten by the fresh compile.

use std::path::{Path, PathBuf};

use crate::pcache_file::{fnv1a, write_atomically, FNV_OFFSET};
use crate::pipeline::SPIRV_MAGIC;

const MAGIC: [u8; 8] = *b"RCSPIRV\0";
const FORMAT_VERSION: u32 = 1;
const HEADER_LEN: usize = 8 + 4 + 8 + 4 + 4 + 8;

/// What a compile produced: the files it read (path relative to the shader root, content hash)
/// and the module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Compiled {
    pub files: Vec<(String, u64)>,
    pub spirv: Vec<u32>,
}

/// The hash of a source file's contents, as stored in an entry.
pub(crate) fn hash_source(text: &str) -> u64 {
    fnv1a(FNV_OFFSET, text.as_bytes())
}

/// The key of a compile: the entry path, the sorted defines and everything that changes the
/// compiler's output (options, the compiler's and this crate's version).
pub(crate) fn key(path: &str, defines: &[(String, String)], options: &str) -> u64 {
    let mut h = fnv1a(FNV_OFFSET, b"radcache-spirv");
    let (spirv_version, spirv_revision) = shaderc::get_spirv_version();
    let versions = format!(
        "{} spirv {spirv_version}.{spirv_revision}",
        env!("CARGO_PKG_VERSION")
    );
    for part in [versions.as_str(), options, path]
        .into_iter()
        .chain(defines.iter().flat_map(|(k, v)| [k.as_str(), v.as_str()]))
    {
        h = fnv1a(h, &(part.len() as u64).to_le_bytes());
        h = fnv1a(h, part.as_bytes());
    }
    h
}

pub(crate) fn encode(key: u64, c: &Compiled) -> Vec<u8> {
    let mut body = Vec::new();
    for (path, hash) in &c.files {
        body.extend_from_slice(&(path.len() as u32).to_le_bytes());
        body.extend_from_slice(path.as_bytes());
        body.extend_from_slice(&hash.to_le_bytes());
    }
    body.extend_from_slice(bytemuck::cast_slice(&c.spirv));
    let mut out = Vec::with_capacity(HEADER_LEN + body.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&key.to_le_bytes());
    out.extend_from_slice(&(c.files.len() as u32).to_le_bytes());
    out.extend_from_slice(&(c.spirv.len() as u32).to_le_bytes());
    out.extend_from_slice(&fnv1a(FNV_OFFSET, &body).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

/// Bounds-checked little-endian reads.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| format!("truncated ({} bytes)", self.bytes.len()))?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
}

/// The entry in `bytes`, written by [`encode`] for `key`, or why it cannot be used.
pub(crate) fn decode(key: u64, bytes: &[u8]) -> Result<Compiled, String> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err("not a radcache SPIR-V cache entry".into());
    }
    let mut r = Reader { bytes, at: 8 };
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "format version {version} (this build reads {FORMAT_VERSION})"
        ));
    }
    if r.u64()? != key {
        return Err("written for another shader or compiler".into());
    }
    let n_files = r.u32()? as usize;
    let n_words = r.u32()? as usize;
    let checksum = r.u64()?;
    if fnv1a(FNV_OFFSET, &bytes[HEADER_LEN..]) != checksum {
        return Err("checksum mismatch (corrupt)".into());
    }
    let mut files = Vec::new();
    for _ in 0..n_files {
        let len = r.u32()? as usize;
        let path = std::str::from_utf8(r.take(len)?).map_err(|_| "a path is not UTF-8")?;
        files.push((path.to_string(), r.u64()?));
    }
    let words = r.take(n_words.checked_mul(4).ok_or("too many words")?)?;
    if r.at != bytes.len() {
        return Err(format!("{} bytes after the module", bytes.len() - r.at));
    }
    let spirv: Vec<u32> = words
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    if spirv.len() < 5 || spirv[0] != SPIRV_MAGIC {
        return Err("not a SPIR-V module".into());
    }
    Ok(Compiled { files, spirv })
}

/// The cache's folder.
#[derive(Debug, Clone)]
pub(crate) struct DiskCache {
    dir: PathBuf,
}

impl DiskCache {
    /// The SPIR-V cache under `dir` (the pipeline cache's folder).
    pub(crate) fn new(dir: &Path) -> Self {
        DiskCache {
            dir: dir.join("spirv"),
        }
    }

    fn path(&self, key: u64) -> PathBuf {
        self.dir.join(format!("{key:016x}.spv"))
    }

    /// The entry for `key` if there is a usable one whose every file `is_fresh` accepts. A
    /// missing or stale entry is no warning; one that cannot be decoded is, once.
    pub(crate) fn load(&self, key: u64, is_fresh: impl Fn(&str, u64) -> bool) -> Option<Compiled> {
        let path = self.path(key);
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
            Err(e) => {
                log::warn!("ignoring the SPIR-V cache entry {}: {e}", path.display());
                return None;
            }
        };
        match decode(key, &bytes) {
            Ok(c) => c.files.iter().all(|(f, h)| is_fresh(f, *h)).then_some(c),
            Err(why) => {
                log::warn!("ignoring the SPIR-V cache entry {}: {why}", path.display());
                None
            }
        }
    }

    /// Writes the entry for `key` atomically; a failure is a warning (it only costs a compile).
    pub(crate) fn store(&self, key: u64, compiled: &Compiled) {
        let path = self.path(key);
        if let Err(e) = write_atomically(&path, &encode(key, compiled)) {
            log::warn!("not saving the SPIR-V cache entry {}: {e}", path.display());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry() -> Compiled {
        Compiled {
            files: vec![("a.comp".into(), 7), ("inc/b.glsl".into(), u64::MAX)],
            spirv: vec![SPIRV_MAGIC, 0x0001_0600, 0, 12, 0, 0x0002_0011],
        }
    }

    #[test]
    fn round_trip_and_every_corruption_is_refused() {
        let bytes = encode(42, &entry());
        assert_eq!(decode(42, &bytes).unwrap(), entry());
        assert!(decode(43, &bytes).unwrap_err().contains("another shader"));
        for len in 0..bytes.len() {
            assert!(decode(42, &bytes[..len]).is_err(), "length {len}");
        }
        for at in HEADER_LEN..bytes.len() {
            let mut b = bytes.clone();
            b[at] ^= 1;
            assert!(
                decode(42, &b).unwrap_err().contains("checksum"),
                "byte {at}"
            );
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode(42, &longer).is_err());
        assert!(decode(42, b"#version 460\nvoid main() {}").is_err());
    }

    #[test]
    fn keys_differ_by_path_defines_and_options() {
        let d = |k: &str, v: &str| vec![(k.to_string(), v.to_string())];
        let base = key("a.comp", &d("N", "1"), "opt");
        assert_eq!(base, key("a.comp", &d("N", "1"), "opt"));
        assert_ne!(base, key("b.comp", &d("N", "1"), "opt"));
        assert_ne!(base, key("a.comp", &d("N", "2"), "opt"));
        assert_ne!(base, key("a.comp", &d("N1", ""), "opt"));
        assert_ne!(base, key("a.comp", &d("N", "1"), "debug"));
    }
}
