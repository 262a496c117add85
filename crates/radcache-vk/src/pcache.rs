//! The persistent pipeline cache: one `VkPipelineCache` per context, loaded from and saved to a
//! file per device and driver ([`crate::pcache_file`]), and the count of pipelines compiled from
//! scratch.
//!
//! **Counting.** A pipeline counts as a cache hit when the driver says so in its creation
//! feedback (`APPLICATION_PIPELINE_CACHE_HIT`), or when radcache's own index says the cache holds
//! it *and* the driver's cache holds pipelines at all. The index lists a [`PipelineKey`] — a hash
//! of every stage's SPIR-V and the pipeline's description — for each pipeline created through the
//! cache (saved in the file beside the driver's data). The second condition keeps the count
//! honest on drivers whose cache is a stub: lavapipe (Mesa 25) reports `VALID` feedback but never
//! a hit, and its `vkGetPipelineCacheData` returns only the 32-byte Vulkan header, so on lavapipe
//! every pipeline counts as compiled from scratch, as it is (its compile cost is JIT work at the
//! first dispatch, which Mesa's own shader disk cache persists; docs/design.md, "Pipeline
//! cache").
//!
//! **Saving.** The file is read once when the context is created and written (atomically: a
//! temporary file renamed over it) when the context shuts down or its device is dropped, only if
//! a pipeline was added since the last save. A file that cannot be used — truncated, garbage,
//! another device's or driver's, a bad checksum — is ignored with one warning naming it, and
//! replaced at the next save.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use ash::vk;

use crate::error::{Result, VkResultExt};
use crate::pcache_file::{self, fnv1a, write_atomically, Contents, Identity, FNV_OFFSET};
use crate::pipeline::{BindingLayout, GraphicsDesc};

/// How many pipelines a context created and how: counts since the context was created.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PipelineStats {
    /// Pipelines created.
    pub created: u32,
    /// Of those, pipelines not found in the pipeline cache (compiled by the driver from SPIR-V).
    pub compiled_from_scratch: u32,
    /// Of those, pipelines the cache already held (`created - compiled_from_scratch`).
    pub cache_hits: u32,
    /// Of those, pipelines radcache's index lists: created through this cache (this run or one
    /// whose file was loaded) before. A hit where the driver's cache holds pipelines.
    pub indexed: u32,
    /// Seconds spent in `vkCreate*Pipelines`, summed.
    pub creation_s: f64,
    /// Bytes of the driver's cache data before the last creation (32, the Vulkan header alone,
    /// where the driver keeps no pipelines in it, as on lavapipe).
    pub driver_cache_bytes: u64,
}

/// Whether a pipeline was found in the cache: the driver's feedback says so, or the index holds
/// its key and the driver's cache holds more than its header.
pub(crate) fn is_cache_hit(feedback_hit: bool, indexed: bool, driver_cache_bytes: u64) -> bool {
    feedback_hit || (indexed && driver_cache_bytes > pcache_file::VK_HEADER_LEN as u64)
}

/// A stable hash of what makes a pipeline: its stages' SPIR-V and its description.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct PipelineKey(pub u64);

struct KeyHasher(u64);

impl KeyHasher {
    fn new(kind: &str) -> Self {
        KeyHasher(fnv1a(FNV_OFFSET, kind.as_bytes()))
    }
    fn bytes(&mut self, b: &[u8]) -> &mut Self {
        // The length first, so that consecutive fields cannot run into each other.
        self.0 = fnv1a(self.0, &(b.len() as u64).to_le_bytes());
        self.0 = fnv1a(self.0, b);
        self
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    fn layout(&mut self, bindings: &[BindingLayout], push_constant_size: u32) -> &mut Self {
        self.u32(bindings.len() as u32);
        for b in bindings {
            self.u32(b.binding)
                .i32(b.kind.descriptor_type().as_raw())
                .u32(b.count);
        }
        self.u32(push_constant_size)
    }
}

impl PipelineKey {
    /// The key of a compute pipeline.
    pub(crate) fn compute(spirv: &[u32], bindings: &[BindingLayout], push: u32) -> Self {
        let mut h = KeyHasher::new("compute");
        h.bytes(bytemuck::cast_slice(spirv)).layout(bindings, push);
        PipelineKey(h.0)
    }

