//! The headless Vulkan context: device, queue, allocator, and deferred destruction.
//!
//! Every GPU object holds an `Arc<DeviceShared>`. Dropping an object does not destroy it at once: its
//! handles go to a graveyard tagged with the newest command recording that may reference them, and
//! are destroyed once every recording up to that one has completed (its fence signalled) or been
//! abandoned. `DeviceShared::drop` waits for the device to idle, empties the graveyard, and reports
//! allocations that were never freed.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, MutexGuard};

use ash::vk;
use gpu_allocator::vulkan::{Allocation, Allocator, AllocatorCreateDesc};

use crate::device::{self, DeviceInfo};
use crate::error::{Error, Result, VkResultExt};
use crate::instance::{self, InstanceParts};
use crate::options::ContextOptions;
use crate::pcache::PipelineCache;
use crate::select;

/// A GPU object waiting for the GPU to be done with it.
pub(crate) enum Garbage {
    Buffer(vk::Buffer, Allocation),
    Image(vk::Image, vk::ImageView, Allocation),
    AccelerationStructure(vk::AccelerationStructureKHR),
    Pipeline(vk::Pipeline, vk::PipelineLayout, vk::DescriptorSetLayout),
    QueryPool(vk::QueryPool),
    Sampler(vk::Sampler),
    CommandBuffer(vk::CommandBuffer),
    Fence(vk::Fence),
}

#[derive(Default)]
pub(crate) struct Tracking {
    /// Index of the last recording begun.
    begun: u64,
    /// Recordings begun and neither completed nor abandoned.
    outstanding: BTreeSet<u64>,
    /// The outstanding recordings that were submitted: the GPU may be executing them.
    submitted: BTreeSet<u64>,
    graveyard: Vec<(u64, Garbage)>,
    /// Live allocations: id -> name.
    live: BTreeMap<u64, String>,
    next_alloc_id: u64,
}

