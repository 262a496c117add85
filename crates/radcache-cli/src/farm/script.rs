//! The job scripts of `radcache farm`: bash with `#SBATCH` headers, every path absolute and
//! quoted, so a task runs the same on any node that mounts the same file system.
//!
//! Each chunk task prints a start line and an end line into its log (`logs/chunk_<i>.out`,
//! appended across runs), which the final job's summary reads:
//!
//! ```text
//! radcache-farm: chunk 3 frames 49..72 started on node7 at 2026-12-01T21:00:00Z
//! radcache-farm: chunk 3 frames 49..72 exit 0 seconds 61.4
//! ```
//!
//! A render killed by a signal (exit status 128 + n: an abort, a segmentation fault, the
//! kernel's out-of-memory killer) is run again, at most [`Jobs::retries`] times; each such
//! attempt leaves a line before the end line, and the run again keeps the frames the killed one
//! wrote (it renders the others, with their warm-up frames):
//!
//! ```text
//! radcache-farm: chunk 3 frames 49..72 attempt 1 exit 134 (signal 6); running it again
//! ```
//!
//! Other failures (exit 1: an error the render named) are not retried: they would fail again.

use std::path::Path;

use super::Layout;

/// What the scripts are made from.
#[derive(Debug)]
pub struct Jobs<'a> {
    pub layout: &'a Layout,
    /// The `radcache` binary, absolute.
    pub binary: &'a Path,
    /// Options passed to every `radcache render` (and to the prepass).
    pub render: &'a [String],
    pub warm_up: u32,
    pub partition: Option<&'a str>,
    pub cpus_per_task: Option<u32>,
    /// Write `prepass.sh` over every N-th frame (the cache file is not on disk yet).
    pub prepass_every: Option<u32>,
    /// The chunks read the prepass's cache file.
    pub cache_in: bool,
    /// Runs again of a chunk's render that a signal killed.
    pub retries: u32,
}

/// `text` as one single-quoted shell word.
pub fn quote(text: &str) -> String {
    if !text.is_empty()
        && text
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_./=:,+%@".contains(&b))
    {
        return text.to_string();
    }
    format!("'{}'", text.replace('\'', r"'\''"))
}

fn quote_path(path: &Path) -> String {
    quote(&path.display().to_string())
}

