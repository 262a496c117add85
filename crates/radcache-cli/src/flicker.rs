//! `radcache flicker SEQUENCE [--reference REF] [--frames A..B] [--json]`: temporal stability of an
//! EXR sequence, per pair of consecutive frames and overall.
//!
//! The figures are those of [`radcache_image::flicker`] (see its module docs): against a
//! reference sequence, the relative RMS of the temporal differences that the reference does not
//! have; without one, the relative RMS of the temporal differences over pixels whose
//! depth/normal/albedo AOVs do not change (every pixel when the frames have no AOVs, so motion
//! then counts as flicker). Frames are read one at a time, so long sequences need little memory.
//!
//! Without `--frames` the frames are those of the sequence that exist on disk: the files in the
//! pattern's directory whose names are the pattern with digits in place of its run of `#` (as
//! [`radcache_image::frame_path`] writes them), in frame order. Pairs are consecutive frames of
//! that list, even where numbers are missing between them.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context as _, Result};
use clap::Args;
use radcache_image::{frame_path, read_exr, FlickerMeter, FlickerMode, FlickerReport, Image};

#[derive(Args, Debug)]
pub struct FlickerArgs {
    /// The EXR sequence: a path with a run of `#` for the frame number, e.g. `out/frame_####.exr`.
    sequence: PathBuf,
    /// A reference sequence with the same frame numbers (e.g. converged renders); without it
    /// only pixels whose depth/normal/albedo AOVs do not change are measured.
    #[arg(long, value_name = "REF_PATTERN")]
    reference: Option<PathBuf>,
    /// Frames `A..B`, both included (e.g. `1..48`); default: every frame of the sequence on disk.
    #[arg(long, value_name = "A..B", value_parser = parse_frames)]
    frames: Option<FrameRange>,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
}

/// An inclusive range of at least two frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct FrameRange {
    first: u32,
    last: u32,
}

/// Parses `A..B` (also `A..=B`) as `radcache render --frames` does; clap's message names
/// `--frames` and the text.
fn parse_frames(text: &str) -> Result<FrameRange, String> {
    const FORM: &str = "expected A..B with whole frame numbers, both included, e.g. 1..48";
    if !text.contains("..") {
        return Err(FORM.into());
    }
    let (first, last) = crate::sequence::parse_frames(text).map_err(|e| format!("{e:#}"))?;
    if first == last {
        return Err(format!(
            "{first}..{last} holds fewer than the 2 frames flicker needs; {FORM}"
        ));
    }
    Ok(FrameRange { first, last })
}

pub fn run(args: &FlickerArgs) -> Result<ExitCode> {
    let frames: Box<dyn Iterator<Item = u32>> = match args.frames {
        Some(range) => Box::new(range.first..=range.last),
        None => Box::new(frames_on_disk(&args.sequence)?.into_iter()),
    };
    let mut meter = FlickerMeter::new();
    let mut numbers = Vec::new();
    let mut first = None;
    for frame in frames {
        let path = frame_path(&args.sequence, frame)?;
        let image = read_frame(&path, &mut first)?;
        let reference = match &args.reference {
            Some(pattern) => Some(read_frame(&frame_path(pattern, frame)?, &mut first)?),
            None => None,
        };
        meter
            .push(image, reference)
            .with_context(|| format!("measuring frame {frame} ('{}')", path.display()))?;
        numbers.push(frame);
    }
    let report = meter.finish()?;
    let text = if args.json {
        format!(
            "{}\n",
            serde_json::to_string_pretty(&json(args, &report, &numbers))?
        )
    } else {
        table(args, &report, &numbers)
    };
    crate::output::emit(&text)?;
    Ok(ExitCode::SUCCESS)
}

/// The frame numbers of `pattern` that exist on disk, in increasing order; at least two.
fn frames_on_disk(pattern: &Path) -> Result<Vec<u32>> {
    frame_path(pattern, 0)?; // Checks the pattern: UTF-8, one run of '#'.
    let Some(name) = pattern.file_name().and_then(|n| n.to_str()) else {
        bail!("'{}' names no file", pattern.display());
    };
    let Some(start) = name.find('#') else {
        bail!(
            "cannot look for the frames of '{}': the run of '#' is not in the file name; give \
             --frames A..B",
            pattern.display()
        );
    };
    let width = name[start..].bytes().take_while(|&b| b == b'#').count();
    let (prefix, suffix) = (&name[..start], &name[start + width..]);
    let dir = match pattern.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let listing_error = || {
        format!(
            "cannot list '{}' for the frames of '{}'",
            dir.display(),
            pattern.display()
        )
    };
    let mut frames = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(listing_error)? {
        let file_name = entry.with_context(listing_error)?.file_name();
        let digits = file_name
            .to_str()
            .and_then(|n| n.strip_prefix(prefix)?.strip_suffix(suffix))
            .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()));
        // Only names that `frame_path` writes: `f_7.exr` is not a frame of `f_##.exr`.
        if let Some((digits, frame)) = digits.and_then(|d| Some((d, d.parse::<u32>().ok()?))) {
            if format!("{frame:0width$}") == digits {
                frames.push(frame);
            }
        }
    }
    frames.sort_unstable();
    if frames.len() < 2 {
        bail!(
            "found {} frame(s) of '{}' in '{}', but flicker needs at least 2",
            frames.len(),
            pattern.display(),
            dir.display()
        );
    }
    Ok(frames)
}

