//! `radcache render --profile trace.json`: the run's timeline in the Chrome trace event format
//! (loadable in Perfetto and chrome://tracing) — one track for GPU passes, one for host work —
//! and, at the end of a run, a table per GPU pass: count, GPU time (total, mean, min, max, share
//! of the frames' wall time), the wall time of the host phases that submitted it, rays and rays/s.
//!
//! GPU spans come from the profiler's timestamps, placed at the host time of their submission
//! (`radcache_render::Span`); every event carries its frame number.
//!
//! **Which figures are printed.** A driver may run work outside the timestamps around it
//! (lavapipe runs compute work that follows draws in one submission outside them, so a first run
//! printed `direct … 70158.80 Mrays/s`). Each submission is made and waited for inside one host
//! phase (`Track::Cpu` span, an exact wall time), which bounds what its timestamps can say. A
//! pass's timestamps are believed when each of its spans took a positive time, in a phase whose
//! timestamps add up to no more than its wall time, and when, over the run, the timestamps of the
//! phases that submitted it account for at least [`MIN_COVERAGE`] of their wall time (lavapipe's
//! shade phases: about 10 %; its record creation: over 90 %). Otherwise the pass's GPU columns
//! read `—`, and its rate is taken over the wall time of those phases, a measured lower bound
//! (`≥`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use radcache_render::{FrameOutput, Span, Track};
use serde_json::{json, Value};

const PID: u32 = 1;
const GPU_TID: u32 = 1;
const CPU_TID: u32 = 2;

/// The share of a host phase's wall time its GPU timestamps must account for to be believed.
pub const MIN_COVERAGE: f64 = 0.5;

/// Slack of the comparison of timestamps with wall time (clock granularity), seconds.
const SLACK_S: f64 = 50e-6;

/// Figures of one pass name over the run.
#[derive(Debug, Default, Clone)]
struct PassFigures {
    count: u64,
    total_ms: f64,
    min_ms: f64,
    max_ms: f64,
    rays: u64,
    /// Wall time of the host phases that submitted the pass (shared with the other passes of
    /// those phases), ms.
    wall_ms: f64,
    /// GPU time of all the passes of those phases, ms.
    phases_gpu_ms: f64,
    /// Spans that cannot be right: no time, or in a phase whose timestamps exceed its wall time.
    impossible: u64,
}

impl PassFigures {
    /// Whether the pass's timestamps are believed (see the module's doc).
    fn believed(&self) -> bool {
        self.impossible == 0 && self.phases_gpu_ms >= MIN_COVERAGE * self.wall_ms
    }

    /// The rate in Mrays/s, over GPU time when it is believed, else a lower bound over wall time.
    fn rate(&self) -> String {
        let mrays_per = |ms: f64| self.rays as f64 / (ms * 1e-3) / 1e6;
        if self.rays == 0 {
            "-".into()
        } else if self.believed() && self.total_ms > 0.0 {
            format!("{:.2}", mrays_per(self.total_ms))
        } else if self.wall_ms > 0.0 {
            format!("≥{:.2}", mrays_per(self.wall_ms))
        } else {
            "—".into()
        }
    }
}

