//! `cargo xtask bench pt`: the reference path tracer on the bundled Cornell box at 256² and 512²:
//! samples per second (pixel samples), ray queries per second, and the share of the raw ray-query
//! rate (`bench rays`, incoherent case, measured by this run on the same device) it reaches.

use anyhow::{Context as _, Result};
use radcache_render::{render_path, Budget, GpuScene, PathSettings, Track};
use radcache_scene::{LoadOptions, Scene};

use super::harness::{Bench, Figure};

pub fn run(args: &[&str]) -> Result<()> {
    let spp: u32 = match args {
        [] => 16,
        ["--spp", n] => n.parse().context("--spp N")?,
        _ => anyhow::bail!("usage: cargo xtask bench pt [--spp N]"),
    };
    let path = crate::root().join("assets/cornell/cornell.gltf");
    let (scene, _) = Scene::load(&path, &LoadOptions::default())?;
    let bench = Bench::new("pt")?;
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    let raw = super::rays::incoherent_rate(ctx, shaders)?;
    println!("device: {}", bench.device());
    println!("raw incoherent ray-query rate: {:.2} Mrays/s", raw / 1e6);
    let mut figures = vec![Figure::new("raw_incoherent", "rays_per_s", raw, "rays/s")];
    let mut gpu = GpuScene::new(ctx, &scene, None)?;
    bench.warm_up_path(&scene, &mut gpu)?;
    println!(
        "{:>6} {:>5} {:>9} {:>12} {:>10} {:>9}",
        "size", "spp", "time s", "Msamples/s", "Mrays/s", "of raw"
    );
    for size in [256u32, 512] {
        let settings = PathSettings {
            width: size,
            height: size,
            budget: Budget::Samples(spp),
            ..PathSettings::default()
        };
        let out = render_path(ctx, shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
        // The host's wall time of the sampling submissions: lavapipe's timestamps do not bracket
        // compute work reliably (they gave rates several times the raw ray rate).
        let gpu_s: f64 = out
            .spans
            .iter()
            .filter(|s| s.track == Track::Cpu && s.name == "path_trace")
            .map(|s| s.duration_s)
            .sum();
        let samples = f64::from(size) * f64::from(size) * f64::from(out.spp);
        let rays: u64 = out.rays.values().sum();
        let sps = samples / gpu_s.max(1e-9);
        let rps = rays as f64 / gpu_s.max(1e-9);
        println!(
            "{:>6} {:>5} {:>9.2} {:>12.3} {:>10.2} {:>8.0}%",
            format!("{size}²"),
            out.spp,
            out.time_s,
            sps / 1e6,
            rps / 1e6,
            100.0 * rps / raw
        );
        let case = format!("cornell_{size}");
        figures.push(Figure::new(&case, "samples_per_s", sps, "samples/s"));
        figures.push(Figure::new(&case, "rays_per_s", rps, "rays/s"));
        figures.push(Figure::new(
            &case,
            "rays_per_sample",
            rays as f64 / samples,
            "rays",
        ));
        figures.push(Figure::new(&case, "share_of_raw", rps / raw, "ratio"));
    }
    drop(gpu);
    bench.finish(&figures)
}
