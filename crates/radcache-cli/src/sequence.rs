//! Frame sequences of `radcache render`: which frames, at which scene times, the progress
//! across them (a bar and a line per frame) and the optional contact sheet.
//!
//! Frames are numbered like Blender's: `--frames 1..120` is inclusive. Frame `f` of a sequence
//! starting at frame `first` shows the scene at `start + (f − first) / fps` (a single `--frame N`
//! counts from frame 1, like a sequence `1..N`), where `start` is
//! `--start-time`, else the animation's first key time, else 0. Without `--frames` or `--frame`,
//! an output pattern with `#` on an animated scene renders the animation's own range (from its
//! first to its last key at `fps`); anything else renders frame 1.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use radcache_image::PngOptions;
use radcache_image::{contact_sheet, read_exr, reduce, reduction_factor, write_png, Image};

use crate::progress::{self, SequenceBar};

/// Largest side of a contact sheet's cell, in pixels.
pub const CONTACT_CELL: u32 = 160;

/// The frames of a sequence, reduced, for `--contact-sheet` (nothing is kept without it).
#[derive(Debug)]
pub struct ContactSheet {
    path: Option<PathBuf>,
    cells: Vec<Image>,
}

impl ContactSheet {
    /// A sheet written to `path` at the end, or none.
    pub fn new(path: Option<PathBuf>) -> Self {
        ContactSheet {
            path,
            cells: Vec::new(),
        }
    }

    /// Adds a rendered frame.
    pub fn add(&mut self, image: &Image) {
        if self.path.is_some() {
            let f = reduction_factor(image.width(), image.height(), CONTACT_CELL);
            self.cells.push(reduce(image, f));
        }
    }

    /// Adds a frame already on disk (skipped by a resumed run): an EXR is read back; a PNG-only
    /// output cannot be, and leaves its cell out with a warning.
    pub fn add_file(&mut self, path: &Path) -> Result<()> {
        if self.path.is_none() {
            return Ok(());
        }
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            log::warn!(
                "contact sheet: {} is a PNG and is left out (only EXR frames are read back)",
                path.display()
            );
            return Ok(());
        }
        // The reader's errors name the file.
        let (image, _) = read_exr(path).context("reading a frame back for the contact sheet")?;
        self.add(&image);
        Ok(())
    }

    /// Writes the sheet (when asked for and any frame was added).
    pub fn write(&self, options: &PngOptions) -> Result<()> {
        let Some(path) = &self.path else {
            return Ok(());
        };
        if self.cells.is_empty() {
            log::warn!("contact sheet {}: no frame to show", path.display());
            return Ok(());
        }
        crate::output::make_parent(path, "contact sheet")?;
        let sheet = contact_sheet(&self.cells)?;
        write_png(path, &sheet, options).context("writing the contact sheet")?;
        Ok(())
    }
}

/// The frames to render and their scene times.
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    /// (frame number, scene time in seconds), in order.
    pub frames: Vec<(u32, f32)>,
    /// The frame shown at `start` and the frames per second (`time_of`).
    origin: u32,
    start: f32,
    fps: f32,
}

/// What a run does with one frame (see [`Sequence::steps`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Render and write it.
    Write,
    /// Render it for the cache's sake only (a warm-up frame): not written.
    WarmUp,
    /// Leave it: it is on disk and no frame to write follows closely.
    Skip,
}

/// One frame of a run's plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    pub frame: u32,
    pub time: f32,
    pub action: Action,
    /// The frame before it was not rendered in this run (the first rendered frame, or one after
    /// skipped frames): a kept cache has no history for it and starts afresh.
    pub after_gap: bool,
}

/// Parses an inclusive frame range `A..B` (or a single frame `N`).
pub fn parse_frames(text: &str) -> Result<(u32, u32)> {
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .with_context(|| format!("--frames {text:?}: {v:?} is not a frame number"))
    };
    let (a, b) = match text.split_once("..") {
        Some((a, b)) => (parse(a)?, parse(b.trim_start_matches('='))?),
        None => {
            let n = parse(text)?;
            (n, n)
        }
    };
    if a > b {
        bail!("--frames {text:?}: the first frame {a} comes after the last {b}");
    }
    if b - a >= 1_000_000 {
        bail!("--frames {text:?}: more than a million frames");
    }
    Ok((a, b))
}

