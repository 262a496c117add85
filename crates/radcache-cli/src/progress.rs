//! Progress on stderr, drawn by `indicatif`: a bar per frame (samples per pixel, or the cache's
//! sub-frame phases: done/total, elapsed time, ETA) below a bar over the frames of a sequence.
//!
//! On a terminal the bars are redrawn in place and every other line of stderr (per-frame
//! summaries, log records) is printed above them, so that neither overwrites the other. Anywhere
//! else (a file, a pipe, a test capturing stderr) the bars are hidden, as `indicatif` does, and
//! the lines are printed as they come: a log keeps the per-frame summaries and the final "wrote"
//! line, without a bar's intermediate states.

use std::io::{IsTerminal, Write};
use std::sync::OnceLock;

use indicatif::{
    MultiProgress, ProgressBar, ProgressDrawTarget, ProgressFinish, ProgressState, ProgressStyle,
};

/// The run's bars, shared with the logger.
fn bars() -> &'static MultiProgress {
    static BARS: OnceLock<MultiProgress> = OnceLock::new();
    BARS.get_or_init(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr()))
}

/// Sets up the logger (`RUST_LOG`, warnings by default): on a terminal, its records are printed
/// above the bars.
pub fn init_logger() {
    let env = env_logger::Env::default().default_filter_or("warn");
    let mut builder = env_logger::Builder::from_env(env);
    if !bars().is_hidden() {
        builder.target(env_logger::Target::Pipe(Box::new(AboveBars)));
        // A pipe target is not coloured by default; this one ends on the terminal.
        let colour = std::io::stderr().is_terminal()
            && std::env::var_os("NO_COLOR").is_none()
            && std::env::var_os("RUST_LOG_STYLE").is_none();
        if colour {
            builder.write_style(env_logger::WriteStyle::Always);
        }
    }
    builder.init();
}

/// Writes log records to stderr with the bars cleared, then redraws them.
struct AboveBars;

impl Write for AboveBars {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        bars().suspend(|| std::io::stderr().write_all(buf))?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        std::io::stderr().flush()
    }
}

/// Prints `text` as a line of stderr (above the bars, on a terminal).
pub fn line(text: &str) {
    let bars = bars();
    if bars.is_hidden() || bars.println(text).is_err() {
        let _ = writeln!(std::io::stderr().lock(), "{text}");
    }
}

/// A frame's bar: `frame 3 [####>----] 25% 4/16 spp 1.2s, ETA 3.6s`.
const FRAME_TEMPLATE: &str =
    "{prefix} [{bar:30}] {percent:>3}% {pos}/{len} {msg} {elapsed_s}, ETA {eta_s}";

/// A sequence's bar: `frames [####>----] 3/10 ETA 12 s`.
const SEQUENCE_TEMPLATE: &str = "frames [{bar:30}] {pos}/{len} {msg}";

/// A bar style from `template`, with `{elapsed_s}` and `{eta_s}` in seconds (one decimal).
fn style(template: &str) -> ProgressStyle {
    let seconds = |d: std::time::Duration, w: &mut dyn std::fmt::Write| {
        let _ = write!(w, "{:.1}s", d.as_secs_f64());
    };
    ProgressStyle::with_template(template)
        .expect("a valid progress template")
        .progress_chars("#>-")
        .with_key(
            "elapsed_s",
            move |s: &ProgressState, w: &mut dyn std::fmt::Write| seconds(s.elapsed(), w),
        )
        .with_key(
            "eta_s",
            move |s: &ProgressState, w: &mut dyn std::fmt::Write| seconds(s.eta(), w),
        )
}

/// A bar of the run: hidden when `quiet`, cleared when done or dropped.
fn bar(len: u64, template: &str, quiet: bool) -> ProgressBar {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        bars().add(ProgressBar::new(len))
    };
    bar.set_style(style(template));
    bar.with_finish(ProgressFinish::AndClear)
}

/// The progress of one frame (or of a reference render), in `unit` (e.g. "spp").
#[derive(Debug)]
pub struct FrameBar {
    bar: ProgressBar,
}

