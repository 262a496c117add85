//! The record pass's push constants and seeds (`shaders/passes/record.comp`; the fields in the
//! order of the module doc of `passes/record.rs`).

use radcache_cache::sampling::ircache_hash;
use radcache_shared::consts::SEED_SUB_FRAME_MUL;

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`RecordPush` in GLSL).
    pub struct RecordPush {
        /// M.
        pub m: u32 => "uint",
        /// N.
        pub n: u32 => "uint",
        /// Seed.
        pub seed: u32 => "uint",
        /// Level in the low 16 bits, sub-frame in the high 16 bits.
        pub level_subframe: u32 => "uint",
        /// Min px.
        pub min_px: f32 => "float",
        /// Max px.
        pub max_px: f32 => "float",
        /// V scale.
        pub v_scale: f32 => "float",
        /// R eps rel.
        pub r_eps_rel: f32 => "float",
        /// 0: requests are pixels (new records); 1: requests are record indices (refresh in place).
        pub source: u32 => "uint",
        /// The first creation level whose records take the fine strata (but those made for
        /// glossy lobes; `IcParams::fine_level`; docs/irradiance-cache.md §2.8).
        pub fine_level: u32 => "uint",
        /// Fine M.
        pub fine_m: u32 => "uint",
        /// Fine N.
        pub fine_n: u32 => "uint",
        /// 1: the fine strata fall off below `fine_level` (`IcParams::strata_falloff`,
        /// `falloff_strata`; docs/irradiance-cache.md §2.8).
        pub strata_falloff: u32 => "uint",
        /// The dispatch's epoch in the frame's radiance grid (`PATH_GRID`; 0: the grid is
        /// neither read nor written; docs/cache-frame.md §4.1).
        pub grid_epoch: u32 => "uint",
    }
}

/// The pass seed of the records created for sub-frame `sub_frame` of a frame rendered with
/// `seed` (`IcRenderer`); `record.comp` recomputes it from a record's stored sub-frame when it
/// refreshes the record, so a refresh draws the record's own directions and paths again.
pub fn creation_seed(seed: u32, sub_frame: u32) -> u32 {
    seed.wrapping_mul(SEED_SUB_FRAME_MUL) ^ sub_frame
}

/// Seed of the jitter of the record created at `pixel_index` with the pass seed `seed`: stratum
/// `i` of that record is jittered by `radcache_cache::sampling::stratum_jitter(record_seed, i)`,
/// so the same pixel and seed always reproduce the same gather directions
/// (docs/irradiance-cache.md §2.3).
pub fn record_seed(pixel_index: u32, seed: u32) -> u32 {
    ircache_hash(pixel_index ^ ircache_hash(seed))
}
