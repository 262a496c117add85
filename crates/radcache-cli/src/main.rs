//! `radcache`: render glTF scenes with global illumination, inspect them, compare images.

mod compare;
mod convergence;
mod flicker;
mod frame;
mod ic_args;
mod info;
mod output;
mod profile;
mod progress;
mod render;
mod sequence;

use std::path::PathBuf;
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
    Render(Box<render::RenderArgs>),
    /// Print a scene's summary and the plan of what its frames need.
    Info(info::InfoArgs),
    /// Compare a candidate image against a reference (RMSE, relMSE, MAE, block RMSE, FLIP, ...).
    Compare(compare::CompareArgs),
    /// Measure the flicker of an EXR sequence, against a reference sequence or over static pixels.
    Flicker(flicker::FlickerArgs),
    /// Error against run time of the cache and the path tracer on one frame: CSV, log–log plot,
    /// Markdown summary with the Pareto front and the speed-ups.
    Convergence(convergence::ConvergenceArgs),
}

/// Where the GLSL sources live: `RADCACHE_SHADERS`, else the source tree this binary was built
/// from.
pub(crate) fn shader_root() -> PathBuf {
    std::env::var_os("RADCACHE_SHADERS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shaders")))
}

/// Writes `text` to stdout; a closed pipe (`radcache info x | head`) is not an error.
pub(crate) fn emit(text: &str) -> std::io::Result<()> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Flicker(args) => flicker::run(&args),
        Command::Convergence(args) => convergence::run(&args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
