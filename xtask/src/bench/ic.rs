//! `cargo xtask bench ic [--scene cornell|courtyard]`: the irradiance cache against the path
//! tracer, on the Cornell box (the default) or the Sponza-class courtyard.
//!
//! At 256² (where `tests/refs/<scene>_256.exr` is the reference), for each quality preset (the
//! courtyard: the default only): the IC
//! frame's time (everything `render_ic` does, pipeline creation included), records and rays and
//! its relMSE; the path tracer's relMSE at 4, 16 and 64 spp and its time per spp; the
//! path tracer's time to reach the IC's relMSE, as `radcache convergence` computes it
//! ([`radcache_image::equal_error`]: log–log interpolation between the measured points, relMSE ∝
//! 1/time beyond them), each point timed at the time per spp measured at 16 spp just before the
//! IC frame (this machine's speed drifts by up to 2× over minutes: a time per spp from the end
//! of the run once doubled the ratios); and their ratio. Errors are each method's own: the
//! reference's noise (`c / S` of the fit `relMSE = c/spp + c/S`) is taken off every measured
//! relMSE. At 512² (no reference): the
//! default preset's time, records and rays. The record pass's ray rate is its rays over the wall
//! time of the record-creation submissions (lavapipe's timestamps do not bracket asynchronous
//! compute work; this time also holds the neighbour pass and the submission overhead, so the
//! share is a lower bound), set against the raw incoherent ray-query rate in the same scene (the
//! scene's triangles, rays from random surface points, measured in the same run). Beside the
//! defaults, the frame at 256² with the direct light of before the closed-form emitters and the
//! sky through the records (`--set emitters=sampled --set sky=direct`; case suffix `_sampled_light`), and
//! with adaptive anti-aliasing (suffix `_aa`; `_aa_no_path_grid` with full gather paths instead
//! of the radiance grid, docs/cache-frame.md §4.1), and splatting at
//! every sub-frame instead of once per frame (suffixes `_splat_per_sub_frame` and
//! `_aa_splat_per_sub_frame`), and, where the emitters are taken in closed form, with a quarter
//! of the direct samples as shadow rays at every pixel instead of adaptive emitter shadows
//! (suffix `_fixed_shadows`), and with the preset's strata at every creation level instead of the
//! fine strata where records are as dense as `R⁻` (suffixes `_uniform_strata` and
//! `_aa_uniform_strata`), each with its direct rays, sub-frames and shade-phase time, so one run
//! shows what they changed.

/// A scene of the benchmark: name, glTF, reference, the presets timed at 256² and whether the
/// default is also timed at 512².
struct BenchScene {
    name: &'static str,
    gltf: &'static str,
    reference: &'static str,
    presets: &'static [Preset],
    at_512: bool,
}

const SCENES: &[BenchScene] = &[
    BenchScene {
        name: "cornell",
        gltf: "assets/cornell/cornell.gltf",
        reference: "tests/refs/cornell_256.exr",
        presets: &[Preset::Draft, Preset::Default, Preset::High],
        at_512: true,
    },
    BenchScene {
        name: "courtyard",
        gltf: "assets/courtyard/courtyard.gltf",
        reference: "tests/refs/courtyard_256.exr",
        presets: &[Preset::Default],
        at_512: false,
    },
];

use anyhow::{Context as _, Result};
use radcache_cache::{IcParams, Preset};
use radcache_image::equal_error::{self, PtPoint};
use radcache_image::{compare, read_exr, Image};
use radcache_render::{
    render_ic, render_path, AntiAliasing, Budget, EmitterLight, EmitterShadows, GpuScene,
    IcSettings, PathGridMode, PathSettings, SkyLight, SplatMode,
};
use radcache_scene::{LoadOptions, Scene};

use super::harness::{Bench, Figure};