/// What every GPU object shares: the device and its per-device state.
pub(crate) struct DeviceShared {
    pub info: DeviceInfo,
    pub queue: Mutex<vk::Queue>,
    pub command_pool: Mutex<vk::CommandPool>,
    pub device: ash::Device,
    pub accel: ash::khr::acceleration_structure::Device,
    pub push_descriptor: ash::khr::push_descriptor::Device,
    pub debug_utils: Option<ash::ext::debug_utils::Device>,
    pub allocator: Mutex<Option<Allocator>>,
    pub tracking: Mutex<Tracking>,
    pub last_pass: Mutex<Option<String>>,
    pub pipeline_cache: PipelineCache,
    pub inst: InstanceParts,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A poisoned lock only means another thread panicked while holding it; the data is plain
    // bookkeeping that stays consistent, so continue.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl DeviceShared {
    pub(crate) fn lock_allocator(&self) -> MutexGuard<'_, Option<Allocator>> {
        lock(&self.allocator)
    }

    pub(crate) fn lock_queue(&self) -> MutexGuard<'_, vk::Queue> {
        lock(&self.queue)
    }

    pub(crate) fn lock_command_pool(&self) -> MutexGuard<'_, vk::CommandPool> {
        lock(&self.command_pool)
    }

    /// Registers a live allocation; returns its id for [`Self::unregister`].
    pub(crate) fn register(&self, name: &str) -> u64 {
        let mut t = lock(&self.tracking);
        t.next_alloc_id += 1;
        let id = t.next_alloc_id;
        t.live.insert(id, name.to_string());
        id
    }

    pub(crate) fn unregister(&self, id: u64) {
        lock(&self.tracking).live.remove(&id);
    }

    /// Starts a recording; returns its index.
    pub(crate) fn begin_recording(&self) -> u64 {
        let mut t = lock(&self.tracking);
        t.begun += 1;
        let index = t.begun;
        t.outstanding.insert(index);
        index
    }

    /// Marks a recording submitted: until it ends, the GPU may be executing it.
    pub(crate) fn mark_submitted(&self, index: u64) {
        lock(&self.tracking).submitted.insert(index);
    }

    /// Marks a recording completed (or abandoned) and destroys what no recording needs any more.
    pub(crate) fn end_recording(&self, index: u64) {
        {
            let mut t = lock(&self.tracking);
            t.outstanding.remove(&index);
            t.submitted.remove(&index);
        }
        self.collect();
    }

    /// Whether recording `index` is still being recorded (begun, neither submitted nor ended).
    pub(crate) fn is_unsubmitted(&self, index: u64) -> bool {
        let t = lock(&self.tracking);
        t.outstanding.contains(&index) && !t.submitted.contains(&index)
    }

    /// Keeps, of the recording indices `uses`, those that have not ended.
    pub(crate) fn retain_outstanding(&self, uses: &mut Vec<u64>) {
        let t = lock(&self.tracking);
        uses.retain(|i| t.outstanding.contains(i));
    }

    /// The first of the recording indices `uses` that is submitted and not yet waited for.
    pub(crate) fn first_in_flight(&self, uses: &[u64]) -> Option<u64> {
        let t = lock(&self.tracking);
        uses.iter().copied().find(|i| t.submitted.contains(i))
    }

    /// Queues `g` for destruction after every recording begun so far has ended.
    pub(crate) fn retire(&self, g: Garbage) {
        {
            let mut t = lock(&self.tracking);
            let tag = t.begun;
            t.graveyard.push((tag, g));
        }
        self.collect();
    }

    /// Destroys garbage that no outstanding recording can reference.
    pub(crate) fn collect(&self) {
        let ready: Vec<Garbage> = {
            let mut t = lock(&self.tracking);
            let oldest = t.outstanding.first().copied().unwrap_or(u64::MAX);
            let (ready, keep): (Vec<_>, Vec<_>) =
                t.graveyard.drain(..).partition(|(tag, _)| *tag < oldest);
            t.graveyard = keep;
            ready.into_iter().map(|(_, g)| g).collect()
        };
        for g in ready {
            self.destroy(g);
        }
    }

    fn destroy(&self, g: Garbage) {
        let d = &self.device;
        match g {
            Garbage::Buffer(b, a) => {
                // SAFETY: (every arm) the handle was created from this device, is owned by the
                // graveyard alone, and no pending command buffer references it (see `collect`).
                unsafe { d.destroy_buffer(b, None) };
                self.free(a);
            }
            Garbage::Image(i, v, a) => {
                // SAFETY: as above; the view goes before its image.
                unsafe {
                    d.destroy_image_view(v, None);
                    d.destroy_image(i, None);
                }
                self.free(a);
            }
            // SAFETY: as above.
            Garbage::AccelerationStructure(a) => unsafe {
                self.accel.destroy_acceleration_structure(a, None)
            },
            // SAFETY: as above; the pipeline goes before its layouts.
            Garbage::Pipeline(p, l, s) => unsafe {
                d.destroy_pipeline(p, None);
                d.destroy_pipeline_layout(l, None);
                d.destroy_descriptor_set_layout(s, None);
            },
            // SAFETY: as above.
            Garbage::QueryPool(q) => unsafe { d.destroy_query_pool(q, None) },
            // SAFETY: as above.
            Garbage::Sampler(s) => unsafe { d.destroy_sampler(s, None) },
            Garbage::CommandBuffer(c) => {
                let pool = self.lock_command_pool();
                // SAFETY: as above; the pool is locked (externally synchronized).
                unsafe { d.free_command_buffers(*pool, &[c]) };
            }
            // SAFETY: as above.
            Garbage::Fence(f) => unsafe { d.destroy_fence(f, None) },
        }
    }

    fn free(&self, a: Allocation) {
        if let Some(alloc) = self.lock_allocator().as_mut() {
            if let Err(e) = alloc.free(a) {
                log::error!("freeing GPU memory failed: {e}");
            }
        }
    }

    /// Gives a Vulkan object a debug name (visible in validation messages and GPU debuggers).
    pub(crate) fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(du) = &self.debug_utils else { return };
        let Ok(cname) = std::ffi::CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&cname);
        // SAFETY: `handle` is a live object of this device; `info` outlives the call.
        if let Err(e) = unsafe { du.set_debug_utils_object_name(&info) } {
            log::debug!("naming {name} failed: {e:?}");
        }
    }

    pub(crate) fn wait_idle(&self) -> Result<()> {
        let _queue = self.lock_queue();
        // SAFETY: the queue lock is held, so no submission races with the wait.
        unsafe { self.device.device_wait_idle() }.call("vkDeviceWaitIdle")
    }
}

