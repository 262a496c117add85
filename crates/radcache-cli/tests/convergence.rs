//! `radcache convergence` end to end on the Cornell box at a small size (lavapipe): the CSV holds
//! both ladders with measured points, its derived columns (own relMSE, the path tracer's time to
//! the same error, the speed-up, the Pareto front) follow from its own measured columns by the
//! documented rules, the plots are real images, the summary states the reference and the front;
//! bad input gives one clear error.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
mod common;
use common::{bin, cornell, fresh_path, radcache};

fn out_dir(name: &str) -> PathBuf {
    fresh_path("conv", name)
}

type Row = HashMap<String, String>;

fn read_csv(path: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(path).expect("points.csv");
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells.len(), header.len(), "row {line:?}");
            header
                .iter()
                .cloned()
                .zip(cells.iter().map(|c| c.to_string()))
                .collect()
        })
        .collect()
}

fn num(row: &Row, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column} = {:?} in {row:?}", row[column]))
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// The rule of the summary, written again here: PT points (spp, time, own error) with a positive
/// error, in order of spp; above the first point's error or below every point's, slope −1
/// through the nearest point (extrapolated); else log–log interpolation in the first pair that
/// brackets the target.
fn time_to_match(pt: &[(f64, f64, f64)], target: f64) -> Option<(f64, bool)> {
    if target <= 0.0 {
        return None;
    }
    let mut pts: Vec<(f64, f64, f64)> = pt.iter().copied().filter(|p| p.2 > 0.0).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (_, t0, e0) = *pts.first()?;
    if target >= e0 {
        return Some((t0 * e0 / target, target > e0));
    }
    for w in pts.windows(2) {
        let ((_, ta, ea), (_, tb, eb)) = (w[0], w[1]);
        if eb <= target {
            let f = (target / ea).ln() / (eb / ea).ln();
            return Some(((ta.ln() + f * (tb / ta).ln()).exp(), false));
        }
    }
    let (_, tl, el) = *pts.last()?;
    Some((tl * el / target, true))
}