    /// The key of a graphics pipeline (every field of the description but its name).
    pub(crate) fn graphics(desc: &GraphicsDesc<'_>) -> Self {
        let mut h = KeyHasher::new("graphics");
        h.bytes(bytemuck::cast_slice(desc.vertex))
            .bytes(bytemuck::cast_slice(desc.fragment))
            .layout(desc.bindings, desc.push_constant_size)
            .u32(desc.color_formats.len() as u32);
        for f in desc.color_formats {
            h.i32(f.as_raw());
        }
        match desc.depth {
            None => h.u32(0),
            Some(d) => h
                .u32(1)
                .i32(d.format.as_raw())
                .i32(d.compare.as_raw())
                .u32(u32::from(d.write)),
        };
        h.u32(desc.blend as u32)
            .u32(desc.cull.as_raw())
            .i32(desc.topology.as_raw());
        PipelineKey(h.0)
    }
}

/// The context's pipeline cache.
pub(crate) struct PipelineCache {
    raw: vk::PipelineCache,
    /// The file, when the cache persists.
    path: Option<PathBuf>,
    identity: Identity,
    /// Keys of the pipelines the cache holds: loaded from the file, and created since.
    known: Mutex<HashSet<u64>>,
    /// A pipeline was compiled from scratch since the last save.
    dirty: AtomicBool,
    stats: Mutex<PipelineStats>,
    /// The one warning about the file, if it could not be used.
    warning: Option<String>,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// Reads the cache file: its contents, or the warning that says why it was not used (a missing
/// file is no warning: the first run on a machine has none).
fn read(path: &Path, identity: &Identity) -> (Contents, Option<String>) {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return (Contents::default(), None),
        Err(e) => {
            let w = format!("ignoring the pipeline cache {}: {e}", path.display());
            return (Contents::default(), Some(w));
        }
    };
    match pcache_file::decode(identity, &bytes) {
        Ok(c) => (c, None),
        Err(rejection) => {
            let w = format!(
                "ignoring the pipeline cache {}: {rejection}",
                path.display()
            );
            (Contents::default(), Some(w))
        }
    }
}

fn create_raw(device: &ash::Device, data: &[u8]) -> Result<vk::PipelineCache> {
    let info = vk::PipelineCacheCreateInfo::default().initial_data(data);
    // SAFETY: the device is live; `data` is empty or was written by `vkGetPipelineCacheData` of a
    // device with this vendor id, device id, `pipelineCacheUUID` and driver version (its radcache
    // header, checksum and Vulkan header are checked by `pcache_file::decode`); `info` outlives
    // the call.
    unsafe { device.create_pipeline_cache(&info, None) }.call("vkCreatePipelineCache")
}

impl PipelineCache {
    /// The cache of a new device: from `dir`'s file for this device when `dir` is given and the
    /// file is usable, else empty.
    pub(crate) fn open(
        device: &ash::Device,
        dir: Option<&Path>,
        identity: Identity,
    ) -> Result<Self> {
        let path = dir.map(|d| d.join(identity.file_name()));
        let (contents, mut warning) = match &path {
            Some(p) => read(p, &identity),
            None => (Contents::default(), None),
        };
        let raw = match create_raw(device, &contents.data) {
            Ok(raw) => raw,
            Err(e) if !contents.data.is_empty() => {
                if let Some(p) = &path {
                    warning = Some(format!("ignoring the pipeline cache {}: {e}", p.display()));
                }
                create_raw(device, &[])?
            }
            Err(e) => return Err(e),
        };
        let known = if warning.is_none() {
            contents.keys.into_iter().collect()
        } else {
            HashSet::new()
        };
        if let Some(w) = &warning {
            log::warn!("{w}");
        }
        Ok(PipelineCache {
            raw,
            path,
            identity,
            known: Mutex::new(known),
            dirty: AtomicBool::new(false),
            stats: Mutex::new(PipelineStats::default()),
            warning,
        })
    }

