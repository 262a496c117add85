//! `cargo xtask bench scaling [--scene cornell|courtyard] [--preset draft|default|high]
//! [--max-size N]`: how the cache's frame scales with resolution and with triangle count, on the
//! Cornell box; with `--scene courtyard`, how it scales from 256² to 1920×1080 on the
//! Sponza-class courtyard (the default preset there, no triangle sweep), with the frame time per
//! megapixel of each size and the ratio of the 1080p one to the 256² one.
//!
//! On the Cornell box both sweeps use the **draft** preset unless `--preset` says otherwise, so
//! that the 1024² frame stays within a few minutes on lavapipe; the printed header names the
//! preset in use.
//!
//! - Resolution: the cache at 128², 256², 512² and 1024² (sizes whose larger side is above
//!   `--max-size`, default 1920, are skipped): the frame's wall time (`FrameOutput::time_s`,
//!   pipeline creation included), records, ray queries (all passes, and the record pass alone) and the wall time of
//!   the frame's main phases (`IcStats::phases_s`).
//! - Triangles: at 256² (or `--max-size` when smaller), the same scene with every triangle split
//!   into n² congruent sub-triangles (`tessellate.rs`), n = 1, 2, 4, 8, 10: 1× to 100× the
//!   triangles. Per level: triangles, the upload's wall time (`GpuScene::new`, which builds and
//!   compacts the BLASes, then the first TLAS build; the TLAS alone is also given), the frame's
//!   time, records, rays, and the relMSE of the image against the untessellated one at the same
//!   settings and seed. The surface is the same, so that relMSE must stay at noise level; the
//!   noise level is given by the untessellated scene rendered with another seed.
//!
//! Every figure goes to `bench/results.csv` (bench `scaling`): cases `cornell_res_<size>` and
//! `cornell_tess_<k>x`, suffixed `_default` or `_high` when that preset was asked for (`_draft`
//! or `_high` on the courtyard, whose cases are `courtyard_res_256` and `courtyard_res_1920x1080`).

use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use radcache_cache::{IcParams, Preset};
use radcache_image::{compare, Image};
use radcache_render::{render_ic, FrameOutput, GpuScene, IcSettings, IcStats};
use radcache_scene::{LoadOptions, Scene};
use radcache_vk::Context;

use super::harness::{Bench, Figure};
use super::tessellate::subdivide_scene;

const USAGE: &str = "usage: cargo xtask bench scaling [--scene cornell|courtyard] \
                     [--preset draft|default|high] [--max-size N]";

/// The resolutions of the first sweep on the Cornell box.
const SIZES: [(u32, u32); 4] = [(128, 128), (256, 256), (512, 512), (1024, 1024)];
/// The resolutions of the sweep on the courtyard: the benchmarks' 256² and full HD.
const COURTYARD_SIZES: [(u32, u32); 2] = [(256, 256), (1920, 1080)];
/// The subdivision levels of the second sweep (n² triangles per triangle).
const LEVELS: [u32; 5] = [1, 2, 4, 8, 10];
/// The size of the second sweep (smaller when `--max-size` is).
const TESS_SIZE: u32 = 256;

/// Phases of `IcStats::phases_s`: (key, CSV metric, column title). The table shows the first
/// five and the rest summed.
const PHASES: [(&str, &str, &str); 8] = [
    ("record_creation", "phase_record_creation_s", "create"),
    ("shade", "phase_shade_s", "shade"),
    ("hole_selection", "phase_hole_selection_s", "select"),
    ("cache_gbuffer", "phase_cache_gbuffer_s", "gbuffer"),
    ("pipelines", "phase_pipelines_s", "pipelines"),
    ("setup", "phase_setup_s", "setup"),
    ("emission", "phase_emission_s", "emission"),
    ("readback", "phase_readback_s", "readback"),
];

struct Options {
    courtyard: bool,
    preset: Option<Preset>,
    max_size: u32,
}

fn parse(args: &[&str]) -> Result<Options> {
    let mut o = Options {
        courtyard: false,
        preset: None,
        max_size: 1920,
    };
    let mut it = args.iter();
    while let Some(&arg) = it.next() {
        let mut value = || {
            it.next()
                .copied()
                .with_context(|| format!("{arg}: no value\n{USAGE}"))
        };
        match arg {
            "--scene" => {
                o.courtyard = match value()? {
                    "cornell" => false,
                    "courtyard" => true,
                    other => bail!("unknown scene {other:?}\n{USAGE}"),
                }
            }
            "--preset" => {
                o.preset = Some(match value()? {
                    "draft" => Preset::Draft,
                    "default" => Preset::Default,
                    "high" => Preset::High,
                    other => bail!("unknown preset {other:?}\n{USAGE}"),
                })
            }
            "--max-size" => {
                let v = value()?;
                o.max_size = v
                    .parse()
                    .with_context(|| format!("--max-size {v:?}\n{USAGE}"))?;
                anyhow::ensure!(o.max_size >= 16, "--max-size must be at least 16");
            }
            other => bail!("unknown argument {other:?}\n{USAGE}"),
        }
    }
    Ok(o)
}

