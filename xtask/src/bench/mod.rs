//! `cargo xtask bench <what>`: benchmarks whose figures go to `bench/results.csv`.
//!
//! Each one runs in the shared harness ([`harness::Bench`]): the device (validation off unless
//! `RADCACHE_VALIDATION` is set; `RADCACHE_DEVICE` picks it), the warm-up, the CSV rows and the
//! leak check at the end.

mod harness;
mod ic;
mod peer;
mod pt;
mod rays;
mod scale;
mod scaling;
mod scene_rays;
mod temporal;
mod tessellate;

use anyhow::{bail, Result};

pub fn run(args: &[&str]) -> Result<()> {
    match args {
        ["rays", rest @ ..] => rays::run(rest),
        ["pt", rest @ ..] => pt::run(rest),
        ["ic", rest @ ..] => ic::run(rest),
        ["scaling", rest @ ..] => scaling::run(rest),
        ["scale", rest @ ..] => scale::run(rest),
        ["temporal", rest @ ..] => temporal::run(rest),
        ["peer", rest @ ..] => peer::run(rest),
        _ => bail!(
            "usage: cargo xtask bench rays [--rays N] | pt [--spp N] | ic [--scene cornell|courtyard] \
             | scaling [--scene cornell|courtyard] [--preset draft|default|high] [--max-size N] \
             | scale [--size S] [--max-unique N] [--grid G] \
             | temporal [--frames N] [--size S] [--preset P] [--reference-frames K] \
             [--reference-spp SPP] [--temporal-accuracy A] [--max-age F] [--dump DIR] \
             | peer [--scenes a,b,..] [--reference-spp N] [--height H] [--radcache-ref SCENE=FILE.exr]"
        ),
    }
}
