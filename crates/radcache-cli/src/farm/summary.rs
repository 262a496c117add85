//! The final job's step (`radcache farm … --summarize`): from the files on disk, the contact
//! sheet (`contact.png`) and `summary.md` (also printed): frames present and missing, each
//! chunk's last run (exit status, seconds, warm-up seconds, its error), and the flicker of the
//! pairs across chunk boundaries against the pairs inside chunks (from `flicker.json`, written
//! by `radcache flicker --json` just before). Exits 1 when frames are missing.

use std::fmt::Write as _;
use std::process::ExitCode;

use anyhow::{Context as _, Result};
use radcache_image::PngOptions;

use super::{array_list, Layout};
use crate::sequence::ContactSheet;

/// A chunk's last run, from its log.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct ChunkRun {
    /// A start line was found.
    pub started: bool,
    /// Exit status and seconds from the end line (none: killed or still running).
    pub end: Option<(i32, f64)>,
    /// Seconds of warm-up frames (`warm-up: … in X s` lines of the render).
    pub warm_up_s: f64,
    /// The last `error: …` line.
    pub error: Option<String>,
    /// Attempts a signal killed before the last one (the script ran the render again): exit
    /// status and what the render printed after its last progress line (its dying words).
    pub killed: Vec<Killed>,
    /// The dying words of the last attempt, where a signal killed it too.
    pub crash: Option<String>,
}

/// An attempt of a chunk's render that a signal killed.
#[derive(Debug, Clone, PartialEq)]
pub struct Killed {
    pub exit: i32,
    /// The frame of the last progress line before it died.
    pub after_frame: Option<u32>,
    /// The first line the render printed after that (e.g. the C library's heap check).
    pub last_words: Option<String>,
}

/// The last run of chunk `chunk` in its log's text (logs are appended across runs).
pub fn parse_log(text: &str, chunk: u32) -> ChunkRun {
    let start = format!("radcache-farm: chunk {chunk} frames ");
    let lines: Vec<&str> = text.lines().collect();
    let Some(from) = lines
        .iter()
        .rposition(|l| l.starts_with(&start) && l.contains(" started on "))
    else {
        return ChunkRun::default();
    };
    let mut run = ChunkRun {
        started: true,
        ..ChunkRun::default()
    };
    // What the running attempt printed after its last progress line (its last words when a
    // signal kills it).
    let mut after_frame: Option<u32> = None;
    let mut last_words: Option<String> = None;
    let mut listening = true;
    for line in &lines[from + 1..] {
        if let Some(rest) = line.strip_prefix(&start) {
            let words: Vec<&str> = rest.split_whitespace().collect();
            match words[1..] {
                ["exit", rc, "seconds", s, ..] => {
                    if let (Ok(rc), Ok(s)) = (rc.parse::<i32>(), s.parse()) {
                        run.end = Some((rc, s));
                        if rc >= 128 {
                            run.crash = last_words.take();
                        }
                    }
                }
                ["attempt", _, "exit", rc, ..] => {
                    run.killed.push(Killed {
                        exit: rc.parse().unwrap_or(-1),
                        after_frame: after_frame.take(),
                        last_words: last_words.take(),
                    });
                    listening = true;
                }
                _ => {}
            }
        } else if let Some(rest) = line.trim_start().strip_prefix("warm-up: frames ") {
            let seconds = rest
                .split(" in ")
                .nth(1)
                .and_then(|t| t.split_whitespace().next())
                .and_then(|t| t.parse::<f64>().ok());
            run.warm_up_s += seconds.unwrap_or(0.0);
        } else if let Some(n) = progress_frame(line) {
            after_frame = Some(n);
            last_words = None;
            listening = true;
        } else if line.starts_with("error: ") {
            run.error = Some(line.to_string());
        } else if listening && !line.trim().is_empty() {
            last_words = Some(line.chars().take(160).collect());
            listening = false;
        }
    }
    run
}

/// The frame of a render's progress line (`frame 17: 0.77 s [5/12 done, …`).
fn progress_frame(line: &str) -> Option<u32> {
    let rest = line.strip_prefix("frame ")?;
    let (n, _) = rest.split_once(": ")?;
    n.parse().ok()
}