/// Reads one frame; every frame (and reference frame) must have the size of the first one read,
/// which `first` remembers with its path.
fn read_frame(path: &Path, first: &mut Option<(PathBuf, u32, u32)>) -> Result<Image> {
    if let Err(e) = std::fs::metadata(path) {
        bail!("cannot read '{}': {e}", path.display());
    }
    let (image, _) = read_exr(path)?;
    let (width, height) = (image.width(), image.height());
    match first {
        Some((first, w, h)) if (*w, *h) != (width, height) => bail!(
            "'{}' is {width}x{height}, but '{}' is {w}x{h}; every frame of the sequence and of \
             the reference must have one size",
            path.display(),
            first.display()
        ),
        Some(_) => {}
        None => *first = Some((path.to_owned(), width, height)),
    }
    Ok(image)
}

fn mode_name(mode: FlickerMode) -> &'static str {
    match mode {
        FlickerMode::Reference => "reference",
        FlickerMode::Static => "static",
    }
}

/// The JSON report; pairs name frame numbers, not indices.
fn json(args: &FlickerArgs, report: &FlickerReport, numbers: &[u32]) -> serde_json::Value {
    let pairs: Vec<_> = report
        .pairs
        .iter()
        .map(|p| {
            serde_json::json!({
                "from": numbers[p.from],
                "to": numbers[p.to],
                "flicker": p.flicker,
                "static_fraction": p.static_fraction,
                "nonfinite": p.nonfinite,
            })
        })
        .collect();
    serde_json::json!({
        "sequence": args.sequence,
        "reference": args.reference,
        "mode": mode_name(report.mode),
        "frames": numbers,
        "pairs": pairs,
        "flicker": report.flicker,
        "static_fraction": report.static_fraction,
        "nonfinite": report.nonfinite,
    })
}

/// The human-readable report: one row per pair, then the overall figures.
fn table(args: &FlickerArgs, report: &FlickerReport, numbers: &[u32]) -> String {
    let mut text = format!("flicker of {}", args.sequence.display());
    match &args.reference {
        Some(reference) => text.push_str(&format!(" against {}", reference.display())),
        None => text.push_str(" over pixels with unchanged AOVs (all pixels if there are none)"),
    }
    text.push_str(&format!(
        " ({} frames, mode {})\n{:>10} {:>10} {:>12} {:>8} {:>10}\n",
        report.frames,
        mode_name(report.mode),
        "from",
        "to",
        "flicker",
        "static",
        "nonfinite"
    ));
    let row = |label: String, flicker: f64, fraction: f64, nonfinite: u64| {
        let percent = fraction * 100.0;
        format!("{label:>21} {flicker:>12.6} {percent:>7.1}% {nonfinite:>10}\n")
    };
    for p in &report.pairs {
        let label = format!("{:>10} {:>10}", numbers[p.from], numbers[p.to]);
        text.push_str(&row(label, p.flicker, p.static_fraction, p.nonfinite));
    }
    text.push_str(&row(
        "overall".to_owned(),
        report.flicker,
        report.static_fraction,
        report.nonfinite,
    ));
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_parse_and_bad_ones_explain_themselves() {
        let range = |first, last| Ok(FrameRange { first, last });
        assert_eq!(parse_frames("1..48"), range(1, 48));
        assert_eq!(parse_frames("0..=2"), range(0, 2));
        for (text, cause) in [
            ("5", "expected A..B"),
            ("5..x", "\"x\" is not a frame number"),
            ("-1..3", "\"-1\" is not"),
            ("4..4", "fewer than the 2 frames"),
            ("9..2", "comes after the last"),
        ] {
            let err = parse_frames(text).unwrap_err();
            assert!(err.contains(cause), "{text}: {err}");
        }
    }
}
