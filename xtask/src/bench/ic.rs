//! `cargo xtask bench ic`: the irradiance cache on the Cornell box against the path tracer.
//!
//! At 256² (where `tests/refs/cornell_256.exr` is the reference): the IC frame's time, records
//! and rays and its relMSE; the path tracer's relMSE at 4, 16 and 64 spp and its time per spp; the
//! path tracer's time to reach the IC's relMSE, from relMSE ∝ 1/spp fitted to the measured points
//! (an unbiased estimator's MSE falls as 1/N); and their ratio. At 512² (no reference): the IC
//! frame's time, records and rays. The record pass's ray rate is its rays over the wall time of
//! the hole-filling submissions (lavapipe's timestamps do not bracket asynchronous compute work),
//! set against the raw incoherent rate of `bench rays` measured in the same run.

use anyhow::Result;
use radcache_cache::IcParams;
use radcache_image::{compare, read_exr, Image};
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcSettings, PathSettings};
use radcache_scene::{LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};

use crate::results::{append, Figure};

pub fn run(args: &[&str]) -> Result<()> {
    anyhow::ensure!(args.is_empty(), "usage: cargo xtask bench ic");
    let root = crate::root();
    let (scene, _) = Scene::load(
        &root.join("assets/cornell/cornell.gltf"),
        &LoadOptions::default(),
    )?;
    let (reference, _) = read_exr(root.join("tests/refs/cornell_256.exr"))?;
    let ctx = Context::new()?;
    let device = ctx.info().name.clone();
    let shaders = ShaderCompiler::new(root.join("shaders"))?;
    let raw = super::rays::incoherent_rate(&ctx, &shaders)?;
    let mut gpu = GpuScene::new(&ctx, &scene, None)?;
    let mut figures = vec![Figure::new("raw_incoherent", "rays_per_s", raw, "rays/s")];
    println!(
        "device: {device}; raw incoherent rate {:.2} Mrays/s",
        raw / 1e6
    );

    // Warm-up (shader compilation is not part of the figures).
    let warm = IcSettings {
        width: 16,
        height: 16,
        params: IcParams::draft(),
        sub_frames: 1,
        ..IcSettings::default()
    };
    render_ic(&ctx, &shaders, &scene, &mut gpu, &warm, &mut |_| {})?;
    render_path(
        &ctx,
        &shaders,
        &scene,
        &mut gpu,
        &PathSettings {
            width: 16,
            height: 16,
            budget: Budget::Samples(1),
            ..PathSettings::default()
        },
        &mut |_| {},
    )?;

    let mut ic_relmse = 0.0;
    let mut ic_time = 0.0;
    for size in [256u32, 512] {
        let settings = IcSettings {
            width: size,
            height: size,
            ..IcSettings::default()
        };
        let (out, stats) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
        let record_rays = out.rays.get("records").copied().unwrap_or(0) as f64;
        let level_s = stats.hole_filling_s;
        let rays: u64 = out.rays.values().sum();
        let case = format!("cornell_{size}");
        println!(
            "IC {size}²: {:.2} s, {} records {:?}, {:.1} M rays ({:.1} M in records)",
            out.time_s,
            stats.records,
            stats.records_per_level,
            rays as f64 / 1e6,
            record_rays / 1e6
        );
        figures.push(Figure::new(&case, "ic_time_s", out.time_s, "s"));
        figures.push(Figure::new(
            &case,
            "ic_records",
            stats.records as f64,
            "records",
        ));
        figures.push(Figure::new(&case, "ic_rays", rays as f64, "rays"));
        if level_s > 0.0 {
            let rate = record_rays / level_s;
            println!(
                "  record pass: {:.2} Mrays/s over the hole-filling wall time = {:.0}% of raw",
                rate / 1e6,
                100.0 * rate / raw
            );
            figures.push(Figure::new(&case, "record_rays_per_s", rate, "rays/s"));
            figures.push(Figure::new(
                &case,
                "record_share_of_raw",
                rate / raw,
                "ratio",
            ));
        }
        if size == reference.width() {
            let image = Image::from_pixels(out.width, out.height, out.pixels)?;
            let m = compare(&reference, &image)?;
            println!(
                "  vs reference: relMSE {:.3e}, block RMSE {:.3e}",
                m.relmse, m.block_rmse
            );
            figures.push(Figure::new(&case, "ic_relmse", m.relmse, "relMSE"));
            figures.push(Figure::new(&case, "ic_block_rmse", m.block_rmse, "rmse"));
            ic_relmse = m.relmse;
            ic_time = out.time_s;
        }
    }

    // The path tracer at growing spp against the same reference.
    let mut fit = Vec::new();
    let mut per_spp_s = Vec::new();
    for spp in [4u32, 16, 64] {
        let settings = PathSettings {
            width: reference.width(),
            height: reference.height(),
            budget: Budget::Samples(spp),
            seed: 777,
            ..PathSettings::default()
        };
        let out = render_path(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
        let image = Image::from_pixels(out.width, out.height, out.pixels)?;
        let m = compare(&reference, &image)?;
        println!(
            "PT {spp:>3} spp: {:.2} s, relMSE {:.3e}",
            out.time_s, m.relmse
        );
        figures.push(Figure::new(
            format!("cornell_256_pt{spp}"),
            "time_s",
            out.time_s,
            "s",
        ));
        figures.push(Figure::new(
            format!("cornell_256_pt{spp}"),
            "relmse",
            m.relmse,
            "relMSE",
        ));
        fit.push(m.relmse * f64::from(spp));
        per_spp_s.push(out.time_s / f64::from(spp));
    }
    fit.sort_by(f64::total_cmp);
    per_spp_s.sort_by(f64::total_cmp);
    let (c, t1) = (fit[1], per_spp_s[1]);
    if ic_relmse > 0.0 {
        let spp_needed = c / ic_relmse;
        let pt_time = spp_needed * t1;
        println!(
            "PT needs ~{spp_needed:.0} spp = {pt_time:.0} s to reach relMSE {ic_relmse:.2e}; IC took {ic_time:.1} s: {:.1}× faster",
            pt_time / ic_time
        );
        figures.push(Figure::new(
            "cornell_256",
            "pt_spp_to_match",
            spp_needed,
            "spp",
        ));
        figures.push(Figure::new(
            "cornell_256",
            "pt_time_to_match_s",
            pt_time,
            "s",
        ));
        figures.push(Figure::new(
            "cornell_256",
            "speedup",
            pt_time / ic_time,
            "ratio",
        ));
    }
    drop(gpu);
    append("ic", &device, &figures)?;
    let report = ctx.shutdown();
    anyhow::ensure!(report.leaked.is_empty(), "leaked: {:?}", report.leaked);
    Ok(())
}