/// Mean flicker of the pairs across chunk boundaries and of those inside chunks, with their
/// counts, from `radcache flicker --json` output.
pub fn boundary_flicker(layout: &Layout, report: &serde_json::Value) -> [(f64, usize); 2] {
    let mut sums = [(0.0, 0usize); 2];
    for pair in report["pairs"].as_array().into_iter().flatten() {
        let (Some(from), Some(to), Some(f)) = (
            pair["from"].as_u64(),
            pair["to"].as_u64(),
            pair["flicker"].as_f64(),
        ) else {
            continue;
        };
        let in_range = |n: u64| n >= u64::from(layout.first) && n <= u64::from(layout.last);
        if to != from + 1 || !in_range(from) || !in_range(to) {
            continue;
        }
        let across = layout.chunk_of(from as u32) != layout.chunk_of(to as u32);
        let slot = &mut sums[usize::from(!across)];
        slot.0 += f;
        slot.1 += 1;
    }
    sums.map(|(s, n)| (if n > 0 { s / n as f64 } else { 0.0 }, n))
}

pub fn run(layout: &Layout) -> Result<ExitCode> {
    let missing = layout.missing()?;
    let total = layout.last - layout.first + 1;
    let mut text = format!(
        "# radcache farm: {}\n\nframes {}..{}: {} of {total} present",
        layout.pattern.display(),
        layout.first,
        layout.last,
        total as usize - missing.len()
    );
    if missing.is_empty() {
        text.push_str(", none missing\n");
    } else {
        let _ = writeln!(text, "; missing: {}", array_list(&missing));
    }

    text.push_str("\n| chunk | frames | status | seconds | warm-up s |\n|---|---|---|---|---|\n");
    let mut errors = Vec::new();
    for i in 1..=layout.chunks() {
        let (a, b) = layout.chunk_frames(i);
        let log = layout.chunk_log(i);
        let run = match std::fs::read_to_string(&log) {
            Ok(t) => parse_log(&t, i),
            Err(_) => ChunkRun::default(),
        };
        let (status, seconds) = match (run.started, run.end) {
            (false, _) => ("no log".to_string(), "-".to_string()),
            (true, None) => ("did not finish".to_string(), "-".to_string()),
            (true, Some((rc, s))) => {
                let mut status = if rc == 0 {
                    "ok".to_string()
                } else {
                    format!("exit {rc}")
                };
                if !run.killed.is_empty() {
                    let exits: Vec<String> = run
                        .killed
                        .iter()
                        .map(|k| format!("exit {}", k.exit))
                        .collect();
                    let _ = write!(status, " after {}", exits.join(", "));
                }
                (status, format!("{s:.1}"))
            }
        };
        let _ = writeln!(
            text,
            "| {i} | {a}..{b} | {status} | {seconds} | {:.1} |",
            run.warm_up_s
        );
        for (n, k) in run.killed.iter().enumerate() {
            let after = k
                .after_frame
                .map_or(String::new(), |f| format!(" after frame {f}"));
            let words = k.last_words.as_deref().unwrap_or("(nothing printed)");
            errors.push(format!(
                "chunk {i} ({}): attempt {} killed (exit {}){after}, run again: {words}",
                log.display(),
                n + 1,
                k.exit
            ));
        }
        if let Some(words) = &run.crash {
            errors.push(format!("chunk {i} ({}): killed: {words}", log.display()));
        }
        if let Some(e) = run.error {
            errors.push(format!("chunk {i} ({}): {e}", log.display()));
        }
    }
    for e in &errors {
        let _ = writeln!(text, "\n{e}");
    }

    let flicker_path = layout.flicker_json();
    match std::fs::read_to_string(&flicker_path)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
    {
        Some(report) => {
            let [(across, n_across), (inside, n_inside)] = boundary_flicker(layout, &report);
            let _ = writeln!(
                text,
                "\nflicker (mode {}): overall {:.6}; pairs across chunk boundaries {across:.6} \
                 (mean of {n_across}), inside chunks {inside:.6} (mean of {n_inside})",
                report["mode"].as_str().unwrap_or("?"),
                report["flicker"].as_f64().unwrap_or(f64::NAN)
            );
        }
        None => {
            let _ = writeln!(text, "\nflicker: no report ({})", flicker_path.display());
        }
    }

    let sheet_path = layout.dir.join("contact.png");
    let mut sheet = ContactSheet::new(Some(sheet_path.clone()));
    for f in layout.first..=layout.last {
        let path = layout.frame(f)?;
        if path.exists() {
            sheet.add_file(&path)?;
        }
    }
    sheet.write(&PngOptions::default())?;
    let _ = writeln!(text, "\ncontact sheet: {}", sheet_path.display());

    let summary = layout.dir.join("summary.md");
    crate::output::write_text(&summary, &text, "farm summary")
        .with_context(|| format!("the summary of {}", layout.pattern.display()))?;
    crate::output::emit(&text)?;
    Ok(if missing.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_gives_its_last_run() {
        let log = "radcache-farm: chunk 2 frames 13..24 started on a at t\n\
                   error: the GPU fell off\n\
                   radcache-farm: chunk 2 frames 13..24 exit 1 seconds 3.5\n\
                   radcache-farm: chunk 2 frames 13..24 started on b at t\n\
                   warm-up: frames 9..12 (4) in 1.25 s, not written\n\
                   frame 13: 0.20 s [1/12 done, 0 skipped] ETA 2 s\n\
                   warm-up: frames 15..16 (2) in 0.50 s, not written\n\
                   radcache-farm: chunk 2 frames 13..24 exit 0 seconds 7.0\n";
        let run = parse_log(log, 2);
        assert_eq!(run.end, Some((0, 7.0)));
        assert_eq!(run.warm_up_s, 1.75);
        assert_eq!(run.error, None, "the error belongs to the earlier run");
        let killed = parse_log(&log[..log.find("error").unwrap() + 30], 2);
        assert!(killed.started && killed.end.is_none());
        assert_eq!(parse_log(log, 3), ChunkRun::default());
    }

    #[test]
    fn killed_attempts_keep_their_last_words() {
        let log = "radcache-farm: chunk 2 frames 13..24 started on a at t\n\
                   warm-up: frames 1..12 (12) in 6.31 s, not written\n\
                   frame 13: 0.60 s [1/12 done, 0 skipped] ETA 7 s\n\
                   frame 17: 0.77 s [5/12 done, 0 skipped] ETA 5 s\n\
                   malloc_consolidate(): unaligned fastbin chunk detected\n\
                   /spool/slurm_script: line 16: 25738 Aborted /bin/radcache render\n\
                   radcache-farm: chunk 2 frames 13..24 attempt 1 exit 134 (signal 6); running it again\n\
                   warm-up: frames 6..17 (12) in 6.00 s, not written\n\
                   frame 18: 0.60 s [1/12 done, 5 skipped] ETA 4 s\n\
                   frame 24: 0.60 s [7/12 done, 5 skipped] ETA 0 s\n\
                   7 frames rendered (0.60 s each), 5 skipped, 0 not rendered, 11.0 s in all\n\
                   radcache-farm: chunk 2 frames 13..24 exit 0 seconds 30.0\n";
        let run = parse_log(log, 2);
        assert_eq!(run.end, Some((0, 30.0)));
        assert!((run.warm_up_s - 12.31).abs() < 1e-9);
        assert_eq!(
            run.killed,
            vec![Killed {
                exit: 134,
                after_frame: Some(17),
                last_words: Some("malloc_consolidate(): unaligned fastbin chunk detected".into()),
            }]
        );
        assert_eq!(run.crash, None);
        let dead = "radcache-farm: chunk 1 frames 1..12 started on a at t\n\
                    Segmentation fault\n\
                    radcache-farm: chunk 1 frames 1..12 exit 139 seconds 1.0\n";
        let run = parse_log(dead, 1);
        assert_eq!(run.crash.as_deref(), Some("Segmentation fault"));
        assert!(run.killed.is_empty());
    }

    #[test]
    fn pairs_are_split_at_chunk_boundaries() {
        let layout = Layout {
            scene: "/s.gltf".into(),
            pattern: "/o/f_####.exr".into(),
            first: 1,
            last: 6,
            chunk: 3,
            dir: "/o/.farm".into(),
        };
        let report = serde_json::json!({"pairs": [
            {"from": 1, "to": 2, "flicker": 0.1},
            {"from": 2, "to": 3, "flicker": 0.3},
            {"from": 3, "to": 4, "flicker": 0.5},
            {"from": 5, "to": 6, "flicker": 0.2},
            {"from": 6, "to": 8, "flicker": 9.0},
        ]});
        let [(across, n_across), (inside, n_inside)] = boundary_flicker(&layout, &report);
        assert_eq!((across, n_across), (0.5, 1));
        assert!((inside - 0.2).abs() < 1e-12 && n_inside == 3);
    }
}
