//! Sequence renders of the `radcache` binary on lavapipe: frames of a static scene with the
//! cache kept are identical; a run killed mid-way resumes without recomputing a frame and ends
//! with the same files as an uninterrupted run; Ctrl-C finishes the frame in flight and stops.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

use radcache_image::read_exr;

mod common;
use common::{bin, cornell, fresh_dir};

const FRAMES: u32 = 10;

fn out_dir(name: &str) -> PathBuf {
    fresh_dir("seq", name)
}

/// The arguments of a sequence render of the (static) Cornell box into `dir`.
fn args(dir: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "render",
        &cornell(),
        "-o",
        &dir.join("f_####.exr").display().to_string(),
        "--frames",
        &format!("1..{FRAMES}"),
        "--resolution",
        "24x24",
        "--quality",
        "draft",
        "--sub-frames",
        "2",
        "--direct-samples",
        "2",
        "-q",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn run(dir: &Path, extra: &[&str]) -> Output {
    bin()
        .args(args(dir, extra))
        .output()
        .expect("running radcache")
}

fn spawn(dir: &Path) -> Child {
    bin()
        .args(args(dir, &[]))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting radcache")
}

fn frame(dir: &Path, n: u32) -> PathBuf {
    dir.join(format!("f_{n:04}.exr"))
}

fn wait_for(path: &Path) {
    let start = Instant::now();
    while !path.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "{} never appeared",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn pixels(path: &Path) -> Vec<[f32; 3]> {
    read_exr(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
        .pixels()
        .collect()
}

fn on_disk(dir: &Path) -> Vec<(u32, SystemTime)> {
    (1..=FRAMES)
        .filter_map(|n| {
            let m = std::fs::metadata(frame(dir, n)).ok()?;
            Some((n, m.modified().unwrap()))
        })
        .collect()
}

fn assert_ok(out: &Output) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "radcache failed: {stderr}");
}

/// No temporary or partial file is left at a frame path.
fn assert_clean(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            name.starts_with('.') || (name.starts_with("f_") && name.ends_with(".exr")),
            "unexpected file {name}"
        );
    }
}

#[test]
fn a_killed_sequence_resumes_to_the_same_frames() {
    let whole = out_dir("whole");
    assert_ok(&run(&whole, &[]));
    let first = pixels(&frame(&whole, 1));
    for n in 2..=FRAMES {
        assert!(
            pixels(&frame(&whole, n)) == first,
            "frame {n} of a static scene differs from frame 1"
        );
    }

    let cut = out_dir("cut");
    let mut child = spawn(&cut);
    wait_for(&frame(&cut, 2));
    child.kill().unwrap();
    child.wait().unwrap();
    assert_clean(&cut);
    let before = on_disk(&cut);
    assert!(
        before.len() >= 2 && before.len() < FRAMES as usize,
        "{} frames on disk after the kill",
        before.len()
    );
    let stats = cut.join("stats.json");
    let sheet = cut.join("sheet").join("contact.png");
    assert_ok(&run(
        &cut,
        &[
            "--stats",
            &stats.display().to_string(),
            "--contact-sheet",
            &sheet.display().to_string(),
        ],
    ));
    // The contact sheet shows every frame, the ones read back from disk included: 24-pixel
    // cells in ⌈√FRAMES⌉ columns with 2-pixel gaps.
    let png = std::fs::read(&sheet).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    let size = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
    let columns = (f64::from(FRAMES).sqrt().ceil()) as u32;
    let rows = FRAMES.div_ceil(columns);
    assert_eq!(
        (size(16), size(20)),
        (columns * 26 + 2, rows * 26 + 2),
        "contact sheet size"
    );
    // Frames already on disk were kept as they were, and only the others were rendered.
    for (n, modified) in &before {
        let now = std::fs::metadata(frame(&cut, *n))
            .unwrap()
            .modified()
            .unwrap();
        assert_eq!(now, *modified, "frame {n} was written again");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let rendered: Vec<u64> = json["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["frame"].as_u64().unwrap())
        .collect();
    let expected: Vec<u64> = (1..=u64::from(FRAMES))
        .filter(|n| !before.iter().any(|(b, _)| u64::from(*b) == *n))
        .collect();
    assert_eq!(rendered, expected);
    // The frames rendered after the restart come from a cache built afresh: the same records,
    // possibly created in another order (GPU atomics), so equal up to float round-off.
    for n in 1..=FRAMES {
        let (a, b) = (pixels(&frame(&cut, n)), pixels(&frame(&whole, n)));
        for (x, y) in a.iter().zip(&b) {
            for c in 0..3 {
                let tol = 1e-5 * x[c].abs().max(1e-3);
                assert!((x[c] - y[c]).abs() <= tol, "frame {n}: {x:?} vs {y:?}");
            }
        }
    }
    // --overwrite renders everything again.
    let again = run(
        &cut,
        &["--overwrite", "--stats", &stats.display().to_string()],
    );
    assert_ok(&again);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    let frames = json["frames"].as_array().unwrap();
    assert_eq!(frames.len(), FRAMES as usize);
    assert_eq!(json["temporal"], true, "a static scene keeps its records");
    // Frame 1 builds the cache; every later frame keeps it all and creates nothing.
    assert_eq!(frames[0]["records_kept"], 0);
    for f in &frames[1..] {
        assert_eq!(f["records_kept"], frames[0]["records"], "{f}");
        assert_eq!(
            (&f["records_created"], &f["records_evicted"]),
            (&0.into(), &0.into())
        );
        assert!(f["cache_passes"].as_u64().unwrap() >= 1);
    }
}

#[test]
fn ctrl_c_finishes_the_frame_in_flight_and_stops() {
    let dir = out_dir("interrupt");
    let child = spawn(&dir);
    wait_for(&frame(&dir, 1));
    let pid = child.id().to_string();
    let sent = Command::new("kill").args(["-INT", &pid]).status().unwrap();
    assert!(sent.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("finishing the frame in flight"), "{stderr}");
    assert_clean(&dir);
    let done = on_disk(&dir);
    assert!(
        done.len() < FRAMES as usize,
        "the run did not stop: {stderr}"
    );
    for (n, _) in &done {
        assert_eq!(pixels(&frame(&dir, *n)).len(), 24 * 24, "frame {n}");
    }
}