#[test]
fn report_on_the_cornell_box_has_both_ladders_plots_and_consistent_ratios() {
    let dir = out_dir("cornell");
    let out = radcache(&[
        "convergence",
        &cornell(),
        "-o",
        &dir.display().to_string(),
        "--resolution",
        "32x32",
        "--quick",
        "--max-spp",
        "16",
        "--reference-spp",
        "256",
        "--frame",
        "1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "radcache failed: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let rows = read_csv(&dir.join("points.csv"));

    // Both ladders.
    let pt: Vec<&Row> = rows.iter().filter(|r| r["method"] == "path").collect();
    let ic: Vec<&Row> = rows.iter().filter(|r| r["method"] == "ic").collect();
    let spp: Vec<f64> = pt.iter().map(|r| num(r, "spp")).collect();
    assert_eq!(spp, [1.0, 2.0, 4.0, 8.0, 16.0]);
    assert!(pt.iter().all(|r| r["ladder"] == "spp"));
    let presets: Vec<&str> = ic
        .iter()
        .filter(|r| r["ladder"] == "preset")
        .map(|r| r["label"].as_str())
        .collect();
    assert_eq!(presets, ["draft", "default", "high"]);
    let count = |ladder: &str| ic.iter().filter(|r| r["ladder"] == ladder).count();
    assert!(count("accuracy") >= 2 && count("strata") >= 2, "{rows:?}");
    assert_eq!(ic.len(), 3 + count("accuracy") + count("strata"));
    // The accuracy sweep varies T&L's κ (the default weight) around the default preset's.
    let kappa = f64::from(radcache_cache::IcParams::default().kappa);
    let kappas: Vec<f64> = ic
        .iter()
        .filter(|r| r["ladder"] == "accuracy")
        .map(|r| num(r, "weight_param"))
        .collect();
    assert!(kappas.iter().any(|&k| k < kappa) && kappas.iter().any(|&k| k > kappa));
    assert!(ic.iter().all(|r| r["weight"] == "tl"));

    // Measured columns.
    for r in &rows {
        let relmse = num(r, "relmse");
        assert!(relmse.is_finite() && relmse > 0.0, "{r:?}");
        assert!(num(r, "wall_s") > 0.0 && num(r, "gpu_s") >= 0.0, "{r:?}");
        assert!(num(r, "rays") > 0.0, "{r:?}");
        assert!(num(r, "rmse") > 0.0 && num(r, "block_rmse") >= 0.0, "{r:?}");
    }
    // The path tracer's error falls with spp overall (relMSE ∝ 1/spp: ×1/16 expected).
    let first = num(pt[0], "relmse");
    let last = num(pt[pt.len() - 1], "relmse");
    assert!(
        last < first / 4.0,
        "PT relMSE {first} at 1 spp, {last} at 16 spp"
    );

    // Own relMSE: the same reference noise c/256 off every row, c the median of
    // relMSE/(1/spp + 1/256) over the path tracer's rows.
    let mut c: Vec<f64> = pt
        .iter()
        .map(|r| num(r, "relmse") / (1.0 / num(r, "spp") + 1.0 / 256.0))
        .collect();
    c.sort_by(f64::total_cmp);
    let e_ref = c[c.len() / 2] / 256.0;
    for r in &rows {
        let own = num(r, "own_relmse");
        assert!(
            close(num(r, "relmse") - own, e_ref, 1e-9),
            "{r:?}, e_ref {e_ref}"
        );
    }

    // The path tracer's time to match: recomputed from the CSV's own path tracer rows.
    let curve: Vec<(f64, f64, f64)> = pt
        .iter()
        .map(|r| (num(r, "spp"), num(r, "wall_s"), num(r, "own_relmse")))
        .collect();
    let mut ratios = 0;
    for r in &ic {
        match time_to_match(&curve, num(r, "own_relmse")) {
            Some((t, extrapolated)) => {
                let listed = num(r, "pt_time_to_match_s");
                assert!(close(listed, t, 1e-9), "{r:?}: expected {t}");
                assert_eq!(r["extrapolated"], extrapolated.to_string(), "{r:?}");
                let ratio = num(r, "speedup");
                assert!(close(ratio, listed / num(r, "wall_s"), 1e-12), "{r:?}");
                ratios += 1;
            }
            None => {
                assert_eq!(r["pt_time_to_match_s"], "", "{r:?}");
                assert_eq!(r["speedup"], "", "{r:?}");
            }
        }
    }
    assert!(ratios > 0, "no cache point has a speed-up: {rows:?}");
    for r in &pt {
        assert_eq!(r["speedup"], "", "{r:?}");
    }

    // The Pareto front over (wall time, relMSE), recomputed by pairwise dominance.
    let dominated = |i: usize| {
        let (ti, ei) = (num(&rows[i], "wall_s"), num(&rows[i], "relmse"));
        rows.iter().enumerate().any(|(j, r)| {
            let (tj, ej) = (num(r, "wall_s"), num(r, "relmse"));
            j != i && tj <= ti && ej <= ei && (tj < ti || ej < ei || j < i)
        })
    };
    let front: Vec<usize> = (0..rows.len()).filter(|&i| !dominated(i)).collect();
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r["pareto"], front.contains(&i).to_string(), "{r:?}");
    }
    assert!(!front.is_empty());

    // The summary: the reference and how it was made, the front, the ratios.
    let summary = std::fs::read_to_string(dir.join("summary.md")).expect("summary.md");
    assert!(summary.contains("Reference: rendered by this command with the path tracer at 256 spp"));
    let front_section = summary
        .split("## Pareto front")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("a Pareto front section");
    for &i in &front {
        assert!(
            front_section.contains(&format!("| {} |", rows[i]["label"])),
            "{} missing from the front:\n{front_section}",
            rows[i]["label"]
        );
    }
    assert!(
        summary.contains("speed-up") && summary.contains('×'),
        "{summary}"
    );
    assert!(dir.join("reference.exr").is_file());

    // The plots.
    let svg = std::fs::read_to_string(dir.join("error_vs_time.svg")).expect("the SVG");
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    for text in [
        "relMSE against the reference",
        "wall time",
        "path tracer",
        "IC presets",
    ] {
        assert!(svg.contains(text), "the SVG lacks {text:?}");
    }
    let file = std::fs::File::open(dir.join("error_vs_time.png")).expect("the PNG");
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("PNG data");
    assert_eq!((info.width, info.height), (960, 640));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let pixels: Vec<[u8; 3]> = buf[..info.buffer_size()]
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    let count = |c: [u8; 3]| pixels.iter().filter(|&&p| p == c).count();
    assert!(
        count([255, 255, 255]) > pixels.len() / 2,
        "mostly white background"
    );
    // The path tracer's series (black) and the presets' (red) are drawn, and text is there
    // (anti-aliased glyphs give many grey levels).
    assert!(count([0, 0, 0]) > 100 && count([214, 39, 40]) > 50);
    let greys = pixels
        .iter()
        .filter(|p| p[0] == p[1] && p[1] == p[2])
        .map(|p| p[0])
        .collect::<std::collections::BTreeSet<u8>>();
    assert!(greys.len() > 32, "{} grey levels", greys.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_missing_scene_is_one_clear_error() {
    let dir = out_dir("missing");
    let scene = dir.join("no-such-scene.gltf");
    let out = radcache(&[
        "convergence",
        &scene.display().to_string(),
        "-o",
        &dir.display().to_string(),
        "--quick",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("no-such-scene.gltf"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");

    let out = radcache(&["convergence", &cornell(), "-o", "/tmp/x", "--max-spp", "12"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("--max-spp"),
        "{stderr}"
    );

    // A font file that is not a font fails before any rendering, naming the file.
    let out = bin()
        .args(["convergence", &cornell(), "-o", &dir.display().to_string()])
        .env("RADCACHE_FONT", cornell())
        .output()
        .expect("running radcache");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("cornell.gltf") && stderr.contains("font"),
        "{stderr}"
    );
    assert!(
        !dir.exists(),
        "nothing is written before the inputs are checked"
    );
}