/// How a case differs from the preset with 8 sub-frames.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Variant {
    Plain,
    /// `--set emitters=sampled --set sky=direct`.
    SampledLight,
    /// Adaptive anti-aliasing with the preset's target.
    Aa,
    /// Adaptive anti-aliasing and full gather paths (`--set path_grid=off`).
    AaNoPathGrid,
    /// A splat at every sub-frame (`--set splat=per-sub-frame`).
    SplatPerSubFrame,
    /// Adaptive anti-aliasing and a splat at every sub-frame.
    AaSplatPerSubFrame,
    /// A quarter of the direct samples as emitter shadow rays at every pixel and sub-frame
    /// (`--set emitter_shadows=fixed`; scenes whose emitters are taken in closed form).
    FixedShadows,
    /// The preset's strata at every level (`--fine-strata` = `--strata`, `--strata-falloff off`).
    UniformStrata,
    /// Adaptive anti-aliasing and the preset's strata at every level.
    AaUniformStrata,
    /// Adaptive anti-aliasing and the fine strata whole at every fine level
    /// (`--strata-falloff off`).
    AaNoFalloff,
}

impl Variant {
    fn suffix(self) -> &'static str {
        match self {
            Variant::Plain => "",
            Variant::SampledLight => "_sampled_light",
            Variant::Aa => "_aa",
            Variant::AaNoPathGrid => "_aa_no_path_grid",
            Variant::SplatPerSubFrame => "_splat_per_sub_frame",
            Variant::AaSplatPerSubFrame => "_aa_splat_per_sub_frame",
            Variant::FixedShadows => "_fixed_shadows",
            Variant::UniformStrata => "_uniform_strata",
            Variant::AaUniformStrata => "_aa_uniform_strata",
            Variant::AaNoFalloff => "_aa_no_falloff",
        }
    }
}

