//! A progress line with ETA on stderr: redrawn in place on a terminal, a line every ~10% otherwise.

use std::io::{IsTerminal, Write};

/// Prints progress of a unit of work measured in `unit` (e.g. "spp").
#[derive(Debug)]
pub struct ProgressLine {
    label: String,
    unit: &'static str,
    terminal: bool,
    last_decile: u32,
    quiet: bool,
}

impl ProgressLine {
    /// A progress line titled `label`; `quiet` suppresses it entirely.
    pub fn new(label: impl Into<String>, unit: &'static str, quiet: bool) -> Self {
        ProgressLine {
            label: label.into(),
            unit,
            terminal: std::io::stderr().is_terminal(),
            last_decile: 0,
            quiet,
        }
    }

    /// Reports `done` of `total` after `elapsed_s` seconds.
    pub fn update(&mut self, done: u32, total: u32, elapsed_s: f64) {
        if self.quiet {
            return;
        }
        let total = total.max(done).max(1);
        let frac = f64::from(done) / f64::from(total);
        let eta = if done > 0 {
            elapsed_s * (1.0 - frac) / frac
        } else {
            f64::NAN
        };
        let width = 30usize;
        let filled = ((frac * width as f64) as usize).min(width);
        let line = format!(
            "{} [{}{}] {:3.0}% {done}/{total} {} {:.1}s, ETA {:.1}s",
            self.label,
            "#".repeat(filled),
            "-".repeat(width - filled),
            frac * 100.0,
            self.unit,
            elapsed_s,
            eta
        );
        let mut err = std::io::stderr().lock();
        if self.terminal {
            let _ = write!(err, "\r{line}\x1b[K");
            let _ = err.flush();
        } else {
            let decile = (frac * 10.0) as u32;
            if decile > self.last_decile || done == total {
                self.last_decile = decile;
                let _ = writeln!(err, "{line}");
            }
        }
    }

    /// Ends the line (on a terminal).
    pub fn finish(&self) {
        if self.terminal && !self.quiet {
            eprintln!();
        }
    }
}