impl Drop for DeviceShared {
    fn drop(&mut self) {
        if let Err(e) = self.wait_idle() {
            log::error!("waiting for the device at shutdown: {e}");
        }
        let (garbage, leaked) = {
            let mut t = lock(&self.tracking);
            t.outstanding.clear();
            t.submitted.clear();
            let g: Vec<Garbage> = t.graveyard.drain(..).map(|(_, g)| g).collect();
            (g, std::mem::take(&mut t.live))
        };
        for g in garbage {
            self.destroy(g);
        }
        for name in leaked.values() {
            log::error!("GPU allocation {name:?} was never freed");
        }
        if let Some(alloc) = self.lock_allocator().take() {
            alloc.report_memory_leaks(log::Level::Error);
            drop(alloc);
        }
        self.pipeline_cache.save(&self.device);
        self.pipeline_cache.destroy(&self.device);
        let pool = *self.lock_command_pool();
        // SAFETY: the device is idle and every child object has been destroyed above; the
        // messenger is destroyed before its state box and the instance.
        unsafe {
            self.device.destroy_command_pool(pool, None);
            self.device.destroy_device(None);
            if let Some(du) = &self.inst.debug_utils {
                du.destroy_debug_utils_messenger(self.inst.messenger, None);
            }
            self.inst.instance.destroy_instance(None);
        }
    }
}

/// What is left at shutdown: validation messages and allocations still alive.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ShutdownReport {
    /// Validation errors seen over the context's life.
    pub validation_errors: u32,
    /// Validation warnings seen over the context's life.
    pub validation_warnings: u32,
    /// Names of allocations still alive (objects not dropped before shutdown).
    pub leaked: Vec<String>,
}

/// The Vulkan context: cheap to clone; every GPU object created from it keeps the device alive.
#[derive(Clone)]
pub struct Context {
    pub(crate) shared: Arc<DeviceShared>,
}

impl std::fmt::Debug for Context {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Context")
            .field("device", &self.shared.info.name)
            .finish()
    }
}

impl Context {
    /// Creates a context with [`ContextOptions::from_env`].
    pub fn new() -> Result<Self> {
        Self::with_options(&ContextOptions::from_env())
    }