impl FrameBar {
    /// A bar titled `label`; `quiet` hides it.
    pub fn new(label: impl Into<String>, unit: &'static str, quiet: bool) -> Self {
        let bar = bar(1, FRAME_TEMPLATE, quiet);
        bar.set_prefix(label.into());
        bar.set_message(unit);
        FrameBar { bar }
    }

    /// Reports `done` of `total` (the total may change: an estimate under a time budget).
    pub fn update(&self, done: u32, total: u32) {
        self.bar.set_length(u64::from(total.max(done).max(1)));
        self.bar.set_position(u64::from(done));
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// The progress over the frames of a sequence: frames done or skipped of all, and an ETA in the
/// message.
#[derive(Debug)]
pub struct SequenceBar {
    bar: ProgressBar,
}

impl SequenceBar {
    /// A bar over `frames` frames; hidden when `quiet` or for a single frame.
    pub fn new(frames: usize, quiet: bool) -> Self {
        SequenceBar {
            bar: bar(frames as u64, SEQUENCE_TEMPLATE, quiet || frames <= 1),
        }
    }

    /// `passed` frames of the sequence are done (rendered or skipped); `eta` says what is left.
    pub fn update(&self, passed: usize, eta: &str) {
        self.bar.set_position(passed as u64);
        self.bar.set_message(eta.to_string());
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Warm-up frames rendered since the last written frame, reported in one line before it:
/// `warm-up: frames 9..12 (4) in 3.10 s` (a farm's summary reads these).
#[derive(Debug, Default)]
pub struct WarmUp {
    frames: Option<(u32, u32)>,
    seconds: f64,
}

impl WarmUp {
    /// A warm-up frame took `seconds`.
    pub fn add(&mut self, frame: u32, seconds: f64) {
        let first = self.frames.map_or(frame, |(a, _)| a);
        self.frames = Some((first, frame));
        self.seconds += seconds;
    }

    /// Prints the line (unless `quiet`) for the frames added since the last report.
    pub fn report(&mut self, quiet: bool) {
        if let Some((a, b)) = self.frames.take() {
            if !quiet {
                line(&format!(
                    "warm-up: frames {a}..{b} ({}) in {:.2} s, not written",
                    b - a + 1,
                    self.seconds
                ));
            }
            self.seconds = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use super::*;

    /// A terminal that keeps what is written to it.
    #[derive(Debug, Clone, Default)]
    struct Screen(Arc<Mutex<String>>);

    impl indicatif::TermLike for Screen {
        fn width(&self) -> u16 {
            100
        }
        fn move_cursor_up(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_down(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_right(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_left(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn write_line(&self, s: &str) -> std::io::Result<()> {
            self.write_str(&format!("{s}\n"))
        }
        fn write_str(&self, s: &str) -> std::io::Result<()> {
            self.0.lock().unwrap().push_str(s);
            Ok(())
        }
        fn clear_line(&self) -> std::io::Result<()> {
            Ok(())
        }
        fn flush(&self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn bars_show_counts_units_times_and_lines_above_them() {
        let screen = Screen::default();
        let multi = MultiProgress::with_draw_target(ProgressDrawTarget::term_like(Box::new(
            screen.clone(),
        )));
        let sequence = multi.add(ProgressBar::new(10));
        sequence.set_style(style(SEQUENCE_TEMPLATE));
        sequence.set_position(3);
        sequence.set_message("ETA 12 s");
        let frame = multi.add(ProgressBar::new(16));
        frame.set_style(style(FRAME_TEMPLATE));
        frame.set_prefix("frame 4");
        frame.set_message("spp");
        frame.set_position(4);
        multi.println("frame 3: 1.20 s").unwrap();
        let text = screen.0.lock().unwrap().clone();
        let last = text.rfind("frame 3: 1.20 s").expect("the line is printed");
        let after = &text[last..];
        assert!(after.contains("frames ["), "{text:?}");
        assert!(after.contains("3/10 ETA 12 s"), "{text:?}");
        assert!(after.contains("frame 4 ["), "{text:?}");
        assert!(after.contains(" 25% 4/16 spp "), "{text:?}");
        assert!(
            after.contains("s, ETA ") && after.contains("#######>"),
            "{text:?}"
        );
        assert!(after.find("frames [") < after.find("frame 4 ["), "{text:?}");
    }
}