/// What the command line says about frames and time.
#[derive(Debug, Clone, Copy, Default)]
pub struct FrameArgs<'a> {
    /// `--frames A..B`.
    pub frames: Option<&'a str>,
    /// `--frame N`.
    pub frame: Option<u32>,
    /// `--time T` (single frames only).
    pub time: Option<f32>,
    /// `--start-time S`.
    pub start_time: Option<f32>,
    /// `--fps F`.
    pub fps: f32,
    /// The output path contains a `#` run.
    pub pattern: bool,
    /// `--start-frame N`: the frame shown at the start time (default: the first of `--frames`).
    pub start_frame: Option<u32>,
}

impl Sequence {
    /// The frames for `args` on a scene whose animation spans `range` (key times, if any).
    pub fn new(args: &FrameArgs<'_>, range: Option<(f32, f32)>) -> Result<Sequence> {
        if !(args.fps.is_finite() && args.fps > 0.0) {
            bail!("--fps must be a positive number, got {}", args.fps);
        }
        if let Some(s) = args.start_time.filter(|s| !s.is_finite()) {
            bail!("--start-time must be finite, got {s}");
        }
        if let Some(t) = args.time.filter(|t| !t.is_finite()) {
            bail!("--time must be finite, got {t}");
        }
        let start = args.start_time.or(range.map(|(t0, _)| t0)).unwrap_or(0.0);
        // `origin`: the frame shown at `start`.
        let (first, last, origin) = match (args.frames, args.frame) {
            (Some(_), Some(_)) => bail!("--frames and --frame exclude each other"),
            (Some(text), None) => {
                let (a, b) = parse_frames(text)?;
                (a, b, args.start_frame.unwrap_or(a))
            }
            (None, Some(n)) => (n, n, 1.min(n)),
            (None, None) => match range {
                Some((t0, t1)) if args.pattern && args.time.is_none() => {
                    let count = ((t1 - t0).max(0.0) * args.fps + 1e-3).floor() as u32 + 1;
                    (1, count.min(1_000_000), 1)
                }
                _ => (1, 1, 1),
            },
        };
        if args.start_frame.is_some() && args.frames.is_none() {
            bail!("--start-frame applies to a sequence given with --frames");
        }
        if first != last && !args.pattern {
            bail!("a sequence needs a run of '#' in the output path for the frame number");
        }
        if let Some(t) = args.time {
            if first != last {
                bail!("--time sets one frame's time; use --start-time for a sequence");
            }
            return Ok(Sequence {
                frames: vec![(first, t)],
                origin: first,
                start: t,
                fps: args.fps,
            });
        }
        let mut sequence = Sequence {
            frames: Vec::new(),
            origin,
            start,
            fps: args.fps,
        };
        sequence.frames = (first..=last).map(|f| (f, sequence.time_of(f))).collect();
        Ok(sequence)
    }

    /// The scene time of frame `f` (also of frames before the first, for warm-up).
    pub fn time_of(&self, f: u32) -> f32 {
        self.start + (i64::from(f) - i64::from(self.origin)) as f32 / self.fps
    }

    /// The run's plan: every frame not `on_disk` is rendered and written; with `warm_up` K > 0,
    /// the K frames before each of those (down to the frame shown at the start time, even
    /// before the sequence's first frame) are rendered too, without being written, so that the
    /// cache kept across frames has the history it would have in one run from the start (a
    /// chunk of a farm render, or a resumed run). Every other frame on disk is skipped.
    pub fn steps(&self, warm_up: u32, on_disk: impl Fn(u32) -> bool) -> Vec<Step> {
        let missing: Vec<u32> = self
            .frames
            .iter()
            .map(|&(f, _)| f)
            .filter(|&f| !on_disk(f))
            .collect();
        let Some(&(first, _)) = self.frames.first() else {
            return Vec::new();
        };
        let last = self.frames.last().map_or(first, |&(f, _)| f);
        let lowest = first.saturating_sub(warm_up).max(self.origin.min(first));
        let mut steps: Vec<Step> = Vec::new();
        for f in lowest..=last {
            let in_range = f >= first;
            let action = if in_range && missing.binary_search(&f).is_ok() {
                Action::Write
            } else if missing.iter().any(|&m| m > f && m - f <= warm_up) {
                Action::WarmUp
            } else if in_range {
                Action::Skip
            } else {
                continue;
            };
            let after_gap = steps
                .last()
                .is_none_or(|p| p.action == Action::Skip || p.frame + 1 != f);
            steps.push(Step {
                frame: f,
                time: self.time_of(f),
                action,
                after_gap,
            });
        }
        steps
    }
}