    /// The cache handle to create pipelines with.
    pub(crate) fn raw(&self) -> vk::PipelineCache {
        self.raw
    }

    /// The file, when the cache persists.
    pub(crate) fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// The warning given about the file when the context was created, if any.
    pub(crate) fn warning(&self) -> Option<&str> {
        self.warning.as_deref()
    }

    pub(crate) fn stats(&self) -> PipelineStats {
        *lock(&self.stats)
    }

    /// Bytes of the driver's cache data now (0 if the driver does not say).
    pub(crate) fn driver_bytes(&self, device: &ash::Device) -> u64 {
        let mut size = 0usize;
        // SAFETY: the device and the cache are live; a null data pointer asks only for the size,
        // written to `size`, which outlives the call. The cache is internally synchronized.
        let result = unsafe {
            (device.fp_v1_0().get_pipeline_cache_data)(
                device.handle(),
                self.raw,
                &mut size,
                std::ptr::null_mut(),
            )
        };
        if result == vk::Result::SUCCESS {
            size as u64
        } else {
            0
        }
    }

    /// Records a pipeline created through the cache: its creation began at `started`, when the
    /// driver's cache held `driver_bytes`.
    pub(crate) fn record(
        &self,
        key: PipelineKey,
        feedback: &vk::PipelineCreationFeedback,
        started: Instant,
        driver_bytes: u64,
    ) {
        let seconds = started.elapsed().as_secs_f64();
        let flags = vk::PipelineCreationFeedbackFlags::VALID
            | vk::PipelineCreationFeedbackFlags::APPLICATION_PIPELINE_CACHE_HIT;
        let indexed = !lock(&self.known).insert(key.0);
        if !indexed {
            self.dirty.store(true, Ordering::SeqCst);
        }
        let hit = is_cache_hit(feedback.flags.contains(flags), indexed, driver_bytes);
        log::debug!(
            "pipeline {:016x}: {} in {:.1} ms (feedback {:?})",
            key.0,
            if hit { "cache hit" } else { "compiled" },
            seconds * 1e3,
            feedback.flags
        );
        let mut s = lock(&self.stats);
        s.created += 1;
        s.creation_s += seconds;
        s.driver_cache_bytes = driver_bytes;
        s.indexed += u32::from(indexed);
        if hit {
            s.cache_hits += 1;
        } else {
            s.compiled_from_scratch += 1;
        }
    }

    /// Writes the file if a pipeline was compiled since the last save. Failures are logged, not
    /// returned: a cache that could not be saved only costs the next run its compile time.
    pub(crate) fn save(&self, device: &ash::Device) {
        let Some(path) = &self.path else { return };
        if !self.dirty.swap(false, Ordering::SeqCst) {
            return;
        }
        let started = Instant::now();
        // SAFETY: the device and the cache are live; the cache is internally synchronized (no
        // creation flag says otherwise), so pipelines may be created from other threads meanwhile.
        let data = match unsafe { device.get_pipeline_cache_data(self.raw) } {
            Ok(d) => d,
            Err(e) => {
                log::warn!(
                    "not saving the pipeline cache {}: vkGetPipelineCacheData failed: {e:?}",
                    path.display()
                );
                return;
            }
        };
        let mut keys: Vec<u64> = lock(&self.known).iter().copied().collect();
        keys.sort_unstable();
        let bytes = pcache_file::encode(&self.identity, &Contents { keys, data });
        match write_atomically(path, &bytes) {
            Ok(()) => log::info!(
                "saved the pipeline cache {} ({} KiB in {:.1} ms)",
                path.display(),
                bytes.len() / 1024,
                started.elapsed().as_secs_f64() * 1e3
            ),
            Err(e) => log::warn!("not saving the pipeline cache {}: {e}", path.display()),
        }
    }

