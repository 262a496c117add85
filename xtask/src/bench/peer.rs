//! `cargo xtask bench peer`: radcache's default preset against Mitsuba 3 (an independent peer, CPU
//! `llvm_ad_rgb` variant) at equal wall time, on every bundled scene.
//!
//! For each scene (one frame: t = 0 for the still scenes and the courtyard, whose radcache
//! reference is at t = 0; the middle of the animation for `cornell_fly` and `animated`), at 256
//! pixels high and the camera's aspect:
//! 1. the scene is exported for Mitsuba ([`mitsuba::export`], cached under
//!    `~/.cache/radcache/peer/<hash>/`);
//! 2. the reference: Mitsuba at `--reference-spp` (default 8192) samples per pixel, cached as an
//!    EXR beside the export (keyed by the export's hash, which covers resolution and camera, and
//!    the spp), so a second run reuses it (or any cached one with more samples);
//! 3. radcache renders the frame with `--method ic` at the default preset, with the CLI's
//!    default adaptive anti-aliasing (`AntiAliasing::preset`), in-process after a warm-up frame,
//!    as `bench ic` does: its wall time is T;
//! 4. Mitsuba renders for the same T: a discarded warm-up pass compiles its kernels (not in the
//!    figure), the first timed pass gives the time per pass and the number of passes that fits T;
//!    both achieved times are recorded;
//! 5. relMSE, 8×8-block RMSE and FLIP (radcache-image's `compare`: mean LDR-FLIP of the
//!    sRGB-encoded images) of both against the reference. The reference's own noise adds
//!    `e_ref = c / ref_spp` to every relMSE measured against it, where `c = relMSE × spp` of
//!    Mitsuba's unbiased estimate (fitted from its equal-time render:
//!    `relMSE = c · (1/spp + 1/ref_spp)`); both methods' own relMSE is the measured one minus
//!    `e_ref`, and the ratio Mitsuba / radcache is taken on those.
//!
//! Validation of the export: where a radcache path-traced reference exists
//! (`tests/refs/cornell_256.exr`, or `--radcache-ref SCENE=FILE.exr`), Mitsuba's reference is
//! compared with it (per-channel mean ratio and relMSE) before anything is timed.

mod mitsuba;

use anyhow::{Context as _, Result};
use radcache_cache::{IcParams, Preset};
use radcache_image::{compare, read_exr, write_exr, ExrOptions, Image, Metadata, Metrics};
use radcache_render::{render_ic, AntiAliasing, GpuScene, IcSettings};
use radcache_scene::{LoadOptions, Scene};

use super::harness::{Bench, Figure};
use mitsuba::{Mitsuba, PeerBudget};

/// The bundled scenes and the time of their frame.
const SCENES: [(&str, f32); 6] = [
    ("cornell", 0.0),
    ("cornell_fly", 1.0),
    ("animated", 2.5),
    ("furnace", 0.0),
    ("courtyard", 0.0),
    ("metal_spheres", 0.0),
];

/// Samples per pixel per pass of Mitsuba's equal-time render and of its reference.
const PASS_SPP: u32 = 4;
const REFERENCE_PASS_SPP: u32 = 64;

const USAGE: &str = "usage: cargo xtask bench peer [--scenes a,b,..] [--reference-spp N] \
                     [--height H] [--radcache-ref SCENE=FILE.exr]..";

struct Options {
    scenes: Vec<(String, f32)>,
    reference_spp: u32,
    height: u32,
    radcache_refs: Vec<(String, String)>,
}

fn parse(args: &[&str]) -> Result<Options> {
    let mut o = Options {
        scenes: SCENES.iter().map(|(n, t)| (n.to_string(), *t)).collect(),
        reference_spp: 8192,
        height: 256,
        radcache_refs: vec![("cornell".into(), "tests/refs/cornell_256.exr".into())],
    };
    let mut it = args.iter();
    while let Some(&a) = it.next() {
        let mut value = || it.next().copied().context(USAGE);
        match a {
            "--scenes" => {
                let wanted: Vec<&str> = value()?.split(',').collect();
                for w in &wanted {
                    anyhow::ensure!(
                        SCENES.iter().any(|(n, _)| n == w),
                        "unknown scene {w}; {USAGE}"
                    );
                }
                o.scenes.retain(|(n, _)| wanted.contains(&n.as_str()));
            }
            "--reference-spp" => o.reference_spp = value()?.parse().context(USAGE)?,
            "--height" => o.height = value()?.parse().context(USAGE)?,
            "--radcache-ref" => {
                let (s, f) = value()?.split_once('=').context(USAGE)?;
                o.radcache_refs.push((s.into(), f.into()));
            }
            _ => anyhow::bail!("{USAGE}"),
        }
    }
    anyhow::ensure!(o.reference_spp > 0 && o.height > 0, "{USAGE}");
    Ok(o)
}