pub fn run(args: &[&str]) -> Result<()> {
    let usage = "usage: cargo xtask bench ic [--scene cornell|courtyard]";
    let which = match args {
        [] => "cornell",
        ["--scene", name] => name,
        _ => anyhow::bail!(usage),
    };
    let bs = SCENES
        .iter()
        .find(|s| s.name == which)
        .ok_or_else(|| anyhow::anyhow!("no benchmark scene {which:?}; {usage}"))?;
    let root = crate::root();
    let (scene, _) = Scene::load(&root.join(bs.gltf), &LoadOptions::default())?;
    let (reference, ref_meta) = read_exr(root.join(bs.reference))?;
    let ref_spp = ref_meta
        .spp
        .ok_or_else(|| anyhow::anyhow!("the reference's EXR does not record its spp"))?;
    let bench = Bench::new("ic")?;
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    let raw = super::scene_rays::incoherent_rate_in(ctx, shaders, &scene)?;
    let mut gpu = GpuScene::new(ctx, &scene, None)?;
    let mut figures = vec![Figure::new(
        format!("{}_raw_incoherent", bs.name),
        "rays_per_s",
        raw,
        "rays/s",
    )];
    println!(
        "device: {}; raw incoherent rate in the {} {:.2} Mrays/s",
        bench.device(),
        bs.name,
        raw / 1e6
    );
    let draft = IcSettings {
        params: IcParams::draft(),
        ..IcSettings::default()
    };
    let sampled_light = IcSettings {
        emitters: EmitterLight::Sampled,
        sky: SkyLight::Direct,
        ..draft.clone()
    };
    let no_grid = IcSettings {
        path_grid: PathGridMode::Off,
        ..draft.clone()
    };
    bench.warm_up_ic(&scene, &mut gpu, draft)?;
    bench.warm_up_ic(&scene, &mut gpu, sampled_light)?;
    bench.warm_up_ic(&scene, &mut gpu, no_grid)?;
    bench.warm_up_path(&scene, &mut gpu)?;

    // (size, preset, variant): every preset at the reference's size with 8 sub-frames, the
    // default at 512², the default at 256² with the direct light sampled as before, and with
    // the CLI's adaptive anti-aliasing (AntiAliasing::preset; also with full gather paths).
    use Variant::*;
    let mut cases: Vec<(u32, Preset, Variant)> =
        bs.presets.iter().map(|&p| (256, p, Plain)).collect();
    if bs.at_512 {
        cases.push((512, Preset::Default, Plain));
    }
    cases.push((256, Preset::Default, SampledLight));
    cases.push((256, Preset::Default, Aa));
    cases.push((256, Preset::Default, AaNoPathGrid));
    cases.push((256, Preset::Default, SplatPerSubFrame));
    cases.push((256, Preset::Default, AaSplatPerSubFrame));
    if scene.plan().analytic_emitters {
        cases.push((256, Preset::Default, FixedShadows));
    }
    cases.push((256, Preset::Default, UniformStrata));
    cases.push((256, Preset::Default, AaUniformStrata));
    cases.push((256, Preset::Default, AaNoFalloff));
    // (case, relMSE, time, the index in `pt_beside` of the path tracer's time per spp timed just
    // before) of the frames with a reference; one more is timed after the last.
    let mut matched = Vec::new();
    let mut pt_beside = Vec::new();
    let pt_settings = |spp: u32| PathSettings {
        width: reference.width(),
        height: reference.height(),
        budget: Budget::Samples(spp),
        seed: 777,
        ..PathSettings::default()
    };
    // This machine's speed drifts by up to 2× over minutes: the path tracer's time per spp is
    // timed before and after each frame with a reference, and the comparison uses their mean.
    let pt_s_per_spp = |gpu: &mut GpuScene| -> Result<f64> {
        let out = render_path(ctx, shaders, &scene, gpu, &pt_settings(16), &mut |_| {})?;
        Ok(out.time_s / 16.0)
    };
    for (size, preset, variant) in cases {
        if size == reference.width() {
            pt_beside.push(pt_s_per_spp(&mut gpu)?);
        }
        let mut settings = IcSettings {
            width: size,
            height: size,
            params: IcParams::preset(preset),
            ..IcSettings::default()
        };
        match variant {
            Plain => {}
            SampledLight => {
                settings.emitters = EmitterLight::Sampled;
                settings.sky = SkyLight::Direct;
            }
            Aa => settings.anti_aliasing = Some(AntiAliasing::preset(preset)),
            AaNoPathGrid => {
                settings.anti_aliasing = Some(AntiAliasing::preset(preset));
                settings.path_grid = PathGridMode::Off;
            }
            SplatPerSubFrame => settings.splat = SplatMode::PerSubFrame,
            AaSplatPerSubFrame => {
                settings.anti_aliasing = Some(AntiAliasing::preset(preset));
                settings.splat = SplatMode::PerSubFrame;
            }
            FixedShadows => settings.emitter_shadows = EmitterShadows::Fixed,
            AaNoFalloff => {
                settings.anti_aliasing = Some(AntiAliasing::preset(preset));
                settings.params.strata_falloff = false;
            }
            UniformStrata | AaUniformStrata => {
                let p = &mut settings.params;
                (p.fine_strata_m, p.fine_strata_n) = (p.strata_m, p.strata_n);
                p.strata_falloff = false;
                if variant == AaUniformStrata {
                    settings.anti_aliasing = Some(AntiAliasing::preset(preset));
                }
            }
        }
        let (out, stats) = render_ic(ctx, shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
        let record_rays = stats.record_rays as f64;
        let level_s = stats.record_pass_s;
        let rays: u64 = out.rays.values().sum();
        let name = format!("{preset:?}").to_lowercase();
        let mut case = if preset == Preset::Default {
            format!("{}_{size}", bs.name)
        } else {
            format!("{}_{size}_{name}", bs.name)
        };
        case.push_str(variant.suffix());
        let direct_rays = out.rays.get("direct").copied().unwrap_or(0) as f64;
        let shade_s = stats.phases_s.get("shade").copied().unwrap_or(0.0);
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
        let sub_frames = f64::from(stats.sub_frames_shaded);
        figures.push(Figure::new(
            &case,
            "ic_sub_frames",
            sub_frames,
            "sub-frames",
        ));
        figures.push(Figure::new(
            &case,
            "ic_unmatched_samples",
            stats.unmatched_samples as f64,
            "samples",
        ));
        figures.push(Figure::new(
            &case,
            "ic_records",
            stats.records as f64,
            "records",
        ));
        figures.push(Figure::new(&case, "ic_rays", rays as f64, "rays"));
        figures.push(Figure::new(&case, "ic_direct_rays", direct_rays, "rays"));
        figures.push(Figure::new(&case, "ic_shade_s", shade_s, "s"));
        println!(
            "  direct rays {:.2} M, shade phase {shade_s:.2} s ({:.0}% of the frame)",
            direct_rays / 1e6,
            100.0 * shade_s / out.time_s
        );
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
            matched.push((case, m.relmse, out.time_s, pt_beside.len() - 1));
        }
    }

    pt_beside.push(pt_s_per_spp(&mut gpu)?);

    // The path tracer at growing spp against the same reference.
    let mut pt_points = Vec::new();
    let mut per_spp_s = Vec::new();
    for spp in [4u32, 16, 64] {
        let out = render_path(
            ctx,
            shaders,
            &scene,
            &mut gpu,
            &pt_settings(spp),
            &mut |_| {},
        )?;
        let image = Image::from_pixels(out.width, out.height, out.pixels)?;
        let m = compare(&reference, &image)?;
        println!(
            "PT {spp:>3} spp: {:.2} s, relMSE {:.3e}",
            out.time_s, m.relmse
        );
        figures.push(Figure::new(
            format!("{}_256_pt{spp}", bs.name),
            "time_s",
            out.time_s,
            "s",
        ));
        figures.push(Figure::new(
            format!("{}_256_pt{spp}", bs.name),
            "relmse",
            m.relmse,
            "relMSE",
        ));
        pt_points.push((spp, m.relmse));
        per_spp_s.push(out.time_s / f64::from(spp));
    }
    // The error model and the time to the same error are `radcache convergence`'s
    // (`radcache_image::equal_error`): the reference is itself a path-traced image with ref_spp
    // samples, whose noise e_ref = c / ref_spp adds to every relMSE measured against it; both
    // methods are compared on their own error, relMSE − e_ref.
    let t1 = equal_error::median(&per_spp_s).context("the path tracer's per-spp times")?;
    let c = equal_error::noise_constant(&pt_points, Some(ref_spp))
        .context("the path tracer's relMSE against the reference")?;
    let e_ref = equal_error::reference_noise(Some(c), Some(ref_spp));
    println!(
        "PT: relMSE = c/spp + c/{ref_spp} with c = {c:.3e}, {t1:.3} s per spp; the {ref_spp}-spp reference's own relMSE ≈ {e_ref:.2e}"
    );
    figures.push(Figure::new(
        format!("{}_256", bs.name),
        "reference_relmse",
        e_ref,
        "relMSE",
    ));
    for (case, relmse, time, k) in matched {
        let t_local = 0.5 * (pt_beside[k] + pt_beside[k + 1]);
        let own = relmse - e_ref;
        if own <= 0.0 {
            println!("{case}: relMSE {relmse:.2e} is within the reference's own noise");
            continue;
        }
        // The path tracer's points, each timed at the per-spp cost measured around this case.
        let curve: Vec<PtPoint> = pt_points
            .iter()
            .map(|&(spp, relmse)| PtPoint {
                spp,
                time_s: f64::from(spp) * t_local,
                error: relmse - e_ref,
            })
            .collect();
        let Some(matched) = equal_error::pt_time_to_match(&curve, own) else {
            println!("{case}: no path-tracer point to match its relMSE {own:.2e} against");
            continue;
        };
        let pt_time = matched.time_s;
        let spp_needed = pt_time / t_local;
        let how = if matched.extrapolated {
            "extrapolated"
        } else {
            "interpolated"
        };
        println!(
            "{case}: own relMSE {own:.2e} ({relmse:.2e} against the reference); PT needs ~{spp_needed:.0} spp ({how}) = {pt_time:.1} s at {t_local:.3} s per spp timed around it ({:.1} s at the median {t1:.3}); IC took {time:.1} s: {:.1}× faster",
            spp_needed * t1,
            pt_time / time
        );
        figures.push(Figure::new(&case, "pt_s_per_spp_beside", t_local, "s"));
        figures.push(Figure::new(&case, "ic_own_relmse", own, "relMSE"));
        figures.push(Figure::new(&case, "pt_spp_to_match", spp_needed, "spp"));
        figures.push(Figure::new(&case, "pt_time_to_match_s", pt_time, "s"));
        figures.push(Figure::new(&case, "speedup", pt_time / time, "ratio"));
    }
    drop(gpu);
    bench.finish(&figures)
}