    /// Destroys the Vulkan object (the device must be idle of pipeline creation).
    pub(crate) fn destroy(&self, device: &ash::Device) {
        // SAFETY: called once, from `DeviceShared::drop`, before the device is destroyed; no
        // pipeline creation can be running, since every object holding the device is gone.
        unsafe { device.destroy_pipeline_cache(self.raw, None) };
    }
}

impl From<&crate::DeviceInfo> for Identity {
    fn from(info: &crate::DeviceInfo) -> Self {
        Identity {
            vendor_id: info.vendor_id,
            device_id: info.device_id,
            driver_version: info.driver_version,
            uuid: info.pipeline_cache_uuid,
        }
    }
}

impl crate::Context {
    /// How many pipelines this context created, how many of them were compiled from scratch
    /// (not found in the persistent pipeline cache) and the seconds their creation took.
    pub fn pipeline_stats(&self) -> PipelineStats {
        self.shared.pipeline_cache.stats()
    }

    /// The persistent pipeline cache's file for this device, if the cache persists
    /// ([`crate::ContextOptions::pipeline_cache_dir`]).
    pub fn pipeline_cache_file(&self) -> Option<&Path> {
        self.shared.pipeline_cache.path()
    }

    /// The warning given when the pipeline cache's file could not be used (corrupt, truncated,
    /// another device's or driver's), if it was not.
    pub fn pipeline_cache_warning(&self) -> Option<&str> {
        self.shared.pipeline_cache.warning()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::{BindingKind, Blend, DepthState};

    #[test]
    fn a_hit_needs_the_feedback_or_the_index_and_a_driver_cache_with_contents() {
        assert!(is_cache_hit(true, false, 0));
        assert!(is_cache_hit(false, true, 4096));
        // Lavapipe: the index knows the pipeline, the driver's cache is its header alone.
        assert!(!is_cache_hit(false, true, 32));
        assert!(!is_cache_hit(false, false, 4096));
    }

    #[test]
    fn keys_change_with_the_spirv_and_every_field_of_the_description() {
        let spirv = [0x0723_0203, 1, 2, 3, 4];
        let other = [0x0723_0203, 1, 2, 3, 5];
        let b = [BindingLayout::new(0, BindingKind::StorageBuffer)];
        let c = [BindingLayout::new(0, BindingKind::UniformBuffer)];
        let base = PipelineKey::compute(&spirv, &b, 8);
        assert_eq!(base, PipelineKey::compute(&spirv, &b, 8));
        assert_ne!(base, PipelineKey::compute(&other, &b, 8));
        assert_ne!(base, PipelineKey::compute(&spirv, &c, 8));
        assert_ne!(base, PipelineKey::compute(&spirv, &b, 16));
        let formats = [vk::Format::R32G32B32A32_SFLOAT];
        let desc = GraphicsDesc {
            name: "a",
            vertex: &spirv,
            fragment: &other,
            bindings: &b,
            push_constant_size: 0,
            color_formats: &formats,
            depth: None,
            blend: Blend::None,
            cull: vk::CullModeFlags::NONE,
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
        };
        let g = PipelineKey::graphics(&desc);
        assert_eq!(
            g,
            PipelineKey::graphics(&GraphicsDesc {
                name: "b",
                ..desc.clone()
            })
        );
        let variants = [
            GraphicsDesc {
                vertex: &other,
                ..desc.clone()
            },
            GraphicsDesc {
                blend: Blend::Additive,
                ..desc.clone()
            },
            GraphicsDesc {
                cull: vk::CullModeFlags::BACK,
                ..desc.clone()
            },
            GraphicsDesc {
                color_formats: &[],
                ..desc.clone()
            },
            GraphicsDesc {
                depth: Some(DepthState {
                    format: vk::Format::D32_SFLOAT,
                    compare: vk::CompareOp::LESS,
                    write: true,
                }),
                ..desc.clone()
            },
            GraphicsDesc {
                topology: vk::PrimitiveTopology::POINT_LIST,
                ..desc.clone()
            },
        ];
        for v in &variants {
            assert_ne!(g, PipelineKey::graphics(v));
        }
    }
}
