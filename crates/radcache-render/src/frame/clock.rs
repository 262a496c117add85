//! A frame's timeline: GPU pass spans from the profiler's timestamps, placed on the host clock at
//! the time of their submission, and CPU spans (host phases), for `--profile` traces and the
//! per-pass tables.
//!
//! GPU timestamps count from the first timestamp of each submission; the submission's span is
//! placed at the host time just before `vkQueueSubmit` (the GPU cannot start earlier), so the
//! two tracks line up to within the submission latency. On lavapipe, compute work that follows
//! draws in one submission can run outside its timestamps (docs/design.md, "Profiling"); the host
//! phases are exact wall times.

use std::collections::BTreeMap;
use std::time::Instant;

use radcache_vk::{Context, PassTiming, Recorder};

use crate::error::Result;

/// The timeline a span belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Track {
    /// GPU passes (timestamps).
    Gpu,
    /// Host work (wall time).
    Cpu,
}

/// One timed piece of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Span {
    /// GPU or CPU.
    pub track: Track,
    /// Pass or phase name.
    pub name: String,
    /// Start, seconds after the frame's start.
    pub start_s: f64,
    /// Duration, seconds.
    pub duration_s: f64,
    /// Nesting depth of a GPU scope (0 for top-level passes and host phases).
    pub depth: u32,
}

/// Collects a frame's spans, GPU time per pass and wall time per phase.
#[derive(Debug)]
pub(crate) struct FrameClock {
    start: Instant,
    lap: Instant,
    pub spans: Vec<Span>,
    pub passes_ms: BTreeMap<String, f64>,
    pub phases_s: BTreeMap<String, f64>,
}

impl FrameClock {
    pub fn new() -> Self {
        let now = Instant::now();
        FrameClock {
            start: now,
            lap: now,
            spans: Vec::new(),
            passes_ms: BTreeMap::new(),
            phases_s: BTreeMap::new(),
        }
    }

    /// Seconds since the frame started.
    pub fn elapsed_s(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// Submits `rec`, waits for it, and records its passes.
    pub fn submit(&mut self, ctx: &Context, rec: Recorder) -> Result<()> {
        let at = Instant::now();
        let timings = ctx.submit(rec)?.wait()?;
        self.gpu(at, timings);
        Ok(())
    }

    /// Records the passes of a submission made at `submitted`.
    pub fn gpu(&mut self, submitted: Instant, timings: Vec<PassTiming>) {
        let base = submitted.duration_since(self.start).as_secs_f64();
        for t in timings {
            self.spans.push(Span {
                track: Track::Gpu,
                name: t.name.clone(),
                start_s: base + t.start_ms * 1e-3,
                duration_s: t.duration_ms * 1e-3,
                depth: t.depth,
            });
            *self.passes_ms.entry(t.name).or_default() += t.duration_ms;
        }
    }

    /// Ends the host phase `name` that began at the previous lap (or the frame's start).
    pub fn lap(&mut self, name: &str) {
        let now = Instant::now();
        let seconds = now.duration_since(self.lap).as_secs_f64();
        self.spans.push(Span {
            track: Track::Cpu,
            name: name.to_string(),
            start_s: self.lap.duration_since(self.start).as_secs_f64(),
            duration_s: seconds,
            depth: 0,
        });
        *self.phases_s.entry(name.to_string()).or_default() += seconds;
        self.lap = now;
    }
}
