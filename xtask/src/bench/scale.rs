//! `cargo xtask bench scale [--size S] [--max-unique N] [--grid G]`: how loading, the
//! acceleration structures, memory and the frame grow with the scene, on generated scenes of a
//! bumpy UV sphere on a floor under a sun and a constant sky (the default preset, one camera for
//! every case):
//!
//! - `unique_82k`, `unique_1m` (and `unique_10m` with `--max-unique 10000000`): one sphere of
//!   81,920 / 1,024,000 / 10,000,000 triangles;
//! - `instanced_82k_x121_nodes` and `instanced_82k_x121_gpu_instancing`: the 82k sphere placed
//!   11 × 11 times (9.9M instanced triangles) by 121 nodes sharing its mesh, and by one node's
//!   `EXT_mesh_gpu_instancing`; `--grid G` adds a G × G case of each (G = 35: 100M, G = 110: 1G).
//!
//! Per case: triangles (unique and instanced), the load's wall time (`Scene::load`: the file is
//! written first, outside the timing), the upload's (`GpuScene::new`, which builds and compacts the
//! BLASes, plus the first TLAS build) with the BLASes' GPU time, the device memory planned for the
//! upload's peak (`UploadStats::memory_need`) and kept after it (every live allocation), the
//! process's peak resident host memory so far (`VmHWM`), the frame's wall time, records, sub-frames
//! (adaptive AA), and the ray rates: the record pass's (its ray queries over its wall time) and the
//! frame's (every ray query over the frame's wall time). Then the ratios the scale targets are
//! stated against: the instanced frames and record ray rates over the single sphere's, and the 1M
//! sphere's record ray rate over the 82k one's.
//!
//! Two figures are held: **device bytes per unique triangle** (kept bytes of `unique_1m` over its
//! triangles) and **device bytes per instance** (the nodes case's kept bytes less the single
//! sphere's, over the 120 added instances). The bench fails when either is more than 10 % above
//! the lowest earlier value of this bench on the same device in `bench/results.csv` (after
//! appending this run's rows, so the failure is on record).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use glam::Vec3;
use radcache_cache::Preset;
use radcache_render::{render_ic, GpuScene, IcSettings};
use radcache_scene::assets::look;
use radcache_scene::light::LightKind;
use radcache_scene::writer::{
    write_files, GltfBuilder, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc,
};
use radcache_scene::{LoadOptions, Scene};
use radcache_vk::Context;
use serde_json::{json, Value};

use super::harness::{Bench, Figure};

const USAGE: &str = "usage: cargo xtask bench scale [--size S] [--max-unique N] [--grid G]";

/// Allowed growth of the held figures over their best earlier value.
const GROWTH: f64 = 1.10;

/// How a case places its spheres.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Placement {
    /// One node per sphere, all sharing the mesh.
    Nodes,
    /// One node with `EXT_mesh_gpu_instancing` translations.
    GpuInstancing,
}

struct Case {
    name: String,
    /// UV sphere rings and segments: 2 · segments · (rings − 1) triangles.
    rings: u32,
    segments: u32,
    /// Spheres per side of the grid (1: one sphere).
    grid: u32,
    placement: Placement,
}

struct Options {
    size: u32,
    max_unique: u64,
    grids: Vec<u32>,
}

fn parse(args: &[&str]) -> Result<Options> {
    let mut o = Options {
        size: 256,
        max_unique: 1_100_000,
        grids: vec![11],
    };
    let mut it = args.iter();
    while let Some(&arg) = it.next() {
        let mut value = || {
            it.next()
                .copied()
                .with_context(|| format!("{arg}: no value\n{USAGE}"))
        };
        let mut number = |what: &str| -> Result<u64> {
            let v = value()?;
            v.parse()
                .with_context(|| format!("{what} {v:?} is not a number\n{USAGE}"))
        };
        match arg {
            "--size" => o.size = number("--size")?.clamp(16, 4096) as u32,
            "--max-unique" => o.max_unique = number("--max-unique")?,
            "--grid" => o.grids.push(number("--grid")?.clamp(2, 1000) as u32),
            other => bail!("unknown argument {other:?}\n{USAGE}"),
        }
    }
    Ok(o)
}

