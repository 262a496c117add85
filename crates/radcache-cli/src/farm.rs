//! `radcache farm SCENE -o out/f_####.exr --frames 1..240 --chunk 24 [-- RENDER_ARGS]`: a
//! sequence on a Slurm cluster (docs/farm.md).
//!
//! It writes three job scripts under the farm folder (default `.farm/` beside the frames) and
//! submits them with `sbatch`, or prints them with `--dry-run`:
//!
//! - `prepass.sh` (with `--prepass-every N`, static geometry only, when the cache file is not on
//!   disk yet): `radcache cache build` over every N-th frame into `prepass.rcache`;
//! - `chunks.sh`: an array job, task `i` rendering chunk `i` (frames `first + (i−1)·chunk …`)
//!   with `radcache render`, after the prepass (`afterok`), reading its cache file; a moving
//!   scene's task first renders warm-up frames (not written) so its records have the history of
//!   one long run;
//! - `final.sh`, after every task (`afterany`, so it runs when some fail): `radcache flicker`
//!   over the sequence, then this command with `--summarize`: the contact sheet and
//!   `summary.md` (frames present, missing frames, per-chunk times, flicker at chunk
//!   boundaries against inside chunks).
//!
//! Only the chunks with frames missing on disk are submitted (`--array=` lists them), so running
//! the same command again after a failure renders what is missing and nothing else. Frames are
//! written atomically: a task killed mid-frame leaves no partial frame.

mod script;
mod summary;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use anyhow::{bail, Context as _, Result};
use clap::{Args, Parser};
use radcache_scene::{AnimationKind, LoadOptions, Scene};

use crate::args::{Method, RenderArgs};

/// Warm-up frames a chunk of a moving scene renders before its first frame: one second at
/// 24 fps. docs/farm.md has the measurement (flicker across chunk boundaries against inside
/// chunks for K = 0 … 24): the cache remembers its whole run, so only a warm-up that covers
/// the history back to the sequence's first frame reproduces one long run exactly; 24 is the
/// smallest measured K that kept boundaries within 1.2× at 12-frame chunks.
pub const DEFAULT_WARM_UP: u32 = 24;

#[derive(Args, Debug)]
pub struct FarmArgs {
    /// The glTF scene (.gltf or .glb), on a file system every node sees.
    scene: PathBuf,
    /// Output frames, with a run of `#` for the frame number, e.g. `out/f_####.exr`.
    #[arg(short, long)]
    output: PathBuf,
    /// The sequence: frames A..B, both included.
    #[arg(long, value_name = "A..B")]
    frames: String,
    /// Frames per array task.
    #[arg(long, default_value_t = 24)]
    chunk: u32,
    /// Compute the cache over every N-th frame first (`radcache cache build`, one job) and
    /// render every chunk from that file; static geometry only.
    #[arg(long, value_name = "N")]
    prepass_every: Option<u32>,
    /// Slurm partition of every job (default: the cluster's default partition).
    #[arg(long)]
    partition: Option<String>,
    /// Print the job scripts and the sbatch commands instead of submitting them.
    #[arg(long)]
    dry_run: bool,
    /// Warm-up frames per chunk (default: 24 where the scene moves and records are kept, else 0).
    #[arg(long, value_name = "K")]
    warm_up: Option<u32>,
    /// At most N tasks of the array at once (`--array=…%N`).
    #[arg(long, value_name = "N")]
    max_running: Option<u32>,
    /// Runs again of a chunk's render that a signal killed (an abort, a segmentation fault, the
    /// out-of-memory killer); the frames it wrote are kept. Errors are not retried.
    #[arg(long, value_name = "N", default_value_t = 1)]
    retries: u32,
    /// CPUs per task (`--cpus-per-task`).
    #[arg(long, value_name = "N")]
    cpus_per_task: Option<u32>,
    /// Folder of the job scripts, the task logs, the cache file and the summary (default:
    /// `.farm` in the frames' folder).
    #[arg(long, value_name = "DIR")]
    farm_dir: Option<PathBuf>,
    /// The final job's step: write the contact sheet and the summary of the frames on disk.
    #[arg(long, hide = true)]
    summarize: bool,
    /// Options of `radcache render` for every chunk, after `--` (e.g. `-- --resolution 640x360
    /// --quality draft --fps 24`); the farm sets the frames, the output and the cache file.
    #[arg(last = true, value_name = "RENDER_ARGS")]
    render: Vec<String>,
}