/// The progress of a sequence on stderr: a bar over its frames (on a terminal) and one line per
/// finished frame: frame time, frames done and skipped, ETA.
#[derive(Debug)]
pub struct SequenceProgress {
    total: usize,
    done: usize,
    skipped: usize,
    render_s: f64,
    start: Instant,
    quiet: bool,
    bar: SequenceBar,
}

impl SequenceProgress {
    /// Progress over `total` frames.
    pub fn new(total: usize, quiet: bool) -> Self {
        SequenceProgress {
            total,
            done: 0,
            skipped: 0,
            render_s: 0.0,
            start: Instant::now(),
            quiet,
            bar: SequenceBar::new(total, quiet),
        }
    }

    fn line(&self, text: &str) {
        if !self.quiet {
            progress::line(text);
        }
    }

    /// Seconds left at the mean time of the frames rendered so far.
    fn eta_s(&self) -> f64 {
        let left = self.total - self.done - self.skipped;
        self.render_s / self.done.max(1) as f64 * left as f64
    }

    /// A frame already on disk was kept.
    pub fn skipped(&mut self, frame: u32, path: &std::path::Path) {
        self.skipped += 1;
        self.bar.update(self.done + self.skipped, "");
        self.line(&format!(
            "frame {frame}: {} exists, skipped (--overwrite renders it again)",
            path.display()
        ));
    }

    /// A frame was rendered and written in `seconds`.
    pub fn rendered(&mut self, frame: u32, seconds: f64) {
        self.done += 1;
        self.render_s += seconds;
        if self.total <= 1 {
            return; // a single frame has its own "wrote" line
        }
        let eta = self.eta_s();
        self.bar
            .update(self.done + self.skipped, &format!("ETA {eta:.0} s"));
        self.line(&format!(
            "frame {frame}: {seconds:.2} s [{}/{} done, {} skipped] ETA {eta:.0} s",
            self.done, self.total, self.skipped
        ));
    }

