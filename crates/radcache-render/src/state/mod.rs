//! The irradiance cache's GPU state: the record buffer, the request list, the neighbour grid, the
//! records' temporal state, their radiance blocks (where the scene has glossy lobes from the
//! cache) and the counters with the indirect arguments (`IcCounters`), which the
//! bookkeeping pass ([`ic_counters`], owned here with the buffer it keeps) keeps consistent on
//! the GPU, so the host never reads a count to size a dispatch or a draw. The passes below the
//! frame take this state; the state takes no pass.

use bytemuck::Zeroable;
use radcache_shared::gpu::{DispatchArgs, DrawArgs, GpuRecord, GpuRecordTemporal, IcCounters};
use radcache_vk::{vk, Buffer, BufferDesc, Context, MemoryLocation, Recorder, ShaderCompiler};

use crate::error::{Error, Result};
use ic_counters::{CounterStep, IcCountersPass};

pub mod ic_counters;

pub use radcache_cache::cache_file::{RadianceBlock, RADIANCE_BYTES_PER_RECORD};
pub use radcache_shared::consts::{GRID_LEVELS, GRID_SLOTS};

/// Buckets of the neighbour grid for `record_capacity` records: the power of two at or above
/// four per record (lists stay short), at least 1024.
pub fn grid_buckets(record_capacity: u32) -> u32 {
    record_capacity
        .saturating_mul(4)
        .checked_next_power_of_two()
        .unwrap_or(1 << 31)
        .max(1024)
}

/// Records, requests and counters of one cache.
pub struct IcState {
    bookkeeping: IcCountersPass,
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
    /// Per record, the last frame (the renderer's count, from 1) whose final splat it weighed
    /// in; 0 = never.
    pub last_used: Buffer,
    /// `GpuRecordTemporal[record_capacity]`: each record's temporal state (temporal caching,
    /// `crate::passes::temporal`).
    pub temporal: Buffer,
    /// `RadianceBlock[record_capacity]`: each record's radiance coefficients and their
    /// gradients (docs/radiance-caching.md §7.2; the record pass writes them, the glossy splat
    /// reads them), in scenes with glossy lobes from the cache ([`IcStateDesc::radiance`]).
    pub radiance: Option<Buffer>,
    record_capacity: u32,
    request_capacity: u32,
}

/// What [`IcState::new`] allocates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IcStateDesc {
    /// Room for this many records.
    pub record_capacity: u32,
    /// Room for this many pixel requests per batch.
    pub request_capacity: u32,
    /// Also a radiance block per record ([`IcState::radiance`]).
    pub radiance: bool,
}