/// `radcache render` options the farm sets itself.
const SET_BY_FARM: &[&str] = &[
    "-o",
    "--output",
    "--frames",
    "--frame",
    "--time",
    "--start-frame",
    "--warm-up",
    "--overwrite",
    "--stats",
    "--profile",
    "--contact-sheet",
    "--cache-in",
    "--cache-out",
];

#[derive(Parser, Debug)]
#[command(no_binary_name = true, name = "render")]
struct RenderLine {
    #[command(flatten)]
    args: RenderArgs,
}

/// The farm's sequence: its frames, chunks and files, with absolute paths.
#[derive(Debug, Clone)]
pub struct Layout {
    pub scene: PathBuf,
    pub pattern: PathBuf,
    pub first: u32,
    pub last: u32,
    pub chunk: u32,
    pub dir: PathBuf,
}

impl Layout {
    fn new(args: &FarmArgs) -> Result<Layout> {
        let (first, last) = crate::sequence::parse_frames(&args.frames)?;
        if args.chunk == 0 {
            bail!("--chunk must be at least 1");
        }
        radcache_image::frame_path(&args.output, first)
            .with_context(|| format!("the output pattern '{}'", args.output.display()))?;
        if !radcache_image::has_frame_pattern(&args.output) {
            bail!(
                "the output '{}' needs a run of '#' for the frame number",
                args.output.display()
            );
        }
        let scene = std::fs::canonicalize(&args.scene)
            .with_context(|| format!("cannot find the scene '{}'", args.scene.display()))?;
        let pattern = std::path::absolute(&args.output)
            .with_context(|| format!("the output '{}'", args.output.display()))?;
        let dir = match &args.farm_dir {
            Some(d) => std::path::absolute(d)?,
            None => pattern.parent().unwrap_or(Path::new("/")).join(".farm"),
        };
        Ok(Layout {
            scene,
            pattern,
            first,
            last,
            chunk: args.chunk,
            dir,
        })
    }

    /// Number of chunks.
    pub fn chunks(&self) -> u32 {
        (self.last - self.first) / self.chunk + 1
    }

    /// The frames of chunk `i` (1-based), both included.
    pub fn chunk_frames(&self, i: u32) -> (u32, u32) {
        let a = self.first + (i - 1) * self.chunk;
        (a, (a + self.chunk - 1).min(self.last))
    }

    /// The chunk (1-based) that renders `frame`.
    pub fn chunk_of(&self, frame: u32) -> u32 {
        (frame - self.first) / self.chunk + 1
    }

    /// The path of `frame`.
    pub fn frame(&self, frame: u32) -> Result<PathBuf> {
        Ok(radcache_image::frame_path(&self.pattern, frame)?)
    }

    /// The frames not on disk, in order.
    pub fn missing(&self) -> Result<Vec<u32>> {
        let mut missing = Vec::new();
        for f in self.first..=self.last {
            if !self.frame(f)?.exists() {
                missing.push(f);
            }
        }
        Ok(missing)
    }

    pub fn cache_file(&self) -> PathBuf {
        self.dir.join("prepass.rcache")
    }

    pub fn log_dir(&self) -> PathBuf {
        self.dir.join("logs")
    }

    /// The log of chunk `i`.
    pub fn chunk_log(&self, i: u32) -> PathBuf {
        self.log_dir().join(format!("chunk_{i}.out"))
    }

    pub fn flicker_json(&self) -> PathBuf {
        self.dir.join("flicker.json")
    }
}

/// A Slurm `--array` list: runs of consecutive indices as `a-b`, e.g. `1-3,5`.
pub fn array_list(indices: &[u32]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let mut j = i;
        while j + 1 < indices.len() && indices[j + 1] == indices[j] + 1 {
            j += 1;
        }
        parts.push(if i == j {
            indices[i].to_string()
        } else {
            format!("{}-{}", indices[i], indices[j])
        });
        i = j + 1;
    }
    parts.join(",")
}

