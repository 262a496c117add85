//! `radcache farm` on a one-node Slurm cluster (scripts/slurm-local.sh, which needs root and
//! installs Slurm where it is missing; the test fails when the cluster cannot start): 48 frames
//! of the bundled animation in 4 chunks match a single-process render within noise, chunk
//! boundaries flicker no more than 1.15× the single process at the same frames, and a second
//! run after two frames were deleted renders exactly those two.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant, SystemTime};

use radcache_image::{compare, flicker, read_exr, Image};

mod common;
use common::{bin, fresh_dir, repo, text};

const FRAMES: u32 = 48;
const CHUNK: u32 = 12;
const RENDER: &[&str] = &["--resolution", "32x32", "--quality", "draft"];
/// Frames around each chunk boundary (12|13, 24|25, 36|37) that get a path-traced reference.
const AROUND: [u32; 3] = [12, 24, 36];

/// The local cluster, stopped again when the test ends (also when it fails).
struct Cluster;

impl Cluster {
    fn start() -> Cluster {
        let out = slurm_local("start");
        assert!(
            out.status.success(),
            "scripts/slurm-local.sh start failed ({}):\n{}{}",
            out.status,
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        Cluster
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let out = slurm_local("stop");
        if !out.status.success() {
            eprintln!(
                "slurm-local.sh stop: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
    }
}

fn slurm_local(action: &str) -> Output {
    Command::new("bash")
        .arg(repo().join("scripts/slurm-local.sh"))
        .arg(action)
        .output()
        .expect("running scripts/slurm-local.sh")
}

fn animated() -> String {
    text(&repo().join("assets/animated/animated.gltf"))
}

fn frame(dir: &Path, n: u32) -> PathBuf {
    dir.join(format!("f_{n:04}.exr"))
}

fn image(path: &Path) -> Image {
    read_exr(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// Runs `radcache farm` on `dir` and returns its stdout.
fn farm(dir: &Path) -> String {
    let pattern = text(&dir.join("f_####.exr"));
    let chunk = CHUNK.to_string();
    let frames = format!("1..{FRAMES}");
    let mut args = vec![
        "farm", "--frames", &frames, "--chunk", &chunk, "-o", &pattern,
    ];
    let scene = animated();
    args.push(&scene);
    args.push("--");
    args.extend(RENDER);
    let out = bin().args(&args).output().expect("running radcache farm");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "radcache farm failed:\n{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// The job id on the line of `stdout` that starts with `label: job `.
fn job_id(stdout: &str, label: &str) -> String {
    let prefix = format!("{label}: job ");
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .unwrap_or_else(|| panic!("no '{prefix}' line in:\n{stdout}"));
    line.split_whitespace().next().unwrap().to_string()
}

/// Waits (at most 20 minutes) until job `id` has ended; returns its state.
fn wait_for_job(id: &str, dir: &Path) -> String {
    let start = Instant::now();
    loop {
        let out = Command::new("squeue")
            .args(["-h", "-t", "all", "-j", id, "-o", "%T"])
            .output()
            .expect("running squeue");
        let state = String::from_utf8_lossy(&out.stdout).trim().to_string();
        let ended = [
            "COMPLETED",
            "FAILED",
            "CANCELLED",
            "TIMEOUT",
            "NODE_FAIL",
            "OUT_OF_MEMORY",
        ];
        if ended.contains(&state.as_str()) {
            return state;
        }
        if start.elapsed() > Duration::from_secs(1200) {
            let logs = std::fs::read_dir(dir.join(".farm/logs"))
                .map(|d| {
                    d.flatten()
                        .map(|e| std::fs::read_to_string(e.path()).unwrap_or_default())
                        .collect::<Vec<_>>()
                        .join("\n")
                })
                .unwrap_or_default();
            panic!("job {id} still '{state}' after 20 minutes; logs:\n{logs}");
        }
        std::thread::sleep(Duration::from_millis(500));
    }
}

fn mtimes(dir: &Path) -> BTreeMap<u32, SystemTime> {
    (1..=FRAMES)
        .map(|n| {
            let meta = std::fs::metadata(frame(dir, n))
                .unwrap_or_else(|e| panic!("frame {n} in {}: {e}", dir.display()));
            (n, meta.modified().unwrap())
        })
        .collect()
}

/// Renders `frames` of the animation into `dir` in one process, with `extra` options.
fn render(dir: &Path, frames: &str, extra: &[&str]) {
    let pattern = text(&dir.join("f_####.exr"));
    let scene = animated();
    let mut args = vec!["render", &scene, "-o", &pattern, "--frames", frames];
    args.extend(extra);
    args.push("-q");
    let out = bin().args(&args).output().expect("running radcache render");
    assert!(
        out.status.success(),
        "radcache {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Mean relMSE of `dir`'s frames against the reference's, over the frames around boundaries.
fn mean_relmse(dir: &Path, reference: &Path) -> f64 {
    let around: Vec<u32> = AROUND.iter().flat_map(|&b| b - 1..=b + 2).collect();
    let sum: f64 = around
        .iter()
        .map(|&n| {
            let r = image(&frame(reference, n));
            compare(&r, &image(&frame(dir, n))).unwrap().relmse
        })
        .sum();
    sum / around.len() as f64
}

/// Mean flicker (against the reference) of the pairs across chunk boundaries and of the pairs
/// next to them inside chunks.
fn boundary_and_inside_flicker(dir: &Path, reference: &Path) -> (f64, f64) {
    let (mut across, mut inside) = (Vec::new(), Vec::new());
    for b in AROUND {
        let frames: Vec<Image> = (b - 1..=b + 2).map(|n| image(&frame(dir, n))).collect();
        let refs: Vec<Image> = (b - 1..=b + 2)
            .map(|n| image(&frame(reference, n)))
            .collect();
        let report = flicker(&frames, Some(&refs)).unwrap();
        // Pairs (b−1, b) and (b+1, b+2) are inside chunks, (b, b+1) crosses the boundary.
        inside.push(report.pairs[0].flicker);
        across.push(report.pairs[1].flicker);
        inside.push(report.pairs[2].flicker);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    (mean(&across), mean(&inside))
}

#[test]
fn a_sequence_renders_on_a_local_slurm_cluster_and_resumes() {
    let _cluster = Cluster::start();
    let root = fresh_dir("farm", "seq");
    let dir = root.join("farm");

    // The farm run: 4 chunks, every frame on disk afterwards, a summary naming none missing.
    let started = Instant::now();
    let stdout = farm(&dir);
    assert!(stdout.contains("chunks to render: 1-4"), "{stdout}");
    let final_job = job_id(&stdout, "final");
    let state = wait_for_job(&final_job, &dir);
    eprintln!("farm run: {:.1} s", started.elapsed().as_secs_f64());
    let summary = std::fs::read_to_string(dir.join(".farm/summary.md")).unwrap();
    if summary.contains(" killed") {
        // A render a signal killed ran again (--retries 1); the run counts, the crash is shown.
        eprintln!("a chunk's render was killed and ran again:\n{summary}");
    }
    assert_eq!(state, "COMPLETED", "final job; summary:\n{summary}");
    for n in 1..=FRAMES {
        assert!(frame(&dir, n).is_file(), "frame {n} is missing");
    }
    assert!(
        summary.contains("48 of 48 present, none missing"),
        "{summary}"
    );
    // Every chunk's row says ok (a render killed and run again reads "ok after exit 134").
    for i in 1..=4 {
        let row = summary
            .lines()
            .find(|l| l.starts_with(&format!("| {i} | ")))
            .unwrap_or_else(|| panic!("no row for chunk {i}:\n{summary}"));
        let status = row.split('|').nth(3).unwrap_or("").trim();
        assert!(status.starts_with("ok"), "chunk {i}: {row}\n{summary}");
    }
    assert!(dir.join(".farm/contact.png").is_file());

    // One process over the same range, and a path-traced reference around the boundaries.
    let single = root.join("single");
    render(&single, &format!("1..{FRAMES}"), RENDER);
    let reference = root.join("reference");
    for b in AROUND {
        let range = format!("{}..{}", b - 1, b + 2);
        let mut extra = vec!["--start-frame", "1", "--method", "path", "--spp", "256"];
        extra.extend(RENDER);
        render(&reference, &range, &extra);
    }
    let (farm_error, single_error) = (
        mean_relmse(&dir, &reference),
        mean_relmse(&single, &reference),
    );
    eprintln!("relMSE: farm {farm_error:.5}, single process {single_error:.5}");
    assert!(
        farm_error <= 1.2 * single_error,
        "farm relMSE {farm_error} > 1.2 × the single process's {single_error}"
    );
    // The boundary pairs against the same pairs of the single process: what chunking adds,
    // apart from what the animation does there (with adaptive anti-aliasing the single process
    // itself flickers 1.15× more at these pairs than next to them; docs/farm.md).
    let (single_across, single_inside) = boundary_and_inside_flicker(&single, &reference);
    let (across, inside) = boundary_and_inside_flicker(&dir, &reference);
    eprintln!(
        "flicker: across boundaries {across:.5} (single process {single_across:.5}), \
         inside chunks {inside:.5} (single process {single_inside:.5})"
    );
    assert!(
        across <= 1.15 * single_across,
        "flicker across chunk boundaries {across} > 1.15 × the single process's at the same \
         frames {single_across}"
    );

    // Two frames deleted: the summary names them, and a second run renders exactly those.
    let before = mtimes(&dir);
    for n in [14, 30] {
        std::fs::remove_file(frame(&dir, n)).unwrap();
    }
    let out = bin()
        .args(["farm", &animated(), "-o", &text(&dir.join("f_####.exr"))])
        .args(["--frames", "1..48", "--chunk", "12", "--summarize"])
        .output()
        .unwrap();
    let text_out = String::from_utf8_lossy(&out.stdout);
    assert!(!out.status.success(), "missing frames fail the summary");
    assert!(text_out.contains("missing: 14,30"), "{text_out}");

    std::thread::sleep(Duration::from_millis(20)); // a rewritten file gets a later mtime
    let stdout = farm(&dir);
    assert!(
        stdout.contains("missing: 2 frames (14,30); chunks to render: 2-3"),
        "{stdout}"
    );
    let state = wait_for_job(&job_id(&stdout, "final"), &dir);
    assert_eq!(state, "COMPLETED");
    let after = mtimes(&dir);
    for n in 1..=FRAMES {
        if n == 14 || n == 30 {
            assert!(frame(&dir, n).is_file(), "frame {n} was not rendered again");
        } else {
            assert_eq!(after[&n], before[&n], "frame {n} was rewritten");
        }
    }
    let log = std::fs::read_to_string(dir.join(".farm/logs/chunk_2.out")).unwrap();
    assert_eq!(
        log.matches("radcache-farm: chunk 2 frames 13..24 exit 0")
            .count(),
        2,
        "{log}"
    );
    for i in [1, 4] {
        let log = std::fs::read_to_string(dir.join(format!(".farm/logs/chunk_{i}.out"))).unwrap();
        assert_eq!(
            log.matches(" exit 0 ").count(),
            1,
            "chunk {i} ran again:\n{log}"
        );
    }
    let _ = std::fs::remove_dir_all(&root);
}

/// `--dry-run` prints the scripts and the sbatch commands without a cluster; the farm refuses a
/// prepass for moving geometry and the render options it sets itself.
#[test]
fn a_dry_run_prints_the_jobs_and_bad_requests_are_refused() {
    let dir = fresh_dir("farm", "dry");
    let pattern = text(&dir.join("f_####.exr"));
    let cornell = text(&repo().join("assets/cornell/cornell.gltf"));
    let out = bin()
        .args(["farm", &cornell, "-o", &pattern, "--frames", "1..50"])
        .args([
            "--chunk",
            "24",
            "--prepass-every",
            "5",
            "--partition",
            "gpu",
        ])
        .args(["--dry-run", "--", "--resolution", "64x64"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    for expected in [
        "warm-up 0 frames per chunk (plan: None)",
        "chunks to render: 1-3",
        "#SBATCH --partition=gpu",
        "cache build",
        "--every 5 -o",
        "--cache-in",
        "--dependency=afterok:$PREPASS",
        "--array=1-3",
        "--dependency=afterany:$CHUNKS",
        "--summarize",
    ] {
        assert!(stdout.contains(expected), "no {expected:?} in:\n{stdout}");
    }
    assert!(!dir.join(".farm").exists(), "a dry run writes nothing");

    // A camera path over static geometry warms up each chunk, unless a prepass gives every
    // chunk the same records.
    let fly = text(&repo().join("assets/cornell_fly/cornell_fly.gltf"));
    let dry = |extra: &[&str]| {
        let out = bin()
            .args([
                "farm", &fly, "-o", &pattern, "--frames", "1..12", "--chunk", "6",
            ])
            .args(extra)
            .args(["--dry-run", "--", "--resolution", "32x32"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).to_string()
    };
    assert!(dry(&[]).contains("warm-up 24 frames per chunk (plan: CameraOnly)"));
    assert!(
        dry(&["--prepass-every", "4"]).contains("warm-up 0 frames per chunk (plan: CameraOnly)")
    );

    let refused = |extra: &[&str], cause: &str| {
        let out = bin()
            .args(["farm", &animated(), "-o", &pattern, "--frames", "1..4"])
            .args(extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(cause), "{stderr}");
    };
    refused(&["--prepass-every", "4", "--dry-run"], "moving geometry");
    refused(
        &["--dry-run", "--", "--frames", "2"],
        "`--frames` after `--`",
    );
    refused(&["--dry-run", "--", "--qualty", "x"], "--qualty");
    refused(&["--chunk", "0", "--dry-run"], "--chunk");
    // The prepass job takes the chunks' options: one `cache build` does not accept is refused
    // before anything is written or submitted.
    let out = bin()
        .args(["farm", &cornell, "-o", &pattern, "--frames", "1..8"])
        .args(["--prepass-every", "4", "--dry-run", "--", "--png"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && stderr.contains("radcache cache build")
            && stderr.contains("--png"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
