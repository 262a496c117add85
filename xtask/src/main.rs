//! radcache's project tasks: `cargo xtask <task>`.

mod assets;
mod bench;
mod codegen;
mod gallery;
mod refs;
mod shaders;
mod stiff;
mod test;

use std::path::PathBuf;

use anyhow::{bail, Result};

const HELP: &str = "\
cargo xtask <task>

Tasks:
  test              run the whole test suite on lavapipe with validation (the README's command)
  shaders           compile every shader in shaders/ and run spirv-val on the output
  codegen [--check] write shaders/shared/*.glsl from the Rust layouts (--check: fail if stale)
  assets [--check]  write the bundled glTF scenes into assets/ (--check: fail if they differ)
  gallery [--size N] [--spp N] [--models a,b] [--out F]
                    the Khronos sample models of ../shared/models under an environment: cache
                    frame against the path tracer, tiled into docs/gallery.png
  refs              render the path-traced references of the cache tests into tests/refs/
  bench rays        raw ray-query throughput and BLAS/TLAS build times on the chosen device
  bench ic          the cache on the Cornell box: time, records, rays, error, speed-up over the path tracer
  bench pt          path tracer on the Cornell box at 256² and 512²: samples/s and rays/s
  bench scaling     the cache's frame time and records against resolution and triangle count
  bench temporal    an animation with kept records against a per-frame rebuild: rays, time, error, flicker
  stiff [--size N] [--ref-spp N] [--spp N] [--scenes a,b]
                    the stiff and extreme suite: every method on furnaces, slits, thin walls,
                    corners, extreme scales and radiance, degenerate input; writes bench/stiff.md
  help              this text

Benchmarks append their figures to bench/results.csv.
Environment: RADCACHE_DEVICE=<name substring> picks the device; VK_DRIVER_FILES as usual.
";

/// The repository root (the parent of xtask/).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(PathBuf::from)
        .unwrap_or_default()
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("info")).init();
    if let Err(e) = try_main() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn try_main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    match args.as_slice() {
        ["test", rest @ ..] => test::run(rest),
        ["shaders"] => shaders::run(),
        ["codegen", rest @ ..] => codegen::run(rest),
        ["assets", rest @ ..] => {
            assets::run(&rest.iter().map(|s| s.to_string()).collect::<Vec<_>>())
        }
        ["bench", rest @ ..] => bench::run(rest),
        ["refs", rest @ ..] => refs::run(rest),
        ["gallery", rest @ ..] => gallery::run(rest),
        ["stiff", rest @ ..] => stiff::run(rest),
        [] | ["help"] | ["--help"] | ["-h"] => {
            print!("{HELP}");
            Ok(())
        }
        other => bail!("unknown task {other:?}\n\n{HELP}"),
    }
}