impl IcStateDesc {
    /// Room for `record_capacity` records and `request_capacity` requests per batch, without
    /// radiance blocks.
    pub fn new(record_capacity: u32, request_capacity: u32) -> IcStateDesc {
        IcStateDesc {
            record_capacity,
            request_capacity,
            radiance: false,
        }
    }
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
    /// Allocates the state `desc` describes.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler, desc: &IcStateDesc) -> Result<IcState> {
        let IcStateDesc {
            record_capacity,
            request_capacity,
            radiance,
        } = *desc;
        let bookkeeping = IcCountersPass::new(ctx, shaders)?;
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
            bookkeeping,
            records: buffer(
                "ic.records",
                u64::from(record_capacity) * std::mem::size_of::<GpuRecord>() as u64,
                storage | vk::BufferUsageFlags::TRANSFER_SRC,
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
            last_used: buffer(
                "ic.last_used",
                u64::from(record_capacity.max(1)) * 4,
                storage | vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::GpuOnly,
            )?,
            temporal: buffer(
                "ic.temporal",
                u64::from(record_capacity.max(1)) * std::mem::size_of::<GpuRecordTemporal>() as u64,
                storage | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )?,
            radiance: if radiance {
                Some(buffer(
                    "ic.radiance",
                    u64::from(record_capacity.max(1)) * RADIANCE_BYTES_PER_RECORD,
                    storage
                        | vk::BufferUsageFlags::TRANSFER_SRC
                        | vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuOnly,
                )?)
            } else {
                None
            },
            record_capacity,
            request_capacity,
        })
    }

    /// Largest number of records.
    pub fn record_capacity(&self) -> u32 {
        self.record_capacity
    }

    fn step(&self, rec: &mut Recorder, step: CounterStep) -> Result<()> {
        let capacities = (self.record_capacity, self.request_capacity);
        self.bookkeeping
            .record(rec, &self.counters, step, capacities)
    }

    /// Records forgetting every record (the start of a frame without reuse).
    pub fn record_reset(&self, rec: &mut Recorder) -> Result<()> {
        rec.fill_buffer(&self.last_used, 0, vk::WHOLE_SIZE, 0);
        self.step(rec, CounterStep::Reset)
    }

    /// Records the start of a creation level (no requests, hole count 0).
    pub fn record_begin_level(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, CounterStep::BeginLevel)
    }

    /// Records turning the requests into the record pass's indirect dispatch.
    pub fn record_begin_batch(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, CounterStep::BeginBatch)
    }

    /// Records adding the batch to the record count and the splat draw.
    pub fn record_end_batch(&self, rec: &mut Recorder) -> Result<()> {
        self.step(rec, CounterStep::EndBatch)
    }

    /// Keeps the records `keep` selects (by index and last use) and drops the others, moving the
    /// kept ones (with their temporal state and radiance blocks) to the front in their order;
    /// returns how many were dropped. The caller must rebuild the neighbour grid afterwards. It
    /// goes through the host: the marks are read back, and the records only when some go.
    pub fn compact(&self, ctx: &Context, keep: impl Fn(usize, u32) -> bool) -> Result<u32> {
        self.compact_where(ctx, false, |i, used, _| keep(i, used))
    }

    /// As [`Self::compact`], with each record's temporal state read back too for `keep`.
    pub fn compact_temporal(
        &self,
        ctx: &Context,
        keep: impl Fn(usize, u32, &GpuRecordTemporal) -> bool,
    ) -> Result<u32> {
        self.compact_where(ctx, true, keep)
    }

    /// [`Self::compact`]; `keep` sees the temporal states where `read_temporal` (zeroed ones
    /// otherwise).
    fn compact_where(
        &self,
        ctx: &Context,
        read_temporal: bool,
        keep: impl Fn(usize, u32, &GpuRecordTemporal) -> bool,
    ) -> Result<u32> {
        let counters = self.read_counters()?;
        let count = counters.record_count.min(self.record_capacity) as usize;
        if count == 0 {
            return Ok(0);
        }
        let used: Vec<u32> = ctx.read_buffer(&self.last_used, count)?;
        let mut temporal: Vec<GpuRecordTemporal> = if read_temporal {
            ctx.read_buffer(&self.temporal, count)?
        } else {
            Vec::new()
        };
        let none = GpuRecordTemporal::zeroed();
        let kept: Vec<usize> = (0..count)
            .filter(|&i| keep(i, used[i], temporal.get(i).unwrap_or(&none)))
            .collect();
        let dropped = (count - kept.len()) as u32;
        if dropped == 0 {
            return Ok(0);
        }
        if !read_temporal {
            temporal = ctx.read_buffer(&self.temporal, count)?;
        }
        let records: Vec<GpuRecord> = ctx.read_buffer(&self.records, count)?;
        let blocks: Vec<RadianceBlock> = match &self.radiance {
            Some(b) => ctx.read_buffer(b, count)?,
            None => Vec::new(),
        };
        let mut rec = ctx.begin("ic.compact")?;
        let n = kept.len() as u32;
        let mut staging = Vec::new();
        if n > 0 {
            let new_records: Vec<GpuRecord> = kept.iter().map(|&i| records[i]).collect();
            let new_used: Vec<u32> = kept.iter().map(|&i| used[i]).collect();
            let src = vk::BufferUsageFlags::TRANSFER_SRC;
            let r = ctx.create_buffer_init("ic.compact.records", src, &new_records)?;
            let u = ctx.create_buffer_init("ic.compact.last_used", src, &new_used)?;
            let new_temporal: Vec<GpuRecordTemporal> = kept.iter().map(|&i| temporal[i]).collect();
            let t = ctx.create_buffer_init("ic.compact.temporal", src, &new_temporal)?;
            let bytes = std::mem::size_of_val(&new_records[..]) as u64;
            rec.copy_buffer(&r, 0, &self.records, 0, bytes);
            rec.copy_buffer(&u, 0, &self.last_used, 0, u64::from(n) * 4);
            let bytes = std::mem::size_of_val(&new_temporal[..]) as u64;
            rec.copy_buffer(&t, 0, &self.temporal, 0, bytes);
            staging.extend([r, u, t]);
            if let Some(radiance) = &self.radiance {
                let new_blocks: Vec<RadianceBlock> = kept.iter().map(|&i| blocks[i]).collect();
                let b = ctx.create_buffer_init("ic.compact.radiance", src, &new_blocks)?;
                let bytes = std::mem::size_of_val(&new_blocks[..]) as u64;
                rec.copy_buffer(&b, 0, radiance, 0, bytes);
                staging.push(b);
            }
        }
        // Slots past the kept records start again as never used.
        rec.fill_buffer(
            &self.last_used,
            u64::from(n) * 4,
            (count as u64 - u64::from(n)) * 4,
            0,
        );
        let mut c = counters;
        c.record_count = n;
        c.batch_first = n;
        c.dispatch.x = 0;
        c.draw = DrawArgs::quads(n, 0);
        c.batch_draw = DrawArgs::quads(0, 0);
        rec.update_buffer(&self.counters, 0, std::slice::from_ref(&c));
        ctx.submit(rec)?.wait()?;
        drop(staging);
        Ok(dropped)
    }

    /// The first `count` records with their temporal states and last-use marks (after the last
    /// submission's fence).
    pub fn download(
        &self,
        ctx: &Context,
    ) -> Result<(Vec<GpuRecord>, Vec<GpuRecordTemporal>, Vec<u32>)> {
        let count = self.read_counters()?.record_count.min(self.record_capacity) as usize;
        if count == 0 {
            return Ok(Default::default());
        }
        Ok((
            ctx.read_buffer(&self.records, count)?,
            ctx.read_buffer(&self.temporal, count)?,
            ctx.read_buffer(&self.last_used, count)?,
        ))
    }

    /// Replaces every record by `records` with their temporal states and last-use marks (equal
    /// lengths, at most the capacity); the slots after them start as never used, the counters
    /// say `records.len()` records and no batch. The caller must rebuild the neighbour grid
    /// before the records are looked up.
    pub fn upload(
        &self,
        ctx: &Context,
        records: &[GpuRecord],
        temporal: &[GpuRecordTemporal],
        last_used: &[u32],
    ) -> Result<()> {
        let n = records.len();
        if temporal.len() != n || last_used.len() != n {
            return Err(Error::Invalid(format!(
                "{n} records with {} temporal states and {} marks",
                temporal.len(),
                last_used.len()
            )));
        }
        if n > self.record_capacity as usize {
            return Err(Error::Invalid(format!(
                "{n} records do not fit in the cache's capacity of {}",
                self.record_capacity
            )));
        }
        let n = n as u32;
        let mut rec = ctx.begin("ic.upload")?;
        rec.fill_buffer(&self.last_used, 0, vk::WHOLE_SIZE, 0);
        let mut staging = Vec::new();
        if n > 0 {
            let src = vk::BufferUsageFlags::TRANSFER_SRC;
            let r = ctx.create_buffer_init("ic.upload.records", src, records)?;
            let t = ctx.create_buffer_init("ic.upload.temporal", src, temporal)?;
            let u = ctx.create_buffer_init("ic.upload.last_used", src, last_used)?;
            rec.copy_buffer(
                &r,
                0,
                &self.records,
                0,
                std::mem::size_of_val(records) as u64,
            );
            rec.copy_buffer(
                &t,
                0,
                &self.temporal,
                0,
                std::mem::size_of_val(temporal) as u64,
            );
            rec.copy_buffer(&u, 0, &self.last_used, 0, u64::from(n) * 4);
            staging.extend([r, t, u]);
        }
        let counters = IcCounters {
            record_count: n,
            requested: 0,
            batch_first: n,
            holes: 0,
            dispatch: DispatchArgs {
                x: 0,
                y: 1,
                z: 1,
                pad: 0,
            },
            draw: DrawArgs::quads(n, 0),
            record_capacity: self.record_capacity,
            request_capacity: self.request_capacity,
            dropped_requests: 0,
            rejected_records: 0,
            batch_draw: DrawArgs::quads(0, 0),
            radii_shrunk: 0,
        };
        rec.update_buffer(&self.counters, 0, std::slice::from_ref(&counters));
        ctx.submit(rec)?.wait()?;
        drop(staging);
        Ok(())
    }

    /// The radiance blocks of the first `count` records (after the last submission's fence);
    /// none without radiance blocks.
    pub fn download_radiance(&self, ctx: &Context) -> Result<Vec<RadianceBlock>> {
        let Some(radiance) = &self.radiance else {
            return Ok(Vec::new());
        };
        let count = self.read_counters()?.record_count.min(self.record_capacity) as usize;
        if count == 0 {
            return Ok(Vec::new());
        }
        Ok(ctx.read_buffer(radiance, count)?)
    }

    /// Writes `blocks` as the radiance blocks of the first `blocks.len()` records (after
    /// [`IcState::upload`] of as many records). An error without radiance blocks or with more
    /// blocks than the capacity.
    pub fn upload_radiance(&self, ctx: &Context, blocks: &[RadianceBlock]) -> Result<()> {
        let Some(radiance) = &self.radiance else {
            return Err(Error::Invalid(
                "radiance blocks for a cache made without radiance records".into(),
            ));
        };
        if blocks.len() > self.record_capacity as usize {
            return Err(Error::Invalid(format!(
                "{} radiance blocks do not fit in the cache's capacity of {}",
                blocks.len(),
                self.record_capacity
            )));
        }
        if blocks.is_empty() {
            return Ok(());
        }
        let src = vk::BufferUsageFlags::TRANSFER_SRC;
        let b = ctx.create_buffer_init("ic.upload.radiance", src, blocks)?;
        let mut rec = ctx.begin("ic.upload.radiance")?;
        rec.copy_buffer(&b, 0, radiance, 0, std::mem::size_of_val(blocks) as u64);
        ctx.submit(rec)?.wait()?;
        drop(b);
        Ok(())
    }

    /// The counters after the last submission's fence.
    pub fn read_counters(&self) -> Result<IcCounters> {
        Ok(self.counters.read::<IcCounters>(1)?[0])
    }
}