    /// The closing summary; `stopped` when Ctrl-C ended the run early.
    pub fn finish(&self, stopped: bool) {
        self.bar.finish();
        if self.total <= 1 && !stopped {
            return;
        }
        let mean = if self.done > 0 {
            self.render_s / self.done as f64
        } else {
            0.0
        };
        self.line(&format!(
            "{}{} frames rendered ({mean:.2} s each), {} skipped, {} not rendered, {:.1} s in all",
            if stopped { "stopped: " } else { "" },
            self.done,
            self.skipped,
            self.total - self.done - self.skipped,
            self.start.elapsed().as_secs_f64()
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(frames: Option<&str>, frame: Option<u32>) -> FrameArgs<'_> {
        FrameArgs {
            frames,
            frame,
            fps: 24.0,
            pattern: true,
            ..FrameArgs::default()
        }
    }

    #[test]
    fn ranges_are_inclusive_and_checked() {
        assert_eq!(parse_frames("1..120").unwrap(), (1, 120));
        assert_eq!(parse_frames("5..=7").unwrap(), (5, 7));
        assert_eq!(parse_frames("3").unwrap(), (3, 3));
        for bad in ["7..5", "a..3", "1..", "-1..2", ""] {
            assert!(parse_frames(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn frame_times_follow_fps_and_start() {
        let s = Sequence::new(&args(Some("10..12"), None), Some((0.5, 2.0))).unwrap();
        assert_eq!(
            s.frames,
            vec![(10, 0.5), (11, 0.5 + 1.0 / 24.0), (12, 0.5 + 2.0 / 24.0)]
        );
        let mut a = args(Some("1..2"), None);
        a.start_time = Some(3.0);
        a.fps = 2.0;
        assert_eq!(
            Sequence::new(&a, None).unwrap().frames,
            vec![(1, 3.0), (2, 3.5)]
        );
    }

    #[test]
    fn the_default_is_the_animation_range_or_frame_one() {
        let s = Sequence::new(&args(None, None), Some((0.0, 1.0))).unwrap();
        assert_eq!(s.frames.len(), 25);
        assert_eq!(s.frames[24], (25, 1.0));
        let s = Sequence::new(&args(None, None), None).unwrap();
        assert_eq!(s.frames, vec![(1, 0.0)]);
        let mut single = args(None, Some(7));
        assert_eq!(
            Sequence::new(&single, Some((0.5, 2.0))).unwrap().frames,
            vec![(7, 0.5 + 6.0 / 24.0)],
            "frame 7 of a sequence that starts at frame 1"
        );
        single.time = Some(0.25);
        assert_eq!(
            Sequence::new(&single, None).unwrap().frames,
            vec![(7, 0.25)]
        );
    }

    #[test]
    fn contradictions_are_errors() {
        assert!(Sequence::new(&args(Some("1..3"), Some(2)), None).is_err());
        let mut a = args(Some("1..3"), None);
        a.time = Some(1.0);
        assert!(Sequence::new(&a, None).is_err());
        a = args(Some("1..3"), None);
        a.pattern = false;
        assert!(Sequence::new(&a, None).is_err());
        a = args(Some("1..3"), None);
        a.fps = 0.0;
        assert!(Sequence::new(&a, None).is_err());
    }

    fn plan(steps: &[Step]) -> Vec<(u32, char, bool)> {
        let letter = |a| match a {
            Action::Write => 'w',
            Action::WarmUp => 'u',
            Action::Skip => 's',
        };
        steps
            .iter()
            .map(|s| (s.frame, letter(s.action), s.after_gap))
            .collect()
    }

    #[test]
    fn warm_up_frames_precede_each_frame_to_write() {
        // A chunk 13..16 of a sequence from frame 1: two warm-up frames before it, with the
        // times of the long run.
        let mut a = args(Some("13..16"), None);
        a.start_frame = Some(1);
        let s = Sequence::new(&a, Some((0.0, 5.0))).unwrap();
        assert_eq!(s.frames[0], (13, 12.0 / 24.0));
        let steps = s.steps(2, |_| false);
        assert_eq!(steps[0].time, 10.0 / 24.0);
        assert_eq!(
            plan(&steps),
            [
                (11, 'u', true),
                (12, 'u', false),
                (13, 'w', false),
                (14, 'w', false),
                (15, 'w', false),
                (16, 'w', false)
            ]
        );
        // Frames on disk: warm-up frames before each missing one (on disk or not), skips
        // elsewhere; a frame after skipped ones starts afresh.
        let on_disk = |f| f != 14 && f != 20;
        let s = Sequence::new(&args(Some("11..20"), None), None).unwrap();
        assert_eq!(
            plan(&s.steps(2, on_disk)),
            [
                (11, 's', true),
                (12, 'u', true),
                (13, 'u', false),
                (14, 'w', false),
                (15, 's', false),
                (16, 's', true),
                (17, 's', true),
                (18, 'u', true),
                (19, 'u', false),
                (20, 'w', false)
            ]
        );
        // Warm-up never goes before the frame shown at the start time; without warm-up frames
        // on disk are skipped as before.
        let s = Sequence::new(&args(Some("1..3"), None), None).unwrap();
        assert_eq!(plan(&s.steps(8, |_| false))[0], (1, 'w', true));
        let on_disk = |f| f == 2;
        assert_eq!(
            plan(&s.steps(0, on_disk)),
            [(1, 'w', true), (2, 's', false), (3, 'w', true)]
        );
        let mut a = args(Some("3..4"), None);
        a.start_frame = Some(2);
        let s = Sequence::new(&a, None).unwrap();
        assert_eq!(plan(&s.steps(8, |_| false))[0], (2, 'u', true));
        a.frames = None;
        a.frame = Some(3);
        assert!(
            Sequence::new(&a, None).is_err(),
            "--start-frame needs --frames"
        );
    }
}