pub fn run(args: &[&str]) -> Result<()> {
    let opts = parse(args)?;
    let peer = Mitsuba::find()?;
    let root = crate::root();
    let bench = Bench::new("peer")?;
    println!(
        "device: {}; peer: Mitsuba {} (llvm_ad_rgb, CPU)",
        bench.device(),
        peer.version()
    );
    for (s, file) in &opts.radcache_refs {
        let path = root.join(file);
        anyhow::ensure!(
            path.exists(),
            "bench peer: radcache reference for {s}: {} does not exist",
            path.display()
        );
    }
    let mut figures = Vec::new();
    let mut rows = Vec::new();
    for (name, t) in &opts.scenes {
        let scene_run = one_scene(&bench, &peer, &opts, name, *t, &mut figures);
        match scene_run {
            Ok(row) => rows.push(row),
            Err(e) => {
                // Keep the finished scenes' figures.
                bench.finish(&figures)?;
                return Err(e.context(format!("bench peer: scene {name}")));
            }
        }
    }
    println!("\n| scene | T s | radcache relMSE | block RMSE | FLIP | Mitsuba spp | time s | relMSE | block RMSE | FLIP | relMSE Mitsuba/radcache |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!("{}", r.markdown());
    }
    bench.finish(&figures)
}

/// One scene: export, reference, validation, radcache's frame and Mitsuba's equal-time render.
fn one_scene(
    bench: &Bench,
    peer: &Mitsuba,
    opts: &Options,
    name: &str,
    t: f32,
    figures: &mut Vec<Figure>,
) -> Result<Row> {
    let root = crate::root();
    let cache = mitsuba::cache_root()?.join("peer");
    let (scene, _) = Scene::load(
        &root.join(format!("assets/{name}/{name}.gltf")),
        &LoadOptions::default(),
    )?;
    let aspect = scene.camera.perspective.aspect_ratio.unwrap_or(1.0);
    let height = opts.height;
    let width = ((height as f32 * aspect).round() as u32).max(1);
    let xml = mitsuba::export(&scene, t, width, height, &cache)?;
    let (reference, ref_spp) = reference(peer, &xml, opts.reference_spp)?;
    let case = format!("{name}_{height}");
    for (s, file) in opts.radcache_refs.iter().filter(|(s, _)| s == name) {
        let path = root.join(file);
        let (rc_ref, meta) =
            read_exr(&path).with_context(|| format!("radcache reference for {s}"))?;
        let m = compare(&rc_ref, &reference)?;
        let dev = m.max_mean_ratio_dev();
        println!(
            "{name}: Mitsuba {} spp against radcache's {} ({} spp): mean ratio {:.4?} \
             (max |dev| {:.2}%), relMSE {:.3e}",
            ref_spp,
            file,
            meta.spp.map_or("?".into(), |s| s.to_string()),
            m.mean_ratio,
            100.0 * dev,
            m.relmse
        );
        figures.push(Figure::new(&case, "validation_mean_dev", dev, "ratio"));
        figures.push(Figure::new(&case, "validation_relmse", m.relmse, "relMSE"));
    }

    // radcache: default preset with the CLI's adaptive anti-aliasing, in-process, warm.
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    let mut gpu = GpuScene::new(ctx, &scene, None)?;
    let settings = IcSettings {
        width,
        height,
        params: IcParams::preset(Preset::Default),
        anti_aliasing: Some(AntiAliasing::preset(Preset::Default)),
        time: t,
        ..IcSettings::default()
    };
    bench.warm_up_ic(&scene, &mut gpu, settings.clone())?;
    let (out, stats) = render_ic(ctx, shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
    drop(gpu);
    println!(
        "  radcache: {} sub-frames shaded (adaptive anti-aliasing)",
        stats.sub_frames_shaded
    );
    figures.push(Figure::new(
        &case,
        "radcache_sub_frames",
        f64::from(stats.sub_frames_shaded),
        "sub-frames",
    ));
    let rc_image = Image::from_pixels(out.width, out.height, out.pixels)?;
    let big_t = out.time_s;

    let mi = peer.render(&xml, PeerBudget::Seconds(big_t), PASS_SPP)?;
    let rc = compare(&reference, &rc_image)?;
    let pm = compare(&reference, &mi.image)?;
    // Mitsuba's relMSE × spp, with the reference's noise (same estimator) fitted out.
    let c = pm.relmse / (1.0 / f64::from(mi.spp) + 1.0 / f64::from(ref_spp));
    let e_ref = c / f64::from(ref_spp);
    let row = Row::new(name, big_t, &rc, &mi, &pm, e_ref);
    row.print();
    row.figures(&case, figures);
    Ok(row)
}

/// Mitsuba's long render of `xml` and its spp: the cached one beside the export with the most
/// samples if it has at least `spp` (an unreadable one is ignored with a warning), else a new one.
fn reference(peer: &Mitsuba, xml: &std::path::Path, spp: u32) -> Result<(Image, u32)> {
    let dir = xml.parent().unwrap_or(std::path::Path::new("."));
    let mut cached: Vec<(u32, std::path::PathBuf)> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| {
            let path = e.ok()?.path();
            let name = path.file_name()?.to_str()?;
            let n = name.strip_prefix("reference_")?.strip_suffix("spp.exr")?;
            Some((n.parse().ok()?, path))
        })
        .filter(|(n, _)| *n >= spp)
        .collect();
    cached.sort();
    for (n, path) in cached.into_iter().rev() {
        match read_exr(&path) {
            Ok((image, _)) => return Ok((image, n)),
            Err(e) => log::warn!("ignoring the cached reference: {e}"),
        }
    }
    let path = dir.join(format!("reference_{spp}spp.exr"));
    println!(
        "rendering the Mitsuba reference at {spp} spp into {}",
        path.display()
    );
    let r = peer.render(xml, PeerBudget::Spp(spp), REFERENCE_PASS_SPP)?;
    println!("  {} spp in {:.1} s", r.spp, r.time_s);
    let mut meta = Metadata::new();
    meta.method = Some("mitsuba3 llvm_ad_rgb path".into());
    meta.spp = Some(r.spp);
    meta.render_time_s = Some(r.time_s);
    let options = ExrOptions {
        aovs: false,
        ..ExrOptions::default()
    };
    write_exr(&path, &r.image, &meta, &options)?;
    Ok((r.image, r.spp))
}