fn cases(o: &Options) -> Vec<Case> {
    let mut cases = vec![];
    for (name, rings, segments) in [
        ("unique_82k", 161, 256),
        ("unique_1m", 1001, 512),
        ("unique_10m", 3126, 1600),
    ] {
        if 2 * u64::from(segments) * u64::from(rings - 1) <= o.max_unique {
            cases.push(Case {
                name: name.into(),
                rings,
                segments,
                grid: 1,
                placement: Placement::Nodes,
            });
        }
    }
    for &grid in &o.grids {
        for (placement, how) in [
            (Placement::Nodes, "nodes"),
            (Placement::GpuInstancing, "gpu_instancing"),
        ] {
            cases.push(Case {
                name: format!("instanced_82k_x{}_{how}", grid * grid),
                rings: 161,
                segments: 256,
                grid,
                placement,
            });
        }
    }
    cases
}

/// A UV sphere of radius ~1 whose radius is modulated by 3 % bumps, with its vertex normals (the
/// normalized sum of the adjacent faces' area-weighted normals).
fn bumpy_sphere(rings: u32, segments: u32) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<u32>) {
    let mut p = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let r = 1.0 + 0.03 * (12.0 * theta).sin() * (12.0 * phi).sin();
            p.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ),
            );
        }
    }
    let idx = |i: u32, j: u32| i * segments + (j % segments);
    let mut indices = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1));
            if i != 0 {
                indices.extend([a, c, b]);
            }
            if i != rings - 1 {
                indices.extend([b, c, d]);
            }
        }
    }
    let mut n = vec![Vec3::ZERO; p.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|k| k as usize);
        let face = (p[b] - p[a]).cross(p[c] - p[a]);
        for k in [a, b, c] {
            n[k] += face;
        }
    }
    let normals = n
        .iter()
        .zip(&p)
        .map(|(n, p)| n.try_normalize().unwrap_or(p.normalize()).to_array())
        .collect();
    (p.iter().map(|v| v.to_array()).collect(), normals, indices)
}

/// The spheres' centres: a `grid` × `grid` square, 2.5 apart, on the floor.
fn centres(grid: u32) -> Vec<[f32; 3]> {
    let half = (grid as f32 - 1.0) / 2.0;
    (0..grid * grid)
        .map(|k| {
            let (x, z) = ((k % grid) as f32 - half, (k / grid) as f32 - half);
            [2.5 * x, 1.0, 2.5 * z]
        })
        .collect()
}