    /// Creates a context: instance, device choice, logical device, allocator.
    pub fn with_options(opts: &ContextOptions) -> Result<Self> {
        let inst = instance::create_instance(opts.validation, opts.sync_validation)?;
        // From here on, `Guard` destroys the instance if anything fails.
        struct Guard(Option<InstanceParts>);
        impl Drop for Guard {
            fn drop(&mut self) {
                if let Some(i) = self.0.take() {
                    // SAFETY: nothing else was created from the instance on this path.
                    unsafe {
                        if let Some(du) = &i.debug_utils {
                            du.destroy_debug_utils_messenger(i.messenger, None);
                        }
                        i.instance.destroy_instance(None);
                    }
                }
            }
        }
        let mut guard = Guard(Some(inst));
        let inst_ref = guard.0.as_ref().expect("guard holds the instance");
        let instance = &inst_ref.instance;

        // SAFETY: `instance` is a live instance.
        let pds =
            unsafe { instance.enumerate_physical_devices() }.call("vkEnumeratePhysicalDevices")?;
        let caps = pds
            .iter()
            .map(|&pd| device::query_caps(instance, pd))
            .collect::<Result<Vec<_>>>()?;
        let chosen = select::choose(
            &caps,
            &opts.extra_device_extensions,
            opts.device_filter.as_deref(),
        )
        .map_err(Error::NoSuitableDevice)?;
        let pd = pds[chosen];
        let (queue_family, ts_bits) = device::universal_queue_family(instance, pd)
            .ok_or_else(|| Error::MissingFeature("universal queue".into()))?;
        let mut info = device::device_info(instance, pd, ts_bits, inst_ref.validation);
        info.memory_limit = opts.memory_limit;
        log::info!(
            "Vulkan device: {} ({}, {}), validation {}",
            info.name,
            info.kind,
            info.driver,
            if info.validation { "on" } else { "off" }
        );
        let device =
            device::create_device(instance, pd, queue_family, &opts.extra_device_extensions)?;
        // SAFETY: queue 0 of `queue_family` was requested at device creation.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: `device` is live; `pool_info` outlives the call.
        let command_pool = match unsafe { device.create_command_pool(&pool_info, None) } {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: no child object of the device exists yet.
                unsafe { device.destroy_device(None) };
                return Err(Error::Vk {
                    call: "vkCreateCommandPool",
                    result: e,
                });
            }
        };
        let dir = opts.pipeline_cache_dir.as_deref();
        let parts = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: pd,
            debug_settings: Default::default(),
            buffer_device_address: true,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| Error::Alloc {
            name: "allocator".into(),
            source: e,
        })
        .and_then(|a| Ok((a, PipelineCache::open(&device, dir, (&info).into())?)));
        let (allocator, pipeline_cache) = match parts {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: only the command pool was created from the device (an allocator made
                // before the pipeline cache failed was dropped, holding no memory).
                unsafe {
                    device.destroy_command_pool(command_pool, None);
                    device.destroy_device(None);
                }
                return Err(e);
            }
        };
        let inst = guard.0.take().expect("guard holds the instance");
        let accel = ash::khr::acceleration_structure::Device::new(&inst.instance, &device);
        let push_descriptor = ash::khr::push_descriptor::Device::new(&inst.instance, &device);
        let debug_utils = inst
            .debug_utils
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&inst.instance, &device));
        let shared = DeviceShared {
            info,
            queue: Mutex::new(queue),
            command_pool: Mutex::new(command_pool),
            device,
            accel,
            push_descriptor,
            debug_utils,
            allocator: Mutex::new(Some(allocator)),
            tracking: Mutex::new(Tracking::default()),
            last_pass: Mutex::new(None),
            pipeline_cache,
            inst,
        };
        Ok(Context {
            shared: Arc::new(shared),
        })
    }

    /// Facts about the chosen device.
    pub fn info(&self) -> &DeviceInfo {
        &self.shared.info
    }

    /// Validation errors reported so far (0 when validation is off).
    pub fn validation_errors(&self) -> u32 {
        self.shared
            .inst
            .messenger_state
            .errors
            .load(Ordering::SeqCst)
    }

    /// The first validation error message, if any.
    pub fn first_validation_error(&self) -> Option<String> {
        lock(&self.shared.inst.messenger_state.first_error).clone()
    }

    /// Names of allocations currently alive.
    pub fn live_allocations(&self) -> Vec<String> {
        lock(&self.shared.tracking).live.values().cloned().collect()
    }

    /// Bytes of device memory allocated per category: the part of each allocation's name before
    /// its first `.` (`ic.records` → `ic`, `scene.vertices` → `scene`), from the allocator's
    /// report; unnamed allocations count as `other`.
    pub fn memory_by_category(&self) -> std::collections::BTreeMap<String, u64> {
        let mut out = std::collections::BTreeMap::new();
        if let Some(a) = self.shared.lock_allocator().as_ref() {
            for alloc in a.generate_report().allocations {
                let category = match alloc.name.split('.').next() {
                    Some(c) if !c.is_empty() => c.to_string(),
                    _ => "other".to_string(),
                };
                *out.entry(category).or_insert(0) += alloc.size;
            }
        }
        out
    }

    /// Waits for the GPU to finish all work and destroys retired objects.
    pub fn wait_idle(&self) -> Result<()> {
        self.shared.wait_idle()?;
        self.shared.collect();
        Ok(())
    }

    /// Waits for the GPU, destroys retired objects, and reports validation messages and the
    /// allocations still alive. Every GPU object should have been dropped before this.
    pub fn shutdown(self) -> ShutdownReport {
        if let Err(e) = self.shared.wait_idle() {
            log::error!("shutdown: {e}");
        }
        {
            let mut t = lock(&self.shared.tracking);
            t.outstanding.clear();
            t.submitted.clear();
        }
        self.shared.collect();
        self.shared.pipeline_cache.save(&self.shared.device);
        let state = &self.shared.inst.messenger_state;
        ShutdownReport {
            validation_errors: state.errors.load(Ordering::SeqCst),
            validation_warnings: state.warnings.load(Ordering::SeqCst),
            leaked: self.live_allocations(),
        }
    }
}
