//! `radcache`: render glTF scenes with global illumination, inspect them, compare images.
//!
//! Modules depend only downward, in this order (each uses only modules below it):
//!
//! | layer | modules |
//! |---|---|
//! | commands | `render`, `info`, `compare`, `flicker`, `convergence` (with its `ladder`, `model`, `plot`, `report`), `farm` (with its `script`, `summary`), `cache` |
//! | a frame of `render` | `frame` |
//! | helpers | `sequence` (frames, contact sheet, per-frame lines), `profile` (trace, pass table), `cache_io` (`render --cache-in/--cache-out`) |
//! | leaves | `args` (clap types of `render`, `args::ic` the cache's), `progress` (bars), `output` (stdout, files) |
//!
//! This root only parses the command line, sets up the logger and prints a failed command's
//! error, each cause once.

mod args;
mod cache;
mod cache_io;
mod compare;
mod convergence;
mod farm;
mod flicker;
mod frame;
mod info;
mod output;
mod profile;
mod progress;
mod render;
mod sequence;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(
    name = "radcache",
    version,
    about = "Irradiance-caching renderer for glTF scenes",
    args_override_self = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene to an EXR (and optionally a PNG preview).
    Render(Box<args::RenderArgs>),
    /// Print a scene's summary and the plan of what its frames need.
    Info(info::InfoArgs),
    /// Compare a candidate image against a reference (RMSE, relMSE, MAE, block RMSE, FLIP, ...).
    Compare(compare::CompareArgs),
    /// Measure the flicker of an EXR sequence, against a reference sequence or over static pixels.
    Flicker(flicker::FlickerArgs),
    /// Error against run time of the cache and the path tracer on one frame: CSV, log–log plot,
    /// Markdown summary with the Pareto front and the speed-ups.
    Convergence(convergence::ConvergenceArgs),
    /// Render a sequence on a Slurm cluster: an array job of chunks, a prepass where asked and a
    /// final job (contact sheet, flicker, summary); `--dry-run` prints the job scripts.
    Farm(Box<farm::FarmArgs>),
    /// Cache files: `info FILE` prints the header; `build SCENE` computes the records over a
    /// static scene's camera path (prepass) for `render --cache-in`.
    Cache(cache::CacheArgs),
}

/// The error's chain as one line, `outer: cause: cause`, each cause once: a cause whose message
/// the text already holds (an error that prints its source and also returns it from
/// `Error::source`) is not repeated.
fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let message = cause.to_string();
        if text.is_empty() {
            text = message;
        } else if !text.contains(&message) {
            text.push_str(": ");
            text.push_str(&message);
        }
    }
    text
}

/// The command line with `render --config-from F.exr` replaced by the configuration stored in
/// `F.exr` followed by the rest of the arguments (so that they override it); an error for a
/// removed technique flag ([`args::ic::removed_flag`]).
fn expand_args(args: Vec<String>) -> anyhow::Result<Vec<String>> {
    if let Some(message) = args::ic::removed_flag(&args) {
        anyhow::bail!(message);
    }
    let Some(i) = args
        .iter()
        .position(|a| a == "--config-from" || a.starts_with("--config-from="))
    else {
        return Ok(args);
    };
    let (path, end) = match args[i].split_once('=') {
        Some((_, p)) => (p.to_string(), i + 1),
        None => match args.get(i + 1) {
            Some(p) => (p.clone(), i + 2),
            None => anyhow::bail!("--config-from needs an EXR file"),
        },
    };
    let config = read_config(std::path::Path::new(&path))?;
    let Some(render) = args.iter().position(|a| a == "render") else {
        anyhow::bail!("--config-from is an option of `radcache render`");
    };
    let mut out: Vec<String> = args[..=render].to_vec();
    out.extend(config.split_whitespace().map(str::to_string));
    out.extend(args[render + 1..i].iter().cloned());
    out.extend(args[end..].iter().cloned());
    Ok(out)
}

/// The configuration stored in an EXR rendered by radcache.
fn read_config(path: &std::path::Path) -> anyhow::Result<String> {
    use anyhow::Context as _;
    let (_, meta) = radcache_image::read_exr(path)
        .with_context(|| format!("--config-from {}", path.display()))?;
    meta.extra.get(frame::CONFIG_KEY).cloned().with_context(|| {
        format!(
            "--config-from {}: the file holds no radcache configuration (radcache.extra.{}): \
             not rendered by this version of radcache",
            path.display(),
            frame::CONFIG_KEY
        )
    })
}

fn main() -> ExitCode {
    progress::init_logger();
    let argv = match expand_args(std::env::args().collect()) {
        Ok(argv) => argv,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            return ExitCode::FAILURE;
        }
    };
    let cli = Cli::parse_from(argv);
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Flicker(args) => flicker::run(&args),
        Command::Convergence(args) => convergence::run(&args),
        Command::Farm(args) => farm::run(&args),
        Command::Cache(args) => cache::run(&args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An error that prints its source and also returns it, as `#[error("…: {source}")]` does.
    #[derive(Debug)]
    struct Repeats(std::io::Error);

    impl std::fmt::Display for Repeats {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "cannot read 'a.gltf': {}", self.0)
        }
    }

    impl std::error::Error for Repeats {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn each_cause_of_an_error_is_printed_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::new(Repeats(io)).context("loading the scene");
        assert_eq!(
            error_text(&e),
            "loading the scene: cannot read 'a.gltf': no such file"
        );
        // A cause that its wrapper does not print is still shown.
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::new(io).context("reading 'b.exr'");
        assert_eq!(error_text(&e), "reading 'b.exr': no such file");
    }
}
