//! The gather paths' radiance grid (`shaders/common/path_grid.glsl`, docs/cache-frame.md §4.1):
//! `PATH_GRID_CELLS` cells of a key, a ready epoch and a count (`uvec4`) and three 64-bit
//! fixed-point sums (`int64_t[4]`). A frame whose records are not kept over time clears it at its
//! start; a renderer that keeps records with lifespans (temporal caching) keeps it over frames
//! and clears a slice of it per frame instead ([`GridJob::Age`], docs/temporal.md §3.8).
//! Each dispatch that uses it takes the next epoch; epochs keep counting across frames until a
//! whole reset.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use radcache_shared::consts::PATH_GRID_CELLS;
use radcache_vk::{vk, Buffer, BufferDesc, Context, MemoryLocation, Recorder};

use crate::error::Result;

/// Bytes per cell of the key buffer (`uvec4`) and of the sums (`int64_t[4]`).
const KEY_BYTES: u64 = 16;
const SUM_BYTES: u64 = 32;

/// What a frame does to the grid at its start ([`PathGrid::record`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridJob {
    /// Clear every cell (a frame whose records are not kept with lifespans).
    Reset,
    /// Clear the slice frame `frame` ages out, so that no cell is older than `life` frames (a
    /// renderer that keeps records with lifespans, docs/temporal.md §3.8); the other cells, ready
    /// ones included, serve this frame's gathers and refreshes.
    Age {
        /// The frame number.
        frame: u32,
        /// The longest life of a cell, in frames.
        life: u32,
    },
}

/// The grid's buffers, the epoch of the next dispatch, and whether a whole clear has been
/// recorded since they were allocated (their memory is undefined until then). The record pass
/// owns it ([`crate::passes::record::RecordPass::grid`]) and binds it to its gathers.
#[derive(Debug)]
pub struct PathGrid {
    pub(super) keys: Buffer,
    pub(super) sums: Buffer,
    epoch: AtomicU32,
    cleared: AtomicBool,
}

impl PathGrid {
    /// The grid's buffers (GPU-only, cleared by [`GridJob::Reset`] before use).
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
            keys: buffer("records.path_grid", cells * KEY_BYTES)?,
            sums: buffer("records.path_grid_sums", cells * SUM_BYTES)?,
            epoch: AtomicU32::new(0),
            cleared: AtomicBool::new(false),
        })
    }

    /// Records `job`, the grid's step at the start of a frame.
    pub fn record(&self, rec: &mut Recorder, job: GridJob) {
        match job {
            GridJob::Reset => self.record_reset(rec),
            GridJob::Age { frame, life } => self.record_age(rec, frame, life),
        }
    }

    /// Clears every cell; the dispatches after it count their epochs from 1 again.
    fn record_reset(&self, rec: &mut Recorder) {
        rec.fill_buffer(&self.keys, 0, vk::WHOLE_SIZE, 0);
        rec.fill_buffer(&self.sums, 0, vk::WHOLE_SIZE, 0);
        self.epoch.store(0, Ordering::Relaxed);
        self.cleared.store(true, Ordering::Relaxed);
    }

    /// Clears the slice of the grid that frame `frame` ages out ([`aged_slots`]): with the grid
    /// kept over frames, no cell is older than `life` frames. Epochs go on counting, so a cell
    /// that became ready in an earlier frame is read by every dispatch of this one. A grid never
    /// cleared yet (a renderer whose first frame starts from records imported from a cache file)
    /// is cleared whole.
    fn record_age(&self, rec: &mut Recorder, frame: u32, life: u32) {
        if !self.cleared.load(Ordering::Relaxed) {
            self.record_reset(rec);
            return;
        }
        let slots = aged_slots(frame, life);
        let (first, count) = (u64::from(slots.start), u64::from(slots.len() as u32));
        rec.fill_buffer(&self.keys, first * KEY_BYTES, count * KEY_BYTES, 0);
        rec.fill_buffer(&self.sums, first * SUM_BYTES, count * SUM_BYTES, 0);
    }

    /// The epoch of the next dispatch (from 1; 0 tells the shader the grid is off).
    pub(super) fn next_epoch(&self) -> u32 {
        self.epoch.fetch_add(1, Ordering::Relaxed) + 1
    }
}

/// The slots frame `frame` clears when the grid lives over frames: slice `frame mod life` of
/// `life` equal slices of the table. Every slot is cleared once in any `life` consecutive
/// frames, so a cell holds no continuation older than that. A cleared slot is free for any key;
/// a key inserted past it earlier is still found, since a lookup looks through all its probes
/// before it inserts (`path_grid_slot`).
pub(super) fn aged_slots(frame: u32, life: u32) -> Range<u32> {
    let (n, life) = (
        u64::from(PATH_GRID_CELLS),
        u64::from(life.clamp(1, PATH_GRID_CELLS)),
    );
    let part = u64::from(frame) % life;
    (part * n / life) as u32..((part + 1) * n / life) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_slot_is_cleared_once_within_its_life() {
        for life in [1, 2, 5, 7, 30] {
            let mut cleared = vec![0u32; PATH_GRID_CELLS as usize];
            // One life of frames, from an arbitrary frame number.
            for frame in 1000..1000 + life {
                for s in aged_slots(frame, life) {
                    cleared[s as usize] += 1;
                }
            }
            assert!(cleared.iter().all(|&c| c == 1), "life {life}");
        }
        assert_eq!(aged_slots(3, 1), 0..PATH_GRID_CELLS);
    }
}
