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
    for line in &lines[from + 1..] {
        if let Some(rest) = line.strip_prefix(&start) {
            let words: Vec<&str> = rest.split_whitespace().collect();
            if let ["exit", rc, "seconds", s, ..] = words[1..] {
                if let (Ok(rc), Ok(s)) = (rc.parse(), s.parse()) {
                    run.end = Some((rc, s));
                }
            }
        } else if let Some(rest) = line.trim_start().strip_prefix("warm-up: frames ") {
            let seconds = rest
                .split(" in ")
                .nth(1)
                .and_then(|t| t.split_whitespace().next())
                .and_then(|t| t.parse::<f64>().ok());
            run.warm_up_s += seconds.unwrap_or(0.0);
        } else if line.starts_with("error: ") {
            run.error = Some(line.to_string());
        }
    }
    run
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
            (true, Some((0, s))) => ("ok".to_string(), format!("{s:.1}")),
            (true, Some((rc, s))) => (format!("exit {rc}"), format!("{s:.1}")),
        };
        let _ = writeln!(
            text,
            "| {i} | {a}..{b} | {status} | {seconds} | {:.1} |",
            run.warm_up_s
        );
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
