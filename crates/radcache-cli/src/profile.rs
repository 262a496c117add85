//! `radcache render --profile trace.json`: the run's timeline in the Chrome trace event format
//! (loadable in Perfetto and chrome://tracing) — one track for GPU passes, one for host work —
//! and, at the end of a run, a table per GPU pass: count, total, mean, min, max, share of the
//! frames' wall time, and rays and rays/s for the ray-query passes.
//!
//! GPU spans come from the profiler's timestamps, placed at the host time of their submission
//! (`radcache_render::Span`); every event carries its frame number.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use radcache_render::{FrameOutput, Track};
use serde_json::{json, Value};

const PID: u32 = 1;
const GPU_TID: u32 = 1;
const CPU_TID: u32 = 2;

/// Figures of one pass name over the run.
#[derive(Debug, Default, Clone)]
struct PassFigures {
    count: u64,
    total_ms: f64,
    min_ms: f64,
    max_ms: f64,
    rays: u64,
}

/// The run's timeline and per-pass figures.
#[derive(Debug)]
pub struct Profile {
    epoch: Instant,
    events: Vec<Value>,
    passes: BTreeMap<String, PassFigures>,
    frames_s: f64,
}

impl Profile {
    /// A profile whose time 0 is now.
    pub fn new() -> Self {
        Profile {
            epoch: Instant::now(),
            events: Vec::new(),
            passes: BTreeMap::new(),
            frames_s: 0.0,
        }
    }

    fn us(&self, t: Instant) -> f64 {
        t.saturating_duration_since(self.epoch).as_secs_f64() * 1e6
    }

    fn event(&mut self, tid: u32, name: &str, ts_us: f64, dur_us: f64, frame: Option<u32>) {
        let mut e = json!({
            "name": name,
            "cat": if tid == GPU_TID { "gpu" } else { "cpu" },
            "ph": "X",
            "ts": ts_us,
            "dur": dur_us.max(0.0),
            "pid": PID,
            "tid": tid,
        });
        if let Some(f) = frame {
            e["args"] = json!({ "frame": f });
        }
        self.events.push(e);
    }

    /// Host work from `start` to `end` (scene load, upload, write, ...).
    pub fn cpu(&mut self, name: &str, start: Instant, end: Instant, frame: Option<u32>) {
        let (ts, end) = (self.us(start), self.us(end));
        self.event(CPU_TID, name, ts, end - ts, frame);
    }

    /// A frame that started at `started`: its GPU passes and host phases, and the pass figures
    /// (top-level passes only, so nested scopes are not counted twice).
    pub fn frame(&mut self, number: u32, started: Instant, out: &FrameOutput) {
        let base = self.us(started);
        self.event(
            CPU_TID,
            &format!("frame {number}"),
            base,
            out.time_s * 1e6,
            Some(number),
        );
        self.frames_s += out.time_s;
        for span in &out.spans {
            let tid = match span.track {
                Track::Gpu => GPU_TID,
                Track::Cpu => CPU_TID,
            };
            let ts = base + span.start_s * 1e6;
            self.event(tid, &span.name, ts, span.duration_s * 1e6, Some(number));
            if span.track == Track::Gpu && span.depth == 0 {
                let ms = span.duration_s * 1e3;
                let p = self.passes.entry(span.name.clone()).or_default();
                if p.count == 0 || ms < p.min_ms {
                    p.min_ms = ms;
                }
                p.max_ms = p.max_ms.max(ms);
                p.count += 1;
                p.total_ms += ms;
            }
        }
        for (pass, rays) in &out.rays {
            self.passes.entry(pass.clone()).or_default().rays += rays;
        }
    }

    /// Writes the Chrome trace to `path` (atomically).
    pub fn write(&self, path: &Path) -> Result<()> {
        let name = |tid: u32, label: &str| {
            json!({"name": "thread_name", "ph": "M", "pid": PID, "tid": tid,
                   "args": {"name": label}})
        };
        let mut events = vec![
            json!({"name": "process_name", "ph": "M", "pid": PID, "args": {"name": "radcache"}}),
            name(GPU_TID, "GPU passes"),
            name(CPU_TID, "CPU"),
        ];
        events.extend(self.events.iter().cloned());
        let value = json!({ "traceEvents": events, "displayTimeUnit": "ms" });
        crate::output::write_text(path, &serde_json::to_string(&value)?, "profile")
    }

