//! GPU buffers (RAII over gpu-allocator), with typed upload and readback through `bytemuck`.
//!
//! Host-visible buffers (`CpuToGpu`, `GpuToCpu`) are written and read through their mapping;
//! device-local ones are filled through a staging copy ([`Context::create_buffer_init`]) and read
//! back the same way ([`Context::read_buffer`]). lavapipe maps everything, but nothing here relies
//! on that.
//!
//! # Host access and the GPU
//! Every recording that takes a buffer (as a binding, indirect arguments, a copy or fill source or
//! destination, an index buffer) records its index in the buffer. A host write ([`Buffer::write`])
//! or read ([`Buffer::read`]) is refused with [`Error::Invalid`] while one of those recordings is
//! submitted and not yet waited for (its [`Submission`](crate::Submission) neither waited nor
//! dropped): the GPU may be reading what the host would overwrite, or writing what the host would
//! read. A recording still being recorded does not count: the host writes made before
//! `vkQueueSubmit` are visible to the submitted commands (host-coherent memory), so filling a
//! buffer after recording the pass that reads it and before submitting it is sound. Refusing is
//! simpler than waiting (a buffer holds no fence to wait on) and turns a silent race into an error
//! that names the buffer; radcache waits for each submission before touching its buffers again.

use std::sync::{Arc, Mutex};

use ash::vk;
use bytemuck::Pod;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;

use crate::context::{Context, DeviceShared, Garbage};
use crate::error::{Error, Result, VkResultExt};
use crate::hazard::Target;

/// What to create.
#[derive(Debug, Clone)]
pub struct BufferDesc<'a> {
    /// Debug and allocation name (e.g. `"ircache.records"`).
    pub name: &'a str,
    /// Size in bytes (0 is rounded up to 16: Vulkan forbids empty buffers).
    pub size: u64,
    /// Usage; `TRANSFER_SRC | TRANSFER_DST` are always added.
    pub usage: vk::BufferUsageFlags,
    /// Where the memory lives.
    pub location: MemoryLocation,
    /// Extra alignment (e.g. AS scratch offset alignment); 0 for none.
    pub alignment: u64,
}

/// A GPU buffer. Destroyed after the GPU is done with it.
pub struct Buffer {
    shared: Arc<DeviceShared>,
    raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
    /// The usage it was created with (`TRANSFER_SRC | TRANSFER_DST` included).
    usage: vk::BufferUsageFlags,
    /// Indices of the recordings that took this buffer and had not ended when it was last taken.
    uses: Mutex<Vec<u64>>,
    /// Its track: its last use, from which the barrier of its next use is derived (`hazard.rs`).
    pub(crate) target: Target,
    address: Option<u64>,
    name: String,
    alloc_id: u64,
}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Buffer")
            .field("name", &self.name)
            .field("size", &self.size)
            .finish()
    }
}

