//! The gather paths' radiance grid of a frame (`shaders/common/path_grid.glsl`,
//! docs/cache-frame.md §4.1): `PATH_GRID_CELLS` cells of a key, a ready epoch and a count
//! (`uvec4`) and three 64-bit fixed-point sums (`int64_t[4]`), cleared at the start of each
//! frame; each dispatch of new records takes the next epoch.

use std::sync::atomic::{AtomicU32, Ordering};

use radcache_shared::consts::PATH_GRID_CELLS;
use radcache_vk::{vk, Access, Buffer, BufferDesc, Context, MemoryLocation, Recorder};

use crate::error::Result;

/// The grid's buffers and the epoch of the next dispatch.
pub(super) struct PathGrid {
    pub(super) keys: Buffer,
    pub(super) sums: Buffer,
    epoch: AtomicU32,
}

impl PathGrid {
    /// The grid's buffers (GPU-only, cleared by [`PathGrid::record_reset`] before use).
    pub(super) fn new(ctx: &Context) -> Result<PathGrid> {
        let cells = u64::from(PATH_GRID_CELLS);
        let buffer = |name, size| {
            let desc = BufferDesc {
                name,
                size,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
                alignment: 0,
            };
            Buffer::new(ctx, &desc)
        };
        Ok(PathGrid {
            keys: buffer("records.path_grid", cells * 16)?,
            sums: buffer("records.path_grid_sums", cells * 32)?,
            epoch: AtomicU32::new(0),
        })
    }

    /// Clears every cell; the dispatches after it count their epochs from 1 again.
    pub(super) fn record_reset(&self, rec: &mut Recorder) {
        rec.fill_buffer(&self.keys, 0, vk::WHOLE_SIZE, 0);
        rec.fill_buffer(&self.sums, 0, vk::WHOLE_SIZE, 0);
        rec.barrier(Access::TRANSFER_WRITE, Access::COMPUTE_READ_WRITE);
        self.epoch.store(0, Ordering::Relaxed);
    }

    /// The epoch of the next dispatch of new records (from 1; 0 tells the shader the grid is
    /// off).
    pub(super) fn next_epoch(&self) -> u32 {
        self.epoch.fetch_add(1, Ordering::Relaxed) + 1
    }
}