/// Writes `case` to `dir/<name>.gltf` (+ `.bin`).
fn write_case(case: &Case, dir: &Path) -> Result<PathBuf> {
    let mut b = GltfBuilder::new();
    let grey = b.add_material(&MaterialDesc::diffuse("grey", [0.6, 0.6, 0.6]));
    let white = b.add_material(&MaterialDesc::diffuse("white", [0.8, 0.8, 0.8]));
    let (positions, normals, indices) = bumpy_sphere(case.rings, case.segments);
    let sphere = b.add_mesh(
        "sphere",
        &[PrimitiveDesc::triangles(
            positions,
            Some(normals),
            indices,
            Some(grey),
        )],
    );
    let f = 2.5 * case.grid as f32 + 10.0;
    let floor = b.add_mesh(
        "floor",
        &[PrimitiveDesc::triangles(
            vec![[-f, 0.0, -f], [f, 0.0, -f], [f, 0.0, f], [-f, 0.0, f]],
            Some(vec![[0.0, 1.0, 0.0]; 4]),
            vec![0, 2, 1, 0, 3, 2],
            Some(white),
        )],
    );
    let mut roots = vec![b.add_node(&NodeDesc {
        mesh: Some(floor),
        ..NodeDesc::default()
    })];
    let centres = centres(case.grid);
    let instancing_node = match case.placement {
        Placement::Nodes => {
            for c in &centres {
                roots.push(b.add_node(&NodeDesc {
                    mesh: Some(sphere),
                    translation: Some(*c),
                    ..NodeDesc::default()
                }));
            }
            None
        }
        Placement::GpuInstancing => {
            let node = b.add_node(&NodeDesc {
                name: Some("spheres".into()),
                mesh: Some(sphere),
                ..NodeDesc::default()
            });
            roots.push(node);
            Some(node)
        }
    };
    let sun = b.add_light(&LightDesc {
        name: Some("sun".into()),
        kind: LightKind::Directional,
        color: [1.0, 0.95, 0.85],
        intensity: 3.0,
        range: None,
    });
    // The sun 50° high from the south-east (a directional light shines down its node's −Z).
    let sun_dir = Vec3::new(-0.45, -0.77, 0.45).normalize();
    roots.push(b.add_node(&NodeDesc {
        light: Some(sun),
        rotation: Some(look(sun_dir)),
        ..NodeDesc::default()
    }));
    let cam = b.add_perspective_camera("camera", 50f32.to_radians(), Some(1.0), 0.05, Some(500.0));
    let eye = Vec3::new(0.0, 6.0, 14.0);
    roots.push(b.add_node(&NodeDesc {
        camera: Some(cam),
        translation: Some(eye.to_array()),
        rotation: Some(look(Vec3::new(0.0, 0.5, 0.0) - eye)),
        ..NodeDesc::default()
    }));
    b.add_scene(
        "scale",
        &roots,
        Some(json!({"environment": {"radiance": [0.3, 0.4, 0.6]}})),
    );
    let bin_name = format!("{}.bin", case.name);
    let (mut root, mut bin) = b.to_json(Some(&bin_name));
    if let Some(node) = instancing_node {
        add_gpu_instancing(&mut root, &mut bin, node, &centres);
    }
    let path = dir.join(format!("{}.gltf", case.name));
    write_files(&path, &root, Some((&bin_name, &bin)))?;
    Ok(path)
}

/// Gives `node` an `EXT_mesh_gpu_instancing` TRANSLATION accessor of `translations` (appended to
/// `bin`).
fn add_gpu_instancing(root: &mut Value, bin: &mut Vec<u8>, node: usize, translations: &[[f32; 3]]) {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let offset = bin.len();
    bin.extend(translations.iter().flatten().flat_map(|c| c.to_le_bytes()));
    let views = root["bufferViews"]
        .as_array_mut()
        .expect("the sphere has views");
    views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 12 * translations.len()}));
    let view = views.len() - 1;
    let accessors = root["accessors"]
        .as_array_mut()
        .expect("the sphere has accessors");
    accessors.push(json!({
        "bufferView": view, "componentType": 5126, "count": translations.len(), "type": "VEC3",
    }));
    let accessor = accessors.len() - 1;
    root["buffers"][0]["byteLength"] = json!(bin.len());
    root["nodes"][node]["extensions"] =
        json!({"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": accessor}}});
    for list in ["extensionsUsed", "extensionsRequired"] {
        match root[list].as_array_mut() {
            Some(a) => a.push(json!("EXT_mesh_gpu_instancing")),
            None => root[list] = json!(["EXT_mesh_gpu_instancing"]),
        }
    }
}

/// Bytes of every live device allocation.
fn device_bytes(ctx: &Context) -> u64 {
    ctx.memory_by_category().values().sum()
}

/// The process's peak resident set (`VmHWM`), bytes (0 where `/proc` has none).
fn peak_host_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

/// What one case measured.
struct Measured {
    unique: usize,
    instanced: usize,
    instances: usize,
    kept: u64,
    frame_s: f64,
    record_rate: f64,
}