/// The host phase (index into `phases`) whose wall time contains `span`'s start.
fn phase_of(phases: &[&Span], span: &Span) -> Option<usize> {
    phases
        .iter()
        .position(|p| p.start_s <= span.start_s && span.start_s < p.start_s + p.duration_s)
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
        }
        let phases: Vec<&Span> = out.spans.iter().filter(|s| s.track == Track::Cpu).collect();
        let passes: Vec<(&Span, Option<usize>)> = out
            .spans
            .iter()
            .filter(|s| s.track == Track::Gpu && s.depth == 0)
            .map(|s| (s, phase_of(&phases, s)))
            .collect();
        let mut gpu_s = vec![0.0; phases.len()];
        for (span, phase) in &passes {
            if let Some(i) = phase {
                gpu_s[*i] += span.duration_s;
            }
        }
        let fits = |i: usize| gpu_s[i] <= phases[i].duration_s + SLACK_S;
        let mut submitted_in: BTreeMap<&str, BTreeSet<usize>> = BTreeMap::new();
        for (span, phase) in &passes {
            let ms = span.duration_s * 1e3;
            let p = self.passes.entry(span.name.clone()).or_default();
            if p.count == 0 || ms < p.min_ms {
                p.min_ms = ms;
            }
            p.max_ms = p.max_ms.max(ms);
            p.count += 1;
            p.total_ms += ms;
            if span.duration_s <= 0.0 || phase.is_some_and(|i| !fits(i)) {
                p.impossible += 1;
            }
            if let Some(i) = phase {
                submitted_in.entry(&span.name).or_default().insert(*i);
            }
        }
        for (name, indices) in submitted_in {
            let wall_s: f64 = indices.iter().map(|&i| phases[i].duration_s).sum();
            let phases_gpu_s: f64 = indices.iter().map(|&i| gpu_s[i]).sum();
            if let Some(p) = self.passes.get_mut(name) {
                p.wall_ms += wall_s * 1e3;
                p.phases_gpu_ms += phases_gpu_s * 1e3;
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

    /// The per-pass table (see the module's doc for which figures are printed).
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<18} {:>6} {:>10} {:>9} {:>9} {:>9} {:>7} {:>10} {:>11} {:>9}\n",
            "pass",
            "count",
            "GPU ms",
            "mean ms",
            "min ms",
            "max ms",
            "share",
            "wall ms",
            "rays",
            "Mrays/s"
        );
        let frames_ms = (self.frames_s * 1e3).max(1e-9);
        for (name, p) in self.passes.iter().filter(|(_, p)| p.count > 0) {
            let gpu = if p.believed() {
                format!(
                    "{:>10.2} {:>9.3} {:>9.3} {:>9.3} {:>6.1}%",
                    p.total_ms,
                    p.total_ms / p.count as f64,
                    p.min_ms,
                    p.max_ms,
                    100.0 * p.total_ms / frames_ms,
                )
            } else {
                format!("{:>10} {:>9} {:>9} {:>9} {:>7}", "—", "—", "—", "—", "—")
            };
            let wall = if p.wall_ms > 0.0 {
                format!("{:.2}", p.wall_ms)
            } else {
                "—".into()
            };
            s += &format!(
                "{name:<18} {:>6} {gpu} {wall:>10} {:>11} {:>9}\n",
                p.count,
                p.rays,
                p.rate()
            );
        }
        s += &format!(
            "(GPU columns: timestamps, shown where they fit in the wall time of the host phases that \
             submitted them and account for at least {:.0} % of it; wall ms: those phases, shared \
             by their passes; ≥: rays over that wall time, a lower bound)\n",
            100.0 * MIN_COVERAGE
        );
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

    /// The row of `pass` in `table`, split into columns.
    fn row<'a>(table: &'a str, pass: &str) -> Vec<&'a str> {
        let line = table
            .lines()
            .find(|l| l.split_whitespace().next() == Some(pass))
            .unwrap_or_else(|| panic!("no {pass} row in\n{table}"));
        line.split_whitespace().collect()
    }

    #[test]
    fn timestamps_that_do_not_account_for_their_phase_are_not_printed() {
        // lavapipe's shade submission: the draws are timed, the compute pass that traces the
        // rays runs outside its timestamps (1 µs for 2 M rays), 100 ms of wall time in all.
        let mut p = Profile::new();
        let mut f = output(vec![
            span(Track::Cpu, "shade", 0.0, 0.1, 0),
            span(Track::Gpu, "gbuffer", 0.001, 0.002, 0),
            span(Track::Gpu, "direct", 0.003, 1e-6, 0),
            span(Track::Gpu, "composite", 0.003, 0.0, 0),
        ]);
        f.time_s = 0.1;
        f.rays = BTreeMap::from([("direct".to_string(), 2_000_000u64)]);
        p.frame(1, p.epoch, &f);
        let table = p.table();
        // Not the timestamps' 2,000,000 Mrays/s, but 2 M rays over the phase's 100 ms: ≥ 20.
        assert!(!table.contains("2000000.00"), "{table}");
        let direct = row(&table, "direct");
        assert_eq!(direct[2..7], ["—"; 5], "{table}");
        assert_eq!(direct[7..], ["100.00", "2000000", "≥20.00"], "{table}");
        // The same for the passes without rays, which keep their rays' "-".
        assert_eq!(row(&table, "gbuffer")[2], "—", "{table}");
        assert_eq!(*row(&table, "composite").last().unwrap(), "-", "{table}");
    }

    #[test]
    fn timestamps_longer_than_their_phase_or_empty_are_not_printed() {
        let mut p = Profile::new();
        let mut f = output(vec![
            span(Track::Cpu, "record_creation", 0.0, 0.010, 0),
            span(Track::Gpu, "records", 0.001, 0.050, 0),
            span(Track::Cpu, "emission", 0.010, 0.010, 0),
            span(Track::Gpu, "emission", 0.011, 0.008, 0),
            span(Track::Cpu, "shade", 0.020, 0.010, 0),
            span(Track::Gpu, "trace", 0.021, 0.008, 0),
            span(Track::Gpu, "empty", 0.029, 0.0, 0),
        ]);
        f.rays = BTreeMap::from([
            ("records".to_string(), 1000u64),
            ("emission".to_string(), 8000u64),
        ]);
        p.frame(1, p.epoch, &f);
        let table = p.table();
        // 50 ms of GPU work in a 10 ms wait cannot be: the rate is over the wall time.
        let records = row(&table, "records");
        assert_eq!(records[2], "—", "{table}");
        assert_eq!(*records.last().unwrap(), "≥0.10", "{table}");
        // A phase that its timestamps account for (8 of 10 ms) keeps them.
        let emission = row(&table, "emission");
        assert_eq!(emission[2], "8.00", "{table}");
        assert_eq!(*emission.last().unwrap(), "1.00", "{table}");
        // A pass of no time says nothing, and the pass beside it in its phase keeps its figures.
        assert_eq!(row(&table, "empty")[2], "—", "{table}");
        assert_eq!(row(&table, "trace")[2], "8.00", "{table}");
    }
}
