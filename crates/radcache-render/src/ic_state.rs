//! The irradiance cache's GPU state: the record buffer, the request list and the counters with the
//! indirect arguments (`IcCounters`), plus the bookkeeping pass `shaders/passes/ic_counters.comp`
//! that keeps the counters consistent on the GPU, so the host never reads a count to size a
//! dispatch or a draw.

use bytemuck::{Pod, Zeroable};
use radcache_shared::gpu::{GpuRecord, IcCounters};
use radcache_vk::{
    vk, Access, BindingKind, BindingLayout, Buffer, BufferDesc, Context, MemoryLocation, Pipeline,
    Recorder, Resource, ShaderCompiler,
};

use crate::bindings::PASS_BASE;
use crate::error::Result;

/// The bookkeeping shader, relative to `shaders/`.
pub const SHADER: &str = "passes/ic_counters.comp";

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    mode: u32,
    record_capacity: u32,
    request_capacity: u32,
    pad: u32,
}

/// Levels of the neighbour grid (`LEVELS` in `shaders/passes/neighbours.comp`): cell sizes from
/// 2^level_max down to 2^(level_max − 11); smaller radii use the finest level.
pub const GRID_LEVELS: u32 = 12;
/// Grid entries per record: one in table A, one per level in table B.
pub const GRID_SLOTS: u32 = GRID_LEVELS + 1;

/// Buckets of the neighbour grid for `record_capacity` records: the power of two at or above
/// four per record (lists stay short), at least 1024.
pub fn grid_buckets(record_capacity: u32) -> u32 {
    record_capacity
        .saturating_mul(4)
        .checked_next_power_of_two()
        .unwrap_or(1 << 31)
        .max(1024)
}

/// Bookkeeping steps (see the shader).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Reset = 0,
    BeginLevel = 1,
    BeginBatch = 2,
    EndBatch = 3,
}

/// Records, requests and counters of one cache.
pub struct IcState {
    pipeline: Pipeline,
    /// `GpuRecord[record_capacity]`.
    pub records: Buffer,
    /// Pixel indices of requested records, `uint[request_capacity]`.
    pub requests: Buffer,
    /// One `IcCounters` (host-readable).
    pub counters: Buffer,
    /// Heads of the neighbour grid's bucket lists (`uint[GRID_BUCKETS]`, a power of two; see
    /// `shaders/passes/neighbours.comp`).
    pub grid_heads: Buffer,
    /// The neighbour grid's list links, `GRID_SLOTS` per record.
    pub grid_next: Buffer,
    record_capacity: u32,
    request_capacity: u32,
}

impl std::fmt::Debug for IcState {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IcState")
            .field("record_capacity", &self.record_capacity)
            .field("request_capacity", &self.request_capacity)
            .finish_non_exhaustive()
    }
}

impl IcState {
    /// Allocates room for `record_capacity` records and `request_capacity` requests per batch.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        record_capacity: u32,
        request_capacity: u32,
    ) -> Result<IcState> {
        let spirv = shaders.compile(SHADER, &[])?;
        let bindings = [BindingLayout::new(PASS_BASE, BindingKind::StorageBuffer)];
        let pipeline = Pipeline::compute(
            ctx,
            "ic_counters",
            &spirv,
            &bindings,
            std::mem::size_of::<Push>() as u32,
        )?;
        let buffer = |name, size: u64, usage, location| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size,
                    usage,
                    location,
                    alignment: 0,
                },
            )
        };
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        Ok(IcState {
            pipeline,
            records: buffer(
                "ic.records",
                u64::from(record_capacity) * std::mem::size_of::<GpuRecord>() as u64,
                storage,
                MemoryLocation::GpuOnly,
            )?,
            requests: buffer(
                "ic.requests",
                u64::from(request_capacity) * 4,
                storage,
                MemoryLocation::GpuOnly,
            )?,
            counters: buffer(
                "ic.counters",
                std::mem::size_of::<IcCounters>() as u64,
                storage | vk::BufferUsageFlags::INDIRECT_BUFFER,
                MemoryLocation::GpuToCpu,
            )?,
            grid_heads: buffer(
                "ic.grid.heads",
                u64::from(grid_buckets(record_capacity)) * 4,
                storage | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )?,
            grid_next: buffer(
                "ic.grid.next",
                u64::from(record_capacity.max(1)) * u64::from(GRID_SLOTS) * 4,
                storage,
                MemoryLocation::GpuOnly,
            )?,
            record_capacity,
            request_capacity,
        })
    }

    /// Largest number of records.
    pub fn record_capacity(&self) -> u32 {
        self.record_capacity
    }

    fn step(&self, rec: &mut Recorder, mode: Mode) -> Result<()> {
        let push = Push {
            mode: mode as u32,
            record_capacity: self.record_capacity,
            request_capacity: self.request_capacity,
            pad: 0,
        };
        rec.barrier(Access::ALL_WRITES, Access::COMPUTE_READ_WRITE);
        rec.bind_pipeline(&self.pipeline);
        rec.push_bindings(&[(PASS_BASE, Resource::Buffer(&self.counters))]);
        rec.push_constants(&push);
        rec.dispatch(1, 1, 1)?;
        rec.barrier(
            Access::COMPUTE_WRITE,
            Access::ALL.union(Access::INDIRECT).union(Access::HOST_READ),
        );
        Ok(())
    }

    /// Records forgetting every record (the start of a frame without reuse).
    pub fn record_reset(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, Mode::Reset)
    }

    /// Records the start of a creation level (no requests, hole count 0).
    pub fn record_begin_level(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, Mode::BeginLevel)
    }

    /// Records turning the requests into the record pass's indirect dispatch.
    pub fn record_begin_batch(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, Mode::BeginBatch)
    }

    /// Records adding the batch to the record count and the splat draw.
    pub fn record_end_batch(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, Mode::EndBatch)
    }

    /// The counters after the last submission's fence.
    pub fn read_counters(&self) -> Result<IcCounters> {
        Ok(self.counters.read::<IcCounters>(1)?[0])
    }
}