impl Jobs<'_> {
    /// The scripts by file name: `prepass.sh` where it applies, `chunks.sh`, `final.sh`.
    pub fn scripts(&self) -> Vec<(&'static str, String)> {
        let mut scripts = Vec::new();
        if let Some(every) = self.prepass_every {
            scripts.push(("prepass.sh", self.prepass(every)));
        }
        scripts.push(("chunks.sh", self.chunks()));
        scripts.push(("final.sh", self.final_job()));
        scripts
    }

    fn header(&self, name: &str, log: &str) -> String {
        let mut text = format!(
            "#!/bin/bash\n#SBATCH --job-name={name}\n#SBATCH --output={}\n#SBATCH --open-mode=append\n",
            quote_path(&self.layout.log_dir().join(log))
        );
        if let Some(p) = self.partition {
            text.push_str(&format!("#SBATCH --partition={}\n", quote(p)));
        }
        if let Some(n) = self.cpus_per_task {
            text.push_str(&format!("#SBATCH --cpus-per-task={n}\n"));
        }
        text.push_str("# Written by radcache farm (docs/farm.md); paths are absolute.\nset -u\n");
        text
    }

    fn render_options(&self) -> String {
        self.render
            .iter()
            .map(|a| format!(" {}", quote(a)))
            .collect()
    }

    fn prepass(&self, every: u32) -> String {
        let l = self.layout;
        let mut text = self.header("radcache-prepass", "prepass.out");
        text.push_str(&format!(
            "echo \"radcache-farm: prepass started on $(hostname) at $(date -u +%FT%TZ)\"\n\
             {} cache build {} --frames {}..{} --every {every} -o {}{}\n\
             rc=$?\necho \"radcache-farm: prepass exit $rc\"\nexit $rc\n",
            quote_path(self.binary),
            quote_path(&l.scene),
            l.first,
            l.last,
            quote_path(&l.cache_file()),
            self.render_options()
        ));
        text
    }

    fn chunks(&self) -> String {
        let l = self.layout;
        let mut text = self.header("radcache-chunks", "chunk_%a.out");
        let cache = if self.cache_in {
            format!(" --cache-in {}", quote_path(&l.cache_file()))
        } else {
            String::new()
        };
        text.push_str(&format!(
            "# Task i renders chunk i: frames FIRST + (i-1)*CHUNK .. (the chunk's last), after\n\
             # WARM_UP frames it does not write; frames already on disk are kept.\n\
             FIRST={first} LAST={last} CHUNK={chunk} WARM_UP={warm} RETRIES={retries}\n\
             task=${{SLURM_ARRAY_TASK_ID:?run this script as a Slurm array task}}\n\
             a=$((FIRST + (task - 1) * CHUNK))\n\
             b=$((a + CHUNK - 1))\n\
             if ((b > LAST)); then b=$LAST; fi\n\
             echo \"radcache-farm: chunk $task frames $a..$b started on $(hostname) at $(date -u +%FT%TZ)\"\n\
             start=$(date +%s.%N)\n\
             # A render killed by a signal runs again (frames it wrote are kept); errors do not.\n\
             attempt=1\n\
             while :; do\n\
             \x20   {bin} render {scene} -o {pattern} --frames \"$a..$b\" --start-frame $FIRST --warm-up $WARM_UP{cache}{opts}\n\
             \x20   rc=$?\n\
             \x20   if ((rc < 128 || attempt > RETRIES)); then break; fi\n\
             \x20   echo \"radcache-farm: chunk $task frames $a..$b attempt $attempt exit $rc (signal $((rc - 128))); running it again\"\n\
             \x20   attempt=$((attempt + 1))\n\
             done\n\
             seconds=$(awk -v s=\"$start\" -v e=\"$(date +%s.%N)\" 'BEGIN {{ printf \"%.1f\", e - s }}')\n\
             echo \"radcache-farm: chunk $task frames $a..$b exit $rc seconds $seconds\"\n\
             exit $rc\n",
            first = l.first,
            last = l.last,
            chunk = l.chunk,
            warm = self.warm_up,
            retries = self.retries,
            bin = quote_path(self.binary),
            scene = quote_path(&l.scene),
            pattern = quote_path(&l.pattern),
            opts = self.render_options(),
        ));
        text
    }

    fn final_job(&self) -> String {
        let l = self.layout;
        let mut text = self.header("radcache-final", "final.out");
        let flicker = l.flicker_json();
        let partial = flicker.with_extension("json.part");
        text.push_str(&format!(
            "# After every chunk task, failed ones included: flicker, contact sheet, summary.\n\
             if {bin} flicker {pattern} --json > {partial}; then\n\
             \x20   mv {partial} {flicker}\n\
             else\n\
             \x20   rm -f {partial} {flicker}\n\
             \x20   echo \"radcache-farm: flicker failed (see above)\"\n\
             fi\n\
             exec {bin} farm {scene} -o {pattern} --frames {first}..{last} --chunk {chunk} --farm-dir {dir} --summarize\n",
            bin = quote_path(self.binary),
            pattern = quote_path(&l.pattern),
            partial = quote_path(&partial),
            flicker = quote_path(&flicker),
            scene = quote_path(&l.scene),
            first = l.first,
            last = l.last,
            chunk = l.chunk,
            dir = quote_path(&l.dir),
        ));
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_quoted_for_the_shell() {
        assert_eq!(quote("/a/f_####.exr"), "'/a/f_####.exr'");
        assert_eq!(quote("--quality"), "--quality");
        assert_eq!(quote("64x48"), "64x48");
        assert_eq!(quote("it's"), r"'it'\''s'");
        assert_eq!(quote(""), "''");
        assert_eq!(quote("a b"), "'a b'");
    }

    /// Runs chunk 1 of `chunks.sh` (without Slurm) with a fake `radcache` that runs `body`
    /// (bash; `$count` is how many times it ran before) and `retries`; returns the exit status,
    /// the task's output and how often the fake ran.
    fn run_chunk(name: &str, body: &str, retries: u32) -> (i32, String, u32) {
        let dir =
            std::env::temp_dir().join(format!("radcache-script-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let fake = dir.join("radcache");
        let counter = dir.join("count");
        std::fs::write(
            &fake,
            format!(
                "#!/bin/bash\nulimit -c 0\ncount=$(cat {c} 2>/dev/null || echo 0)\n\
                 echo $((count + 1)) > {c}\n{body}\n",
                c = quote_path(&counter)
            ),
        )
        .unwrap();
        std::process::Command::new("chmod")
            .arg("+x")
            .arg(&fake)
            .status()
            .unwrap();
        let layout = Layout {
            scene: dir.join("s.gltf"),
            pattern: dir.join("f_####.exr"),
            first: 1,
            last: 4,
            chunk: 2,
            dir: dir.join(".farm"),
        };
        let jobs = Jobs {
            layout: &layout,
            binary: &fake,
            render: &[],
            warm_up: 0,
            partition: None,
            cpus_per_task: None,
            prepass_every: None,
            cache_in: false,
            retries,
        };
        let script = dir.join("chunks.sh");
        std::fs::write(&script, jobs.chunks()).unwrap();
        // One stream, as Slurm's log file gets it.
        let out = std::process::Command::new("bash")
            .arg("-c")
            .arg(format!("exec bash {} 2>&1", quote_path(&script)))
            .env("SLURM_ARRAY_TASK_ID", "1")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let runs = std::fs::read_to_string(&counter)
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        (out.status.code().unwrap(), text, runs)
    }

    #[test]
    fn a_render_killed_by_a_signal_runs_again_and_an_error_does_not() {
        let abort_once = "echo 'frame 1: 0.5 s [1/2 done, 0 skipped] ETA 1 s'\n\
                          if ((count == 0)); then echo 'heap corrupted' >&2; kill -ABRT $$; fi\n\
                          echo 'frame 2: 0.5 s [1/2 done, 1 skipped] ETA 0 s'";
        let (rc, text, runs) = run_chunk("once", abort_once, 1);
        assert_eq!((rc, runs), (0, 2), "{text}");
        assert!(
            text.contains("radcache-farm: chunk 1 frames 1..2 attempt 1 exit 134 (signal 6); running it again"),
            "{text}"
        );
        // The summary reads the attempt from the log (stderr lands there too under Slurm).
        let run = super::super::summary::parse_log(&text, 1);
        assert_eq!(run.end.map(|e| e.0), Some(0));
        assert_eq!(run.killed.len(), 1, "{text}");
        assert_eq!(run.killed[0].exit, 134);
        assert_eq!(run.killed[0].after_frame, Some(1));
        assert_eq!(run.killed[0].last_words.as_deref(), Some("heap corrupted"));

        let (rc, text, runs) = run_chunk("always", "kill -SEGV $$", 2);
        assert_eq!((rc, runs), (139, 3), "retries are bounded:\n{text}");
        let (rc, text, runs) = run_chunk("error", "echo 'error: bad scene' >&2; exit 1", 3);
        assert_eq!((rc, runs), (1, 1), "an error is not retried:\n{text}");
        let (rc, _, runs) = run_chunk("none", "kill -ABRT $$", 0);
        assert_eq!((rc, runs), (134, 1), "--retries 0 runs once");
    }
}
