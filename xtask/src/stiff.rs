//! `cargo xtask stiff`: the stiff and extreme suite (issue 8). Every scene of
//! `radcache_scene::assets::stiff` is generated into a temporary folder, loaded (warnings
//! counted), and rendered with the cache at each preset and with the path tracer; each render is
//! compared with the scene's reference (analytic, black, or the path tracer at `--ref-spp`), and
//! the table (scene, method, relMSE, block RMSE, leak, NaN count, time) is printed and written to
//! `bench/stiff.md`. Figures are defined in `radcache_tests::stiff`.
//!
//! Options: `--size N` (square image side, default 64), `--ref-spp N` (reference spp, default
//! 1024), `--spp N` (the path tracer's row, default 64), `--scenes a,b` (a subset), `--out F`
//! (default `bench/stiff.md`); `--write DIR` only writes the scenes (`DIR/<name>.gltf`).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use radcache_cache::Preset;
use radcache_image::Image;
use radcache_render::GpuScene;
use radcache_scene::assets::stiff::{stiff_scenes, write_stiff_scene, StiffCheck, StiffScene};
use radcache_scene::{LoadOptions, Scene, WarningKind};
use radcache_tests::stiff::{closed_form_reference, figures, render, Effort, Method};
use radcache_vk::{Context, ShaderCompiler};

struct Options {
    size: u32,
    ref_spp: u32,
    spp: u32,
    scenes: Option<Vec<String>>,
    out: std::path::PathBuf,
    write: Option<std::path::PathBuf>,
}

fn parse(args: &[&str]) -> Result<Options> {
    let mut o = Options {
        size: 64,
        ref_spp: 1024,
        spp: 64,
        scenes: None,
        out: crate::root().join("bench/stiff.md"),
        write: None,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().copied().context(format!("{a} needs a value"));
        match *a {
            "--size" => o.size = value()?.parse()?,
            "--ref-spp" => o.ref_spp = value()?.parse()?,
            "--spp" => o.spp = value()?.parse()?,
            "--scenes" => o.scenes = Some(value()?.split(',').map(str::to_string).collect()),
            "--out" => o.out = value()?.into(),
            "--write" => o.write = Some(value()?.into()),
            other => bail!("unknown option {other}\n\nusage: cargo xtask stiff [--size N] [--ref-spp N] [--spp N] [--scenes a,b] [--out F] | --write DIR"),
        }
    }
    Ok(o)
}

/// One row of the table.
struct Row {
    scene: String,
    method: String,
    relmse: Option<f64>,
    block_rmse: Option<f64>,
    leak: Option<f64>,
    nonfinite: Option<u64>,
    time_s: f64,
    note: String,
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.3e}"))
}

pub fn run(args: &[&str]) -> Result<()> {
    let o = parse(args)?;
    if let Some(dir) = &o.write {
        for s in stiff_scenes() {
            println!("{}", write_stiff_scene(&s, dir)?.display());
        }
        return Ok(());
    }
    let start = Instant::now();
    let dir = std::env::temp_dir().join(format!("radcache-stiff-{}", std::process::id()));
    let ctx = Context::new()?;
    let device = ctx.info().name.clone();
    let validation = ctx.info().validation;
    let shaders = ShaderCompiler::new(crate::root().join("shaders"))?;
    let mut refs: BTreeMap<&'static str, Image> = BTreeMap::new();
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for s in stiff_scenes() {
        if o.scenes
            .as_ref()
            .is_some_and(|l| !l.iter().any(|n| n == s.name))
        {
            continue;
        }
        eprintln!(
            "stiff: {} ({:.0} s so far)",
            s.name,
            start.elapsed().as_secs_f64()
        );
        let path = write_stiff_scene(&s, &dir)?;
        let loaded = Scene::load(&path, &LoadOptions::default());
        let (scene, warnings) = match (&s.check, loaded) {
            (StiffCheck::LoadError(element), Err(e)) => {
                let msg = e.to_string();
                let named = msg.contains(&*path.to_string_lossy()) && msg.contains(element);
                rows.push(load_row(&s, named, &msg));
                continue;
            }
            (StiffCheck::LoadError(_), Ok(_)) => {
                rows.push(load_row(&s, false, "loaded without error"));
                continue;
            }
            (_, r) => r.with_context(|| format!("loading {}", path.display()))?,
        };
        let warn: Vec<String> = warnings
            .iter()
            .filter(|w| w.kind != WarningKind::DefaultCamera)
            .map(|w| format!("{:?}×{}", w.kind, w.count))
            .collect();
        notes.push(format!(
            "- `{}`: {}{}",
            s.name,
            s.about,
            if warn.is_empty() {
                String::new()
            } else {
                format!(" (warnings: {})", warn.join(", "))
            }
        ));
        let mut gpu = GpuScene::new(&ctx, &scene, None)?;
        let effort = Effort {
            size: o.size,
            sub_frames: 8,
            direct_samples: 16,
            seed: 1,
        };
        let reference = match (&s.check, closed_form_reference(&s.check, o.size)) {
            (_, Some(r)) => Some(r),
            (StiffCheck::Reference(of), None) => {
                let key = of.unwrap_or(s.name);
                if !refs.contains_key(key) {
                    let r = reference(&ctx, &shaders, &s, &scene, &mut gpu, &o)?;
                    refs.insert(key, r);
                }
                refs.get(key).cloned()
            }
            _ => None,
        };
        let methods = [
            Method::Ic(Preset::Draft),
            Method::Ic(Preset::Default),
            Method::Ic(Preset::High),
            Method::Path(o.spp),
        ];
        for m in methods {
            let r = render(&ctx, &shaders, &scene, &mut gpu, m, effort)?;
            let f = reference.as_ref().map(|re| figures(&s.check, re, &r.image));
            let mean = radcache_tests::stiff::mean_luminance(&r.image);
            let mut note = format!("mean {mean:.4}");
            if r.records > 0 {
                let _ = write!(note, ", {} records", r.records);
            }
            if let Some(f) = &f {
                let _ = write!(note, ", mean ratio {:.3}", f.metrics.mean_ratio[1]);
            }
            rows.push(Row {
                scene: s.name.into(),
                method: m.label(),
                relmse: f.as_ref().map(|f| f.metrics.relmse),
                block_rmse: f.as_ref().map(|f| f.metrics.block_rmse),
                leak: f.as_ref().and_then(|f| f.leak),
                nonfinite: Some(r.nonfinite),
                time_s: r.time_s,
                note,
            });
            let last = rows.last().expect("just pushed");
            eprintln!(
                "  {:<11} relMSE {:>9}  block {:>9}  leak {:>10}  NaN {}  {:.1} s  {}",
                last.method,
                fmt_opt(last.relmse),
                fmt_opt(last.block_rmse),
                fmt_opt(last.leak),
                r.nonfinite,
                r.time_s,
                last.note
            );
        }
        drop(gpu);
    }
    let first_error = ctx.first_validation_error();
    let report = ctx.shutdown();
    let total = start.elapsed().as_secs_f64();
    let mut md = markdown(&o, &rows, &notes, &device, validation, &report, total);
    md.push_str(&kept_notes(&o.out));
    print!("{md}");
    std::fs::write(&o.out, &md).with_context(|| format!("writing {}", o.out.display()))?;
    eprintln!("wrote {}", o.out.display());
    let _ = std::fs::remove_dir_all(&dir);
    if report.validation_errors > 0 {
        bail!(
            "{} validation errors; first: {}",
            report.validation_errors,
            first_error.unwrap_or_default()
        );
    }
    Ok(())
}

