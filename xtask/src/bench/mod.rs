//! `cargo xtask bench <what>`: benchmarks whose figures go to `bench/results.csv`.
//!
//! Benchmarks run with validation off (it costs CPU time per call) unless `RADCACHE_VALIDATION` is
//! set, and on the device `RADCACHE_DEVICE` names (the preferred one otherwise).

mod ic;
mod pt;
mod rays;
mod scaling;
mod scene_rays;
mod temporal;
mod tessellate;

use anyhow::{bail, Result};

pub fn run(args: &[&str]) -> Result<()> {
    if std::env::var_os("RADCACHE_VALIDATION").is_none() {
        std::env::set_var("RADCACHE_VALIDATION", "0");
    }
    match args {
        ["rays", rest @ ..] => rays::run(rest),
        ["pt", rest @ ..] => pt::run(rest),
        ["ic", rest @ ..] => ic::run(rest),
        ["scaling", rest @ ..] => scaling::run(rest),
        ["temporal", rest @ ..] => temporal::run(rest),
        _ => bail!(
            "usage: cargo xtask bench rays [--rays N] | pt [--spp N] | ic \
             | scaling [--preset draft|default|high] [--max-size N] \
             | temporal [--frames N] [--size S] [--preset P] [--reference-frames K] \
             [--reference-spp SPP]"
        ),
    }
}