/// Checks the render arguments: none the farm sets, and `radcache render` accepts them.
fn render_args(layout: &Layout, extra: &[String]) -> Result<RenderArgs> {
    for arg in extra {
        let name = arg.split('=').next().unwrap_or(arg);
        if SET_BY_FARM.contains(&name) {
            bail!("`{name}` after `--` is set by radcache farm itself; give the farm's own options before `--`");
        }
    }
    let mut line = vec![
        layout.scene.display().to_string(),
        "-o".into(),
        layout.pattern.display().to_string(),
    ];
    line.extend(extra.iter().cloned());
    match RenderLine::try_parse_from(&line) {
        Ok(parsed) => Ok(parsed.args),
        Err(e) => {
            let text = e.render().to_string();
            let first = text.split("\n\n").next().unwrap_or(&text);
            bail!(
                "the render arguments after `--` are not valid `radcache render` options: {}",
                first.trim().trim_start_matches("error: ")
            )
        }
    }
}

pub fn run(args: &FarmArgs) -> Result<ExitCode> {
    let layout = Layout::new(args)?;
    if args.summarize {
        return summary::run(&layout);
    }
    let render = render_args(&layout, &args.render)?;
    let opts = LoadOptions {
        camera_name: render.camera.clone(),
        env: render.env.to_override()?,
    };
    let (scene, _warnings) = Scene::load(&layout.scene, &opts)?;
    let plan = scene.plan();
    let keeps_cache = render.method == Method::Ic && !render.no_temporal;
    let moving = plan.animation.kind != AnimationKind::None;
    let prepass = match args.prepass_every {
        None => None,
        Some(0) => bail!("--prepass-every must be at least 1"),
        Some(_) if render.method != Method::Ic => bail!("--prepass-every needs --method ic"),
        Some(_) if !plan.keeps_records() => bail!(
            "--prepass-every: the scene '{}' has moving geometry or lights (plan: {:?}); a \
             prepass cache applies only where they are static",
            layout.scene.display(),
            plan.animation.kind
        ),
        Some(n) => {
            // The prepass job runs `radcache cache build` with the same options as the chunks:
            // refuse now what it would refuse on the cluster.
            let mut line = vec![
                layout.scene.display().to_string(),
                "-o".into(),
                layout.cache_file().display().to_string(),
                "--every".into(),
                n.to_string(),
            ];
            line.extend(args.render.iter().cloned());
            crate::cache::check_build_line(&line).with_context(|| {
                "--prepass-every: the render arguments after `--` are not all valid \
                 `radcache cache build` options (the prepass job takes the same options)"
                    .to_string()
            })?;
            Some(n)
        }
    };
    // With a prepass every chunk starts from the same records (the scene's geometry is static),
    // so a warm-up would only repeat work.
    let warm_up = match args.warm_up {
        Some(k) => k,
        None if moving && keeps_cache && prepass.is_none() => DEFAULT_WARM_UP,
        None => 0,
    };
    let missing = layout.missing()?;
    let mut chunks: Vec<u32> = missing.iter().map(|&f| layout.chunk_of(f)).collect();
    chunks.dedup();
    let binary = std::env::current_exe().context("finding the radcache binary")?;
    let jobs = script::Jobs {
        layout: &layout,
        binary: &binary,
        render: &args.render,
        warm_up,
        partition: args.partition.as_deref(),
        cpus_per_task: args.cpus_per_task,
        prepass_every: prepass.filter(|_| !layout.cache_file().exists()),
        cache_in: prepass.is_some(),
        retries: args.retries,
    };
    let total = layout.last - layout.first + 1;
    println!(
        "{} frames {}..{} in {} chunks of {}; warm-up {warm_up} frames per chunk (plan: {:?})",
        total,
        layout.first,
        layout.last,
        layout.chunks(),
        layout.chunk,
        plan.animation.kind
    );
    if chunks.is_empty() {
        println!("every frame is on disk: nothing to submit");
        return Ok(ExitCode::SUCCESS);
    }
    let mut array = array_list(&chunks);
    if let Some(n) = args.max_running {
        array.push_str(&format!("%{n}"));
    }
    println!(
        "missing: {} frames ({}); chunks to render: {array}",
        missing.len(),
        array_list(&missing)
    );
    let scripts = jobs.scripts();
    if args.dry_run {
        for (name, text) in &scripts {
            println!("==> {} <==\n{text}", layout.dir.join(name).display());
        }
        for line in submit_lines(&layout, &scripts, &array) {
            println!("{line}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    std::fs::create_dir_all(layout.log_dir())
        .with_context(|| format!("creating the farm folder {}", layout.log_dir().display()))?;
    for (name, text) in &scripts {
        crate::output::write_text(&layout.dir.join(name), text, "job script")?;
    }
    let mut after = None;
    if scripts.iter().any(|(n, _)| *n == "prepass.sh") {
        let id = sbatch(&[], &layout.dir.join("prepass.sh"))?;
        println!("prepass: job {id}");
        after = Some(format!("--dependency=afterok:{id}"));
    }
    let mut options = vec![format!("--array={array}")];
    options.extend(after);
    let id = sbatch(&options, &layout.dir.join("chunks.sh"))?;
    println!("chunks: job {id} (array {array})");
    let final_id = sbatch(
        &[format!("--dependency=afterany:{id}")],
        &layout.dir.join("final.sh"),
    )?;
    println!("final: job {final_id}");
    println!(
        "logs: {}; summary: {}",
        layout.log_dir().display(),
        layout.dir.join("summary.md").display()
    );
    Ok(ExitCode::SUCCESS)
}

/// The sbatch commands `--dry-run` shows (job ids as `$PREPASS` and `$CHUNKS`).
fn submit_lines(layout: &Layout, scripts: &[(&str, String)], array: &str) -> Vec<String> {
    let path = |n: &str| script::quote(&layout.dir.join(n).display().to_string());
    let mut lines = Vec::new();
    let mut dependency = String::new();
    if scripts.iter().any(|(n, _)| *n == "prepass.sh") {
        lines.push(format!(
            "PREPASS=$(sbatch --parsable {})",
            path("prepass.sh")
        ));
        dependency = " --dependency=afterok:$PREPASS".into();
    }
    lines.push(format!(
        "CHUNKS=$(sbatch --parsable --array={array}{dependency} {})",
        path("chunks.sh")
    ));
    lines.push(format!(
        "sbatch --parsable --dependency=afterany:$CHUNKS {}",
        path("final.sh")
    ));
    lines
}

/// Submits `script` with `sbatch --parsable` and returns the job id.
fn sbatch(options: &[String], script: &Path) -> Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(options)
        .arg(script)
        .output()
        .context("running sbatch (is Slurm installed? scripts/slurm-local.sh start sets up a one-node cluster)")?;
    if !out.status.success() {
        bail!(
            "sbatch {} failed ({}): {}",
            script.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    // `--parsable` prints `jobid` or `jobid;cluster`.
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        bail!("sbatch {} printed no job id: {text:?}", script.display());
    }
    Ok(id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_lists_join_runs() {
        assert_eq!(array_list(&[1, 2, 3, 5]), "1-3,5");
        assert_eq!(array_list(&[2]), "2");
        assert_eq!(array_list(&[1, 3, 4, 6, 7, 8]), "1,3-4,6-8");
    }

    #[test]
    fn chunks_cover_the_range() {
        let layout = Layout {
            scene: "/s.gltf".into(),
            pattern: "/o/f_####.exr".into(),
            first: 5,
            last: 54,
            chunk: 12,
            dir: "/o/.farm".into(),
        };
        assert_eq!(layout.chunks(), 5);
        assert_eq!(layout.chunk_frames(1), (5, 16));
        assert_eq!(layout.chunk_frames(5), (53, 54));
        assert_eq!(layout.chunk_of(16), 1);
        assert_eq!(layout.chunk_of(17), 2);
        assert_eq!(layout.chunk_of(54), 5);
    }
}