/// The line after which `bench/stiff.md` holds hand-written findings, kept across runs.
const NOTES_MARKER: &str = "<!-- findings: written by hand, kept by cargo xtask stiff -->";

/// The hand-written part of the existing report (from the marker on), or just the marker.
fn kept_notes(path: &std::path::Path) -> String {
    let old = std::fs::read_to_string(path).unwrap_or_default();
    match old.find(NOTES_MARKER) {
        Some(i) => format!("\n{}", &old[i..]),
        None => format!("\n{NOTES_MARKER}\n"),
    }
}

fn load_row(s: &StiffScene, named: bool, msg: &str) -> Row {
    let verdict = if named {
        "load error names the file and element"
    } else {
        "FAIL: expected a load error naming the file and element"
    };
    let msg = msg.rsplit('/').next().unwrap_or(msg);
    Row {
        scene: s.name.into(),
        method: "load".into(),
        relmse: None,
        block_rmse: None,
        leak: None,
        nonfinite: None,
        time_s: 0.0,
        note: format!("{verdict}: …/{msg}"),
    }
}

fn reference(
    ctx: &Context,
    shaders: &ShaderCompiler,
    s: &StiffScene,
    scene: &Scene,
    gpu: &mut GpuScene,
    o: &Options,
) -> Result<Image> {
    let effort = Effort {
        size: o.size,
        sub_frames: 1,
        direct_samples: 1,
        seed: 12345,
    };
    let r = render(ctx, shaders, scene, gpu, Method::Path(o.ref_spp), effort)?;
    eprintln!(
        "  reference {}: path {} spp, {:.1} s",
        s.name, o.ref_spp, r.time_s
    );
    anyhow::ensure!(r.nonfinite == 0, "the reference of {} has NaN/Inf", s.name);
    Ok(r.image)
}

fn markdown(
    o: &Options,
    rows: &[Row],
    notes: &[String],
    device: &str,
    validation: bool,
    report: &radcache_vk::ShutdownReport,
    total_s: f64,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Stiff and extreme suite (`cargo xtask stiff`)\n");
    let _ = writeln!(
        s,
        "Generated by `cargo xtask stiff --size {} --ref-spp {} --spp {}` on {device}, \
         {:.0} s in all. Validation layer: {}, {} errors, {} warnings.\n",
        o.size,
        o.ref_spp,
        o.spp,
        total_s,
        if validation { "on" } else { "off" },
        report.validation_errors,
        report.validation_warnings
    );
    let _ = writeln!(
        s,
        "{}×{} images; the cache with 8 sub-frames and 16 direct samples per pixel and \
         sub-frame; references: analytic (furnaces), black (`two_rooms`, `inside_object`), \
         else the path tracer at {} spp (`cornell_1e-3` and `cornell_1e4` against \
         `cornell_1`'s). relMSE = Σ(c−r)²/(r²+0.01)/3N; block RMSE over 8×8-block means; leak: \
         mean luminance over what must be dark (absolute for the black scenes; else the excess \
         over the reference's in the 8×8 blocks whose reference mean is at most 2 % of the \
         image's, relative to the image's mean; — where there are none; see \
         `tests/src/stiff.rs`); NaN: non-finite pixels found at readback. Time: wall time of \
         the frame, pipelines included.\n",
        o.size, o.size, o.ref_spp
    );
    let _ = writeln!(
        s,
        "| scene | method | relMSE | block RMSE | leak | NaN | time (s) | note |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {:.2} | {} |",
            r.scene,
            r.method,
            fmt_opt(r.relmse),
            fmt_opt(r.block_rmse),
            fmt_opt(r.leak),
            r.nonfinite.map_or("—".into(), |n| n.to_string()),
            r.time_s,
            r.note
        );
    }
    let _ = writeln!(s, "\n## Scenes\n");
    for n in notes {
        let _ = writeln!(s, "{n}");
    }
    s
}