    /// The per-pass table (GPU time; rays/s over the pass's own GPU time).
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<18} {:>6} {:>10} {:>9} {:>9} {:>9} {:>7} {:>11} {:>9}\n",
            "pass", "count", "total ms", "mean ms", "min ms", "max ms", "share", "rays", "Mrays/s"
        );
        let frames_ms = (self.frames_s * 1e3).max(1e-9);
        for (name, p) in self.passes.iter().filter(|(_, p)| p.count > 0) {
            let rate = if p.rays > 0 && p.total_ms > 0.0 {
                format!("{:.2}", p.rays as f64 / (p.total_ms * 1e-3) / 1e6)
            } else {
                "-".into()
            };
            s += &format!(
                "{name:<18} {:>6} {:>10.2} {:>9.3} {:>9.3} {:>9.3} {:>6.1}% {:>11} {rate:>9}\n",
                p.count,
                p.total_ms,
                p.total_ms / p.count as f64,
                p.min_ms,
                p.max_ms,
                100.0 * p.total_ms / frames_ms,
                p.rays,
            );
        }
        s += "(GPU timestamps; a driver may run compute work that follows draws in one submission \
              outside them, as lavapipe does: the stats' phases_wall_s are host wall times)\n";
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radcache_render::Span;

    fn output(spans: Vec<Span>) -> FrameOutput {
        FrameOutput {
            width: 1,
            height: 1,
            pixels: vec![[0.0; 3]],
            spp: 1,
            time_s: 0.01,
            rays: BTreeMap::from([("trace".to_string(), 2000u64)]),
            passes_ms: BTreeMap::new(),
            spans,
            nonfinite_pixels: 0,
            aovs: None,
        }
    }

    fn span(track: Track, name: &str, start_s: f64, duration_s: f64, depth: u32) -> Span {
        Span {
            track,
            name: name.into(),
            start_s,
            duration_s,
            depth,
        }
    }

    #[test]
    fn passes_are_aggregated_over_frames_and_placed_on_their_tracks() {
        let mut p = Profile::new();
        let t0 = p.epoch;
        let f = output(vec![
            span(Track::Gpu, "trace", 0.001, 0.002, 0),
            span(Track::Gpu, "trace.inner", 0.001, 0.001, 1),
            span(Track::Cpu, "setup", 0.0, 0.001, 0),
        ]);
        p.frame(1, t0, &f);
        let g = output(vec![span(Track::Gpu, "trace", 0.0, 0.004, 0)]);
        p.frame(2, t0 + std::time::Duration::from_millis(10), &g);
        let trace = &p.passes["trace"];
        assert_eq!(trace.count, 2);
        assert!((trace.total_ms - 6.0).abs() < 1e-9);
        assert!((trace.min_ms - 2.0).abs() < 1e-9 && (trace.max_ms - 4.0).abs() < 1e-9);
        assert_eq!(trace.rays, 4000);
        // Nested scopes appear in the trace but not in the table.
        assert!(!p.passes.contains_key("trace.inner"));
        let gpu: Vec<&Value> = p.events.iter().filter(|e| e["tid"] == GPU_TID).collect();
        assert_eq!(gpu.len(), 3);
        // Frame 2's pass starts 10 ms after frame 1's start.
        let ts: Vec<f64> = gpu.iter().map(|e| e["ts"].as_f64().unwrap()).collect();
        assert!(
            (ts[2] - 10_000.0).abs() < 1.0 && (ts[0] - 1_000.0).abs() < 1.0,
            "{ts:?}"
        );
        assert_eq!(gpu[2]["args"]["frame"], 2);
        let table = p.table();
        // 4000 rays over 6 ms of GPU time: 0.67 Mrays/s; 6 ms of 20 ms of frames: 30 %.
        assert!(table.contains("0.67") && table.contains("30.0%"), "{table}");
    }
}