fn measure(
    bench: &Bench,
    case: &Case,
    dir: &Path,
    opts: &Options,
    first: bool,
) -> Result<(Measured, Vec<Figure>)> {
    let (ctx, shaders) = (bench.ctx(), bench.shaders());
    let path = write_case(case, dir)?;
    let start = Instant::now();
    let (scene, _) = Scene::load(&path, &LoadOptions::default())?;
    let load_s = start.elapsed().as_secs_f64();
    let settings = IcSettings {
        width: opts.size,
        height: opts.size,
        ..IcSettings::preset(Preset::Default)
    };
    let before = device_bytes(ctx);
    let start = Instant::now();
    let mut gpu = GpuScene::new(ctx, &scene, None)?;
    gpu.set_time(&scene, 0.0)?;
    let mut rec = ctx.begin("scale.tlas")?;
    gpu.record_update(ctx, &mut rec)?;
    ctx.submit(rec)?.wait()?;
    let upload_s = start.elapsed().as_secs_f64();
    let kept = device_bytes(ctx) - before;
    let planned = gpu.stats().memory_need.total();
    let blas_ms = gpu.stats().blas.build_ms + gpu.stats().blas.compact_ms;
    if first {
        bench.warm_up_ic(&scene, &mut gpu, settings.clone())?;
    }
    let (out, stats) = render_ic(ctx, shaders, &scene, &mut gpu, &settings, &mut |_| {})?;
    drop(gpu);
    let rays: u64 = out.rays.values().sum();
    let record_rate = stats.record_rays as f64 / stats.record_pass_s.max(1e-9);
    let m = Measured {
        unique: scene.triangle_count(),
        instanced: scene.instanced_triangle_count(),
        instances: scene.instances.len(),
        kept,
        frame_s: out.time_s,
        record_rate,
    };
    let peak = peak_host_bytes();
    println!(
        "{:<36} {:>10} {:>11} {:>7.2} {:>7.2} {:>9.0} {:>9.1} {:>9.1} {:>8.1} {:>7.2} {:>7} {:>8.3} {:>8.3}",
        case.name,
        m.unique,
        m.instanced,
        load_s,
        upload_s,
        blas_ms,
        planned as f64 / (1 << 20) as f64,
        kept as f64 / (1 << 20) as f64,
        peak as f64 / (1 << 20) as f64,
        m.frame_s,
        stats.records,
        record_rate / 1e6,
        rays as f64 / m.frame_s / 1e6,
    );
    let c = case.name.as_str();
    let figures = vec![
        Figure::new(c, "unique_triangles", m.unique as f64, "triangles"),
        Figure::new(c, "instanced_triangles", m.instanced as f64, "triangles"),
        Figure::new(c, "instances", m.instances as f64, "instances"),
        Figure::new(c, "load_s", load_s, "s"),
        Figure::new(c, "upload_s", upload_s, "s"),
        Figure::new(c, "blas_gpu_ms", blas_ms, "ms"),
        Figure::new(c, "device_bytes_planned", planned as f64, "B"),
        Figure::new(c, "device_bytes_kept", kept as f64, "B"),
        Figure::new(c, "peak_host_bytes", peak as f64, "B"),
        Figure::new(c, "frame_s", m.frame_s, "s"),
        Figure::new(c, "records", stats.records as f64, "records"),
        Figure::new(c, "record_mrays_per_s", record_rate / 1e6, "Mrays/s"),
        Figure::new(
            c,
            "frame_mrays_per_s",
            rays as f64 / m.frame_s / 1e6,
            "Mrays/s",
        ),
    ];
    Ok((m, figures))
}

/// The lowest earlier value of `case`/`metric` of this bench on `device` in `bench/results.csv`.
fn best_earlier(device: &str, case: &str, metric: &str) -> Option<f64> {
    let text = std::fs::read_to_string(crate::root().join("bench/results.csv")).ok()?;
    text.lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            // date, commit, device, bench, case, metric, value, unit.
            (f.len() == 8 && f[2] == device && f[3] == "scale" && f[4] == case && f[5] == metric)
                .then(|| f[6].parse::<f64>().ok())
                .flatten()
        })
        .reduce(f64::min)
}

