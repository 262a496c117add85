//! Frames: the irradiance cache's ([`ic::IcRenderer`]) and the path tracer's
//! ([`path::render_path`]). This is the one description of a frame's flow; the algorithm behind
//! each step is in `docs/cache-frame.md` and `docs/irradiance-cache.md`.
//!
//! # The cache's frame
//!
//! [`ic::IcRenderer::render`] is a list of phases over the frame's `sub_frames` jittered
//! sub-frames (default 8; the centre, then the R2 sequence in antithetic pairs,
//! [`settings::sub_frame_jitter`]), each phase a function of its own (`ic/phases.rs`,
//! `ic/temporal.rs`):
//!
//! 1. **Setup**: the scene at the frame's time (TLAS refit) and view; records unused for
//!    `evict_after_frames` are evicted; kept records are moved with their instances and the
//!    expired ones listed (temporal caching), or re-clamped to [R⁻, R⁺] of the new view when
//!    only the camera moved; the neighbour grid is rebuilt; the accumulators are cleared.
//! 2. **Cache phase**: for each sub-frame's jitter, the **G-buffer** is rasterized
//!    (`passes/gbuffer.rs`), then holes are filled coarse to fine, level by level: the records
//!    are **splatted** with the stricter creation weights (`passes/splat.rs`), **holes** picks
//!    one hole per S×S block (`passes/holes.rs`, GPU atomics), the **record** pass computes
//!    those records (`passes/record.rs`, one workgroup each, dispatched indirectly from the
//!    counters that **ic_counters** keeps, `state/ic_counters.rs`), and **neighbours** clamps
//!    their radii against the records nearby (`passes/neighbours.rs`, a hash grid). The host
//!    only loops over levels and reads the counters for the figures; a level that finds no hole
//!    ends the sub-frame. With `settle_records` the phase repeats until a pass creates nothing.
//!    Splatting once per frame ([`settings::SplatMode::Once`], the default) the phase covers
//!    sub-frame 0 (the pixel centres) alone, and always repeats until a pass creates nothing.
//! 3. **Look-ahead** (temporal caching, only with a time step): the frame's new records and the
//!    expired ones are evaluated again, at their own points, in the scene of the next frame
//!    (`passes/temporal.rs`, the record pass's refresh), which gives their rates and lifespans.
//! 4. **Shade** each sub-frame: the G-buffer again, **direct** light (`passes/direct.rs`,
//!    one-sample MIS), the splat of every record with the final weights (marking the records
//!    used), the count of the holes left, and the **composite**
//!    `L = direct + albedo/π · Σw·Ẽ / Σw` into the frame accumulator (`passes/composite.rs`).
//!    Splatting once per frame only sub-frame 0 splats and counts holes; its composite stores
//!    the centres' points, and every later sub-frame's composite interpolates the centres' splat
//!    at its samples (docs/cache-frame.md §6.5).
//!    Every sub-frame is shaded with the same, final set of records, so a frame whose holes are
//!    all covered by kept records creates none and shades exactly as the frame before it.
//! 5. **Finish**: the **emission** pass adds the box-filtered emission (`passes/emission.rs`),
//!    the instances are kept for the next frame's motion, and the mean over the sub-frames is
//!    read back with the figures ([`settings::IcStats`]) and the clocks ([`clock`]).
//!
//! # The path tracer's frame
//!
//! [`path::render_path`]: setup (the scene at the frame's time and view, the accumulators
//! cleared), then samples in submissions sized to take about `chunk_target_ms` each until the
//! budget (samples or seconds) is spent, then the read-back of the mean (and the AOVs).

pub mod aa;
pub mod clock;
pub mod ic;
pub mod path;
pub mod settings;
