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
    about = "Irradiance-caching renderer for glTF scenes"
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

fn main() -> ExitCode {
    progress::init_logger();
    let cli = Cli::parse();
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
