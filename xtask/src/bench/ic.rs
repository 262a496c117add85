//! `cargo xtask bench ic`: the irradiance cache on the Cornell box against the path tracer.
//!
//! At 256² (where `tests/refs/cornell_256.exr` is the reference), for each quality preset: the IC
//! frame's time (everything `render_ic` does, pipeline creation included), records and rays and
//! its relMSE; the path tracer's relMSE at 4, 16 and 64 spp and its time per spp; the
//! path tracer's time to reach the IC's relMSE, from relMSE ∝ 1/spp fitted to the measured points
//! (an unbiased estimator's MSE falls as 1/N); and their ratio. Errors are each method's own: the
//! reference's noise (the same fit at the reference's spp) is taken off the IC's measured relMSE,
//! as the path tracer's fit at low spp barely contains it. At 512² (no reference): the
//! default preset's time, records and rays. The record pass's ray rate is its rays over the wall
//! time of the record-creation submissions (lavapipe's timestamps do not bracket asynchronous
//! compute work; this time also holds the neighbour pass and the submission overhead, so the
//! share is a lower bound), set against the raw incoherent ray-query rate in the same scene (the
//! Cornell box's triangles, rays from random surface points, measured in the same run).

use anyhow::Result;
use radcache_cache::{IcParams, Preset};
use radcache_image::{compare, read_exr, Image};
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcSettings, PathSettings};
use radcache_scene::{LoadOptions, Scene};

use super::harness::{Bench, Figure};

pub fn run(args: &[&str]) -> Result<()> {
    anyhow::ensure!(args.is_empty(), "usage: cargo xtask bench ic");
    let root = crate::root();
    let (scene, _) = Scene::load(
        &root.join("assets/cornell/cornell.gltf"),
        &LoadOptions::default(),
    )?;
    let (reference, ref_meta) = read_exr(root.join("tests/refs/cornell_256.exr"))?;
    let ref_spp = ref_meta
        .spp
        .ok_or_else(|| anyhow::anyhow!("the reference's EXR does not record its spp"))?;
    let bench = Bench::new("ic")?;
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    let raw = super::scene_rays::incoherent_rate_in(ctx, shaders, &scene)?;
    let mut gpu = GpuScene::new(ctx, &scene, None)?;
    let mut figures = vec![Figure::new(
        "cornell_raw_incoherent",
        "rays_per_s",
        raw,
        "rays/s",
    )];
    println!(
        "device: {}; raw incoherent rate in the Cornell box {:.2} Mrays/s",
        bench.device(),
        raw / 1e6
    );
    let draft = IcSettings {
        params: IcParams::draft(),
        ..IcSettings::default()
    };
    bench.warm_up_ic(&scene, &mut gpu, draft)?;
    bench.warm_up_path(&scene, &mut gpu)?;

    // (size, preset): every preset at the reference's size, the default at 512².
    let cases = [
        (256u32, Preset::Draft),
        (256, Preset::Default),
        (256, Preset::High),
        (512, Preset::Default),
    ];
    let mut matched = Vec::new(); // (case, relMSE, time) of the frames with a reference
    for (size, preset) in cases {
        let settings = IcSettings {
            width: size,
            height: size,
            params: IcParams::preset(preset),
            ..IcSettings::default()
        };
        let (out, stats) = render_ic(ctx, shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
        let record_rays = stats.record_rays as f64;
        let level_s = stats.record_pass_s;
        let rays: u64 = out.rays.values().sum();
        let name = format!("{preset:?}").to_lowercase();
        let case = if preset == Preset::Default {
            format!("cornell_{size}")
        } else {
            format!("cornell_{size}_{name}")
        };
        println!(
            "IC {size}² {name}: {:.2} s, {} records {:?}, {:.1} M rays ({:.1} M in records)",
            out.time_s,
            stats.records,
            stats.records_per_level,
            rays as f64 / 1e6,
            record_rays / 1e6
        );
        let phases: Vec<String> = stats
            .phases_s
            .iter()
            .map(|(k, v)| format!("{k} {v:.2}"))
            .collect();
        println!("  phases (wall s): {}", phases.join(", "));
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
                "  record pass: {:.2} Mrays/s over its submissions' wall time = {:.0}% of raw",
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
            matched.push((case, m.relmse, out.time_s));
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
        let out = render_path(ctx, shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
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
    // The reference is itself a path-traced image with ref_spp samples: its noise adds
    // e_ref = c / ref_spp to every relMSE measured against it (independent errors add). Both
    // methods are compared on their own error, relMSE − e_ref.
    let e_ref = c / f64::from(ref_spp);
    println!(
        "PT: relMSE × spp = {c:.3e}, {t1:.3} s per spp; the {ref_spp}-spp reference's own relMSE ≈ {e_ref:.2e}"
    );
    figures.push(Figure::new(
        "cornell_256",
        "reference_relmse",
        e_ref,
        "relMSE",
    ));
    for (case, relmse, time) in matched {
        let own = relmse - e_ref;
        if own <= 0.0 {
            println!("{case}: relMSE {relmse:.2e} is within the reference's own noise");
            continue;
        }
        let spp_needed = c / own;
        let pt_time = spp_needed * t1;
        println!(
            "{case}: own relMSE {own:.2e} ({relmse:.2e} against the reference); PT needs ~{spp_needed:.0} spp = {pt_time:.1} s; IC took {time:.1} s: {:.1}× faster",
            pt_time / time
        );
        figures.push(Figure::new(&case, "ic_own_relmse", own, "relMSE"));
        figures.push(Figure::new(&case, "pt_spp_to_match", spp_needed, "spp"));
        figures.push(Figure::new(&case, "pt_time_to_match_s", pt_time, "s"));
        figures.push(Figure::new(&case, "speedup", pt_time / time, "ratio"));
    }
    drop(gpu);
    bench.finish(&figures)
}