impl Buffer {
    /// Creates a buffer.
    pub fn new(ctx: &Context, desc: &BufferDesc<'_>) -> Result<Self> {
        let shared = &ctx.shared;
        let size = desc.size.max(16);
        let usage =
            desc.usage | vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST;
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: the device is live and `info` is valid for the call.
        let raw = unsafe { shared.device.create_buffer(&info, None) }.call("vkCreateBuffer")?;
        // SAFETY: `raw` was just created from this device.
        let mut requirements = unsafe { shared.device.get_buffer_memory_requirements(raw) };
        requirements.alignment = requirements.alignment.max(desc.alignment);
        let allocation = shared.lock_allocator().as_mut().map(|a| {
            a.allocate(&AllocationCreateDesc {
                name: desc.name,
                requirements,
                location: desc.location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
        });
        let allocation = match allocation {
            Some(Ok(a)) => a,
            other => {
                // SAFETY: `raw` is unused and unbound.
                unsafe { shared.device.destroy_buffer(raw, None) };
                return Err(match other {
                    Some(Err(source)) => Error::Alloc {
                        name: desc.name.to_string(),
                        source,
                    },
                    _ => Error::Invalid("allocator already shut down".into()),
                });
            }
        };
        // SAFETY: memory and offset come from an allocation made for these requirements.
        let bound = unsafe {
            shared
                .device
                .bind_buffer_memory(raw, allocation.memory(), allocation.offset())
        };
        let alloc_id = shared.register(desc.name);
        let mut buffer = Buffer {
            shared: shared.clone(),
            raw,
            allocation: Some(allocation),
            size,
            usage,
            uses: Mutex::new(Vec::new()),
            target: Target::new(desc.name, None),
            address: None,
            name: desc.name.to_string(),
            alloc_id,
        };
        bound.call("vkBindBufferMemory")?;
        if usage.contains(vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS) {
            let info = vk::BufferDeviceAddressInfo::default().buffer(raw);
            // SAFETY: the buffer was created with SHADER_DEVICE_ADDRESS usage and is bound.
            buffer.address = Some(unsafe { shared.device.get_buffer_device_address(&info) });
        }
        shared.set_name(raw, desc.name);
        Ok(buffer)
    }

    /// The raw handle (for this crate's command recording).
    pub(crate) fn raw(&self) -> vk::Buffer {
        self.raw
    }

    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// The usage flags it was created with (`TRANSFER_SRC | TRANSFER_DST` always included).
    pub fn usage(&self) -> vk::BufferUsageFlags {
        self.usage
    }

    /// Records that recording `index` takes this buffer (forgetting recordings that have ended).
    pub(crate) fn used_by(&self, index: u64) {
        let mut uses = self.uses.lock().unwrap_or_else(|p| p.into_inner());
        if uses.contains(&index) {
            return;
        }
        self.shared.retain_outstanding(&mut uses);
        uses.push(index);
    }

    /// Refuses host access (`what`: "write" or "read") while a submitted recording that took
    /// this buffer has not been waited for.
    fn check_idle(&self, what: &str) -> Result<()> {
        let uses = self.uses.lock().unwrap_or_else(|p| p.into_inner());
        match self.shared.first_in_flight(&uses) {
            None => Ok(()),
            Some(index) => Err(Error::Invalid(format!(
                "host {what} of buffer {:?} while submission {index}, which uses it, is still in \
                 flight (wait for it first)",
                self.name
            ))),
        }
    }

    /// The allocation name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The device address; the buffer must have `SHADER_DEVICE_ADDRESS` usage.
    pub fn device_address(&self) -> Result<u64> {
        self.address.ok_or_else(|| {
            Error::Invalid(format!(
                "buffer {:?} has no SHADER_DEVICE_ADDRESS usage",
                self.name
            ))
        })
    }

    /// Whether the buffer is mapped into host-coherent memory (what [`Self::write`] and
    /// [`Self::read`] need: they neither flush nor invalidate).
    pub fn is_mapped(&self) -> bool {
        self.allocation.as_ref().is_some_and(|a| {
            a.mapped_slice().is_some()
                && a.memory_properties()
                    .contains(vk::MemoryPropertyFlags::HOST_COHERENT)
        })
    }

    /// Writes `data` at byte `offset` of a host-visible buffer. Refused (an error naming the
    /// buffer) while a submitted recording that uses the buffer has not been waited for: see the
    /// module documentation.
    pub fn write<T: Pod>(&mut self, offset: u64, data: &[T]) -> Result<()> {
        self.check_idle("write")?;
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let name = self.name.clone();
        if !self.is_mapped() {
            return Err(Error::Invalid(format!(
                "buffer {name:?} is not host visible and coherent"
            )));
        }
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| Error::Invalid(format!("buffer {name:?} is not host visible")))?;
        let start = usize::try_from(offset).unwrap_or(usize::MAX);
        let end = start.saturating_add(bytes.len());
        if end > slice.len() {
            return Err(Error::Invalid(format!(
                "write of {} bytes at {offset} overflows buffer {name:?} ({} bytes)",
                bytes.len(),
                slice.len()
            )));
        }
        slice[start..end].copy_from_slice(bytes);
        Ok(())
    }

    /// Reads `count` elements of `T` from a host-visible buffer. Refused (an error naming the
    /// buffer) while a submitted recording that uses the buffer has not been waited for: the GPU
    /// may still be writing it (see the module documentation).
    pub fn read<T: Pod>(&self, count: usize) -> Result<Vec<T>> {
        self.check_idle("read")?;
        if !self.is_mapped() {
            return Err(Error::Invalid(format!(
                "buffer {:?} is not host visible and coherent",
                self.name
            )));
        }
        let slice = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .ok_or_else(|| Error::Invalid(format!("buffer {:?} is not host visible", self.name)))?;
        let bytes = count * std::mem::size_of::<T>();
        if bytes > slice.len() {
            return Err(Error::Invalid(format!(
                "read of {bytes} bytes overflows buffer {:?}",
                self.name
            )));
        }
        // Copy through a correctly aligned vector (the mapping may not be aligned for T).
        let mut out = vec![T::zeroed(); count];
        bytemuck::cast_slice_mut::<T, u8>(&mut out).copy_from_slice(&slice[..bytes]);
        Ok(out)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        self.shared.unregister(self.alloc_id);
        if let Some(a) = self.allocation.take() {
            self.shared.retire(Garbage::Buffer(self.raw, a));
        }
    }
}

impl Context {
    /// Creates a device-local buffer holding `data` (uploaded through a staging buffer).
    pub fn create_buffer_init<T: Pod>(
        &self,
        name: &str,
        usage: vk::BufferUsageFlags,
        data: &[T],
    ) -> Result<Buffer> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let buffer = Buffer::new(
            self,
            &BufferDesc {
                name,
                size: bytes.len() as u64,
                usage,
                location: MemoryLocation::GpuOnly,
                alignment: 0,
            },
        )?;
        if !bytes.is_empty() {
            let mut staging = Buffer::new(
                self,
                &BufferDesc {
                    name: "staging.upload",
                    size: bytes.len() as u64,
                    usage: vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::CpuToGpu,
                    alignment: 0,
                },
            )?;
            staging.write(0, bytes)?;
            let mut rec = self.begin("upload")?;
            rec.copy_buffer(&staging, 0, &buffer, 0, bytes.len() as u64);
            self.submit(rec)?.wait()?;
        }
        Ok(buffer)
    }

    /// Copies `count` elements of `T` out of any buffer (through a staging buffer).
    pub fn read_buffer<T: Pod>(&self, buffer: &Buffer, count: usize) -> Result<Vec<T>> {
        let bytes = (count * std::mem::size_of::<T>()) as u64;
        if bytes > buffer.size() {
            return Err(Error::Invalid(format!(
                "reading {bytes} bytes from buffer {:?} of {} bytes",
                buffer.name(),
                buffer.size()
            )));
        }
        let staging = Buffer::new(
            self,
            &BufferDesc {
                name: "staging.readback",
                size: bytes,
                usage: vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
                alignment: 0,
            },
        )?;
        let mut rec = self.begin("readback")?;
        rec.copy_buffer(buffer, 0, &staging, 0, bytes);
        self.submit(rec)?.wait()?;
        staging.read(count)
    }
}