pub fn run(args: &[&str]) -> Result<()> {
    let opts = parse(args)?;
    let bench = Bench::new("scale")?;
    let dir = std::env::temp_dir().join(format!("radcache-bench-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    println!(
        "device: {}; {}², default preset; sizes in MiB, times in s (blas: GPU ms), rates in Mrays/s",
        bench.device(),
        opts.size
    );
    println!(
        "{:<36} {:>10} {:>11} {:>7} {:>7} {:>9} {:>9} {:>9} {:>8} {:>7} {:>7} {:>8} {:>8}",
        "case",
        "unique",
        "instanced",
        "load",
        "upload",
        "blas ms",
        "planned",
        "kept",
        "host pk",
        "frame",
        "records",
        "rec rate",
        "rate"
    );
    let mut figures = Vec::new();
    let mut measured: Vec<(String, Measured)> = Vec::new();
    for (k, case) in cases(&opts).iter().enumerate() {
        let (m, f) = measure(&bench, case, &dir, &opts, k == 0)?;
        figures.extend(f);
        measured.push((case.name.clone(), m));
    }
    let _ = std::fs::remove_dir_all(&dir);
    let get = |name: &str| measured.iter().find(|(n, _)| n == name).map(|(_, m)| m);
    let mut held = Vec::new();
    if let (Some(single), Some(big)) = (get("unique_82k"), get("unique_1m")) {
        let per_triangle = big.kept as f64 / big.unique as f64;
        println!(
            "\nunique_1m: {per_triangle:.1} device bytes per unique triangle; record ray rate {:.2}× \
             the 82k sphere's",
            big.record_rate / single.record_rate
        );
        figures.push(Figure::new(
            "unique_1m",
            "record_rate_vs_82k",
            big.record_rate / single.record_rate,
            "ratio",
        ));
        figures.push(Figure::new(
            "unique_1m",
            "device_bytes_per_unique_triangle",
            per_triangle,
            "B",
        ));
        held.push((
            "unique_1m",
            "device_bytes_per_unique_triangle",
            per_triangle,
        ));
        for (name, m) in measured.iter().filter(|(_, m)| m.instances > 2) {
            let per_instance =
                (m.kept as f64 - single.kept as f64) / (m.instances - single.instances) as f64;
            let (frame, rate) = (
                m.frame_s / single.frame_s,
                m.record_rate / single.record_rate,
            );
            println!(
                "{name}: frame {frame:.2}× and record ray rate {rate:.2}× the single sphere's; \
                 {per_instance:.0} device bytes per added instance"
            );
            figures.push(Figure::new(name, "frame_vs_single", frame, "ratio"));
            figures.push(Figure::new(name, "record_rate_vs_single", rate, "ratio"));
            figures.push(Figure::new(
                name,
                "device_bytes_per_instance",
                per_instance,
                "B",
            ));
            if name.ends_with("x121_nodes") {
                held.push((
                    "instanced_82k_x121_nodes",
                    "device_bytes_per_instance",
                    per_instance,
                ));
            }
        }
    }
    // The device as `bench/results.csv` writes it (its commas made semicolons).
    let device = bench.device().replace(',', ";");
    let earlier: Vec<Option<f64>> = held
        .iter()
        .map(|(case, metric, _)| best_earlier(&device, case, metric))
        .collect();
    bench.finish(&figures)?;
    for ((case, metric, value), best) in held.iter().zip(earlier) {
        if let Some(best) = best {
            anyhow::ensure!(
                *value <= GROWTH * best,
                "{case} {metric}: {value:.1} is more than {:.0} % above the best earlier {best:.1}",
                (GROWTH - 1.0) * 100.0
            );
        }
    }
    Ok(())
}