fn preset_name(p: Preset) -> &'static str {
    match p {
        Preset::Draft => "draft",
        Preset::Default => "default",
        Preset::High => "high",
    }
}

fn settings((width, height): (u32, u32), preset: Preset, seed: u32) -> IcSettings {
    IcSettings {
        width,
        height,
        params: IcParams::preset(preset),
        seed,
        ..IcSettings::default()
    }
}

fn total_rays(out: &FrameOutput) -> u64 {
    out.rays.values().sum()
}

fn phase(stats: &IcStats, key: &str) -> f64 {
    stats.phases_s.get(key).copied().unwrap_or(0.0)
}

fn image(out: FrameOutput) -> Result<Image> {
    Ok(Image::from_pixels(out.width, out.height, out.pixels)?)
}

/// The scene uploaded with its TLAS built: (scene, wall s of everything, wall s of the TLAS).
fn upload(ctx: &Context, scene: &Scene) -> Result<(GpuScene, f64, f64)> {
    let start = Instant::now();
    let mut gpu = GpuScene::new(ctx, scene, None)?;
    let tlas_start = Instant::now();
    gpu.set_time(scene, 0.0)?;
    let mut rec = ctx.begin("scaling.tlas")?;
    gpu.record_update(ctx, &mut rec)?;
    ctx.submit(rec)?.wait()?;
    let end = Instant::now();
    Ok((
        gpu,
        (end - start).as_secs_f64(),
        (end - tlas_start).as_secs_f64(),
    ))
}

/// The name of a size in case names and tables: `256` for 256², else `1920x1080`.
fn size_name((w, h): (u32, u32)) -> String {
    if w == h {
        w.to_string()
    } else {
        format!("{w}x{h}")
    }
}

/// The resolution sweep: one frame per size on `gpu`, a table row and its figures (the case of
/// each size named by `case`), with the frame time per megapixel; returns those times.
fn resolution_sweep(
    bench: &Bench,
    scene: &Scene,
    gpu: &mut GpuScene,
    sizes: &[(u32, u32)],
    preset: Preset,
    case: &dyn Fn((u32, u32)) -> String,
    figures: &mut Vec<Figure>,
) -> Result<Vec<f64>> {
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    println!("\nresolution sweep (frame and phases: wall time, s)");
    let head: Vec<String> = PHASES[..5].iter().map(|p| format!("{:>9}", p.2)).collect();
    println!(
        "{:>9} {:>8} {:>8} {:>8} {:>9} {:>9} {} {:>9}",
        "size",
        "frame",
        "s/MP",
        "records",
        "Mrays",
        "rec Mrays",
        head.join(" "),
        "other"
    );
    let mut per_mp = Vec::new();
    for &size in sizes {
        let (out, stats) = render_ic(
            ctx,
            shaders,
            scene,
            gpu,
            &settings(size, preset, 0),
            &mut |_| {},
        )?;
        let rays = total_rays(&out);
        let s_per_mp = out.time_s / (f64::from(size.0) * f64::from(size.1) / 1e6);
        per_mp.push(s_per_mp);
        let shown: Vec<String> = PHASES[..5]
            .iter()
            .map(|p| format!("{:>9.3}", phase(&stats, p.0)))
            .collect();
        let other: f64 = PHASES[5..].iter().map(|p| phase(&stats, p.0)).sum();
        println!(
            "{:>9} {:>8.2} {:>8.1} {:>8} {:>9.2} {:>9.2} {} {:>9.3}",
            if size.0 == size.1 {
                format!("{}²", size.0)
            } else {
                size_name(size)
            },
            out.time_s,
            s_per_mp,
            stats.records,
            rays as f64 / 1e6,
            stats.record_rays as f64 / 1e6,
            shown.join(" "),
            other
        );
        let case = case(size);
        figures.push(Figure::new(&case, "frame_s", out.time_s, "s"));
        figures.push(Figure::new(
            &case,
            "frame_s_per_megapixel",
            s_per_mp,
            "s/MP",
        ));
        figures.push(Figure::new(
            &case,
            "records",
            stats.records as f64,
            "records",
        ));
        figures.push(Figure::new(&case, "rays", rays as f64, "rays"));
        figures.push(Figure::new(
            &case,
            "record_rays",
            stats.record_rays as f64,
            "rays",
        ));
        for (key, metric, _) in PHASES {
            figures.push(Figure::new(&case, metric, phase(&stats, key), "s"));
        }
    }
    Ok(per_mp)
}