/// One scene's figures.
struct Row {
    name: String,
    t: f64,
    rc: [f64; 3],
    mi: [f64; 3],
    mi_spp: u32,
    mi_time: f64,
    mi_warmup: f64,
    e_ref: f64,
}

impl Row {
    fn new(
        name: &str,
        t: f64,
        rc: &Metrics,
        mi: &mitsuba::PeerRender,
        pm: &Metrics,
        e_ref: f64,
    ) -> Row {
        let own = |m: &Metrics| [m.relmse - e_ref, m.block_rmse, m.flip.unwrap_or(f64::NAN)];
        Row {
            name: name.into(),
            t,
            rc: own(rc),
            mi: own(pm),
            mi_spp: mi.spp,
            mi_time: mi.time_s,
            mi_warmup: mi.warmup_s,
            e_ref,
        }
    }

    fn ratio(&self) -> f64 {
        self.mi[0] / self.rc[0]
    }

    fn print(&self) {
        println!(
            "{}: radcache T = {:.2} s: relMSE {:.3e}, block RMSE {:.3e}, FLIP {:.4}; Mitsuba {} spp \
             in {:.2} s (warm-up pass {:.1} s not counted): relMSE {:.3e}, block RMSE {:.3e}, FLIP \
             {:.4}; Mitsuba/radcache relMSE {:.2} (reference's own relMSE {:.1e} taken off both)",
            self.name,
            self.t,
            self.rc[0],
            self.rc[1],
            self.rc[2],
            self.mi_spp,
            self.mi_time,
            self.mi_warmup,
            self.mi[0],
            self.mi[1],
            self.mi[2],
            self.ratio(),
            self.e_ref
        );
    }

    fn markdown(&self) -> String {
        format!(
            "| {} | {:.2} | {:.2e} | {:.2e} | {:.4} | {} | {:.2} | {:.2e} | {:.2e} | {:.4} | {:.2} |",
            self.name,
            self.t,
            self.rc[0],
            self.rc[1],
            self.rc[2],
            self.mi_spp,
            self.mi_time,
            self.mi[0],
            self.mi[1],
            self.mi[2],
            self.ratio()
        )
    }

    fn figures(&self, case: &str, out: &mut Vec<Figure>) {
        let f = |metric, value, unit| Figure::new(case, metric, value, unit);
        out.extend([
            f("ic_time_s", self.t, "s"),
            f("ic_relmse", self.rc[0], "relMSE"),
            f("ic_block_rmse", self.rc[1], "rmse"),
            f("ic_flip", self.rc[2], "flip"),
            f("mitsuba_spp", f64::from(self.mi_spp), "spp"),
            f("mitsuba_time_s", self.mi_time, "s"),
            f("mitsuba_relmse", self.mi[0], "relMSE"),
            f("mitsuba_block_rmse", self.mi[1], "rmse"),
            f("mitsuba_flip", self.mi[2], "flip"),
            f("reference_relmse", self.e_ref, "relMSE"),
            f("relmse_ratio_mitsuba_over_ic", self.ratio(), "ratio"),
        ]);
    }
}