pub fn run(args: &[&str]) -> Result<()> {
    let opts = parse(args)?;
    let (name, gltf, default_preset) = if opts.courtyard {
        (
            "courtyard",
            "assets/courtyard/courtyard.gltf",
            Preset::Default,
        )
    } else {
        ("cornell", "assets/cornell/cornell.gltf", Preset::Draft)
    };
    let preset = opts.preset.unwrap_or(default_preset);
    let pname = preset_name(preset);
    let suffix = if preset == default_preset {
        String::new()
    } else {
        format!("_{pname}")
    };
    let root = crate::root();
    let (scene, _) = Scene::load(&root.join(gltf), &LoadOptions::default())?;
    let bench = Bench::new("scaling")?;
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    let mut figures = Vec::new();

    // Warm-up (shader compilation is not part of the figures), on an upload of its own.
    bench.warm_up_ic(
        &scene,
        &mut upload(ctx, &scene)?.0,
        settings((16, 16), preset, 0),
    )?;

    // 1. Resolution.
    println!(
        "device: {}; {name}, {} triangles; preset `{pname}`{}",
        bench.device(),
        scene.instanced_triangle_count(),
        if preset == Preset::Draft && !opts.courtyard {
            " (the default here, so that 1024² stays within minutes on lavapipe)"
        } else {
            ""
        }
    );
    let max = opts.max_size;
    let sizes: Vec<(u32, u32)> = if opts.courtyard {
        &COURTYARD_SIZES[..]
    } else {
        &SIZES[..]
    }
    .iter()
    .copied()
    .filter(|&(w, h)| w.max(h) <= max)
    .collect();
    let case = |size| format!("{name}_res_{}{suffix}", size_name(size));
    let mut gpu = upload(ctx, &scene)?.0;
    let per_mp = resolution_sweep(
        &bench,
        &scene,
        &mut gpu,
        &sizes,
        preset,
        &case,
        &mut figures,
    )?;
    drop(gpu);
    if opts.courtyard {
        // The last size (full HD) against the first (256²), when both were rendered.
        if let ([first, .., last], [a, .., b]) = (&sizes[..], &per_mp[..]) {
            let ratio = b / a;
            println!(
                "frame time per megapixel at {} ÷ at {}: {ratio:.2}",
                size_name(*last),
                size_name(*first)
            );
            figures.push(Figure::new(
                case(*last),
                "per_megapixel_vs_256",
                ratio,
                "ratio",
            ));
        }
        return bench.finish(&figures);
    }

    // 2. Triangles.
    let size = TESS_SIZE.min(opts.max_size);
    println!(
        "\ntriangle sweep at {size}² (each triangle split into n² sub-triangles; upload = \
         GpuScene::new + first TLAS build, wall time, s; relMSE against the 1× image)"
    );
    println!(
        "{:>6} {:>10} {:>9} {:>9} {:>8} {:>8} {:>9} {:>11}",
        "level", "triangles", "upload", "TLAS", "frame", "records", "Mrays", "relMSE vs 1×"
    );
    let mut reference: Option<Image> = None;
    for n in LEVELS {
        let tess = if n == 1 {
            scene.clone()
        } else {
            subdivide_scene(&scene, n)?
        };
        let triangles = tess.instanced_triangle_count();
        let (mut gpu, upload_s, tlas_s) = upload(ctx, &tess)?;
        let (out, stats) = render_ic(
            ctx,
            shaders,
            &tess,
            &mut gpu,
            &settings((size, size), preset, 0),
            &mut |_| {},
        )?;
        let (time_s, rays) = (out.time_s, total_rays(&out));
        let img = image(out)?;
        let case = format!("cornell_tess_{}x{suffix}", n * n);
        let relmse = match &reference {
            Some(r) => Some(compare(r, &img)?.relmse),
            None => {
                // The noise level: the same scene and settings with another seed.
                let (other, _) = render_ic(
                    ctx,
                    shaders,
                    &tess,
                    &mut gpu,
                    &settings((size, size), preset, 1),
                    &mut |_| {},
                )?;
                let noise = compare(&img, &image(other)?)?.relmse;
                figures.push(Figure::new(&case, "relmse_seed_noise", noise, "relMSE"));
                reference = Some(img);
                println!(
                    "{:>6} noise level (1×, seed 1 against seed 0): relMSE {noise:.3e}",
                    ""
                );
                None
            }
        };
        println!(
            "{:>6} {:>10} {:>9.3} {:>9.4} {:>8.2} {:>8} {:>9.2} {:>11}",
            format!("{}×", n * n),
            triangles,
            upload_s,
            tlas_s,
            time_s,
            stats.records,
            rays as f64 / 1e6,
            relmse.map_or("-".to_string(), |e| format!("{e:.3e}"))
        );
        let blas = &gpu.stats().blas;
        figures.push(Figure::new(
            &case,
            "triangles",
            triangles as f64,
            "triangles",
        ));
        figures.push(Figure::new(&case, "upload_s", upload_s, "s"));
        figures.push(Figure::new(&case, "tlas_s", tlas_s, "s"));
        figures.push(Figure::new(
            &case,
            "blas_gpu_ms",
            blas.build_ms + blas.compact_ms,
            "ms",
        ));
        figures.push(Figure::new(&case, "frame_s", time_s, "s"));
        figures.push(Figure::new(
            &case,
            "records",
            stats.records as f64,
            "records",
        ));
        figures.push(Figure::new(&case, "rays", rays as f64, "rays"));
        if let Some(e) = relmse {
            figures.push(Figure::new(&case, "relmse_vs_1x", e, "relMSE"));
        }
    }

    bench.finish(&figures)
}
