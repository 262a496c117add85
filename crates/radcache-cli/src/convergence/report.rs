//! The files of `radcache convergence`: `points.csv` (every point) and `summary.md` (how it was
//! measured, the Pareto front, the cache against the path tracer).

use std::fmt::Write as _;

use super::ladder::{accuracy_of, preset_name, weight_name, Ladder, Point};
use radcache_image::equal_error::Match;

/// The CSV's header: one column per field, in order.
pub const CSV_HEADER: &str = "method,ladder,label,preset,weight,accuracy,weight_param,strata,spp,\
wall_s,gpu_s,rays,records,relmse,own_relmse,rmse,block_rmse,mae,flip,\
pt_time_to_match_s,extrapolated,speedup,pareto";

/// Everything the summary states besides the points.
#[derive(Debug, Clone)]
pub struct RunInfo {
    /// The scene file, as given.
    pub scene: String,
    /// Frame number and scene time, s.
    pub frame: (u32, f32),
    /// Image size.
    pub size: (u32, u32),
    /// The device's name.
    pub device: String,
    /// How the reference was obtained (one sentence).
    pub reference: String,
    /// The reference's spp, when known.
    pub reference_spp: Option<u32>,
    /// The path tracer's `c` of `relMSE = c/spp`.
    pub noise_constant: Option<f64>,
    /// The reference's own relMSE, `c/S`.
    pub reference_noise: f64,
    /// The cache's weight (`tl` or `ward`).
    pub weight: &'static str,
    /// Wall time of the whole run so far, s.
    pub total_s: f64,
}

fn opt<T: ToString>(v: Option<T>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

/// The CSV text: the header, then one row per point. Floats are written in Rust's shortest
/// round-trip form, so a reader recomputes the derived columns exactly.
pub fn csv(points: &[Point]) -> String {
    let mut text = format!("{CSV_HEADER}\n");
    for p in points {
        let ic = p.ic.as_ref();
        let m = &p.metrics;
        let row = [
            p.method().to_string(),
            p.ladder.name().to_string(),
            p.label.clone(),
            opt(ic.map(|(preset, _)| preset_name(*preset))),
            opt(ic.map(|(_, params)| weight_name(params.weight_kind))),
            opt(ic.map(|(_, params)| accuracy_of(params))),
            opt(ic.map(|(_, params)| params.weight_param())),
            opt(ic.map(|(_, params)| format!("{}x{}", params.strata_m, params.strata_n))),
            opt(p.spp),
            p.wall_s.to_string(),
            p.gpu_s.to_string(),
            p.rays.to_string(),
            opt(p.records),
            m.relmse.to_string(),
            p.own_relmse.to_string(),
            m.rmse.to_string(),
            m.block_rmse.to_string(),
            m.mae.to_string(),
            opt(m.flip),
            opt(p.matched.map(|x| x.time_s)),
            opt(p.matched.map(|x| x.extrapolated)),
            opt(p.speedup()),
            p.pareto.to_string(),
        ];
        text.push_str(&row.join(","));
        text.push('\n');
    }
    text
}

/// The Markdown summary.
/// The table cells of a time to the same error and its speed-up over `wall_s`.
fn match_cells(matched: Option<Match>, wall_s: f64) -> (String, String) {
    match matched {
        Some(m) => (
            format!(
                "{:.3}{}",
                m.time_s,
                if m.extrapolated {
                    " (extrapolated)"
                } else {
                    ""
                }
            ),
            format!("{:.2}×", m.time_s / wall_s),
        ),
        None => ("within the reference's noise".into(), "–".into()),
    }
}

pub fn summary(info: &RunInfo, points: &[Point]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Convergence: error against run time\n");
    let _ = writeln!(
        s,
        "- Scene: `{}`, frame {} (scene time {} s), {}×{} pixels",
        info.scene, info.frame.0, info.frame.1, info.size.0, info.size.1
    );
    let _ = writeln!(s, "- Device: {}", info.device);
    let _ = writeln!(s, "- Reference: {}", info.reference);
    let fit = match (info.noise_constant, info.reference_spp) {
        (Some(c), Some(spp)) => format!(
            "c = {c:.4e} (median over the path tracer's points of relMSE/(1/spp + 1/{spp})), \
             so the reference's own relMSE is c/{spp} = {:.4e}",
            info.reference_noise
        ),
        (Some(c), None) => format!(
            "c = {c:.4e} (median of relMSE·spp); the reference's spp is unknown, so it is \
             taken as noise-free (own relMSE = measured relMSE)"
        ),
        _ => "no fit (no path tracer point)".into(),
    };
    let _ = writeln!(
        s,
        "- Error model: the path tracer's relMSE falls as c/spp; {fit}. Each point's own relMSE \
         is its measured relMSE less the reference's (as `cargo xtask bench ic`)."
    );
    let _ = writeln!(
        s,
        "- Timing: wall = one whole frame from an empty state (set-up, passes created from the \
         already compiled shaders, rendering, read-back; a warm-up frame of each method took the \
         shader compilation); GPU = the sum of the frame's pass timestamps (drivers whose \
         timestamps miss asynchronous work, like lavapipe, under-count it). Ratios use wall time."
    );
    let _ = writeln!(
        s,
        "- Path tracer's time to the same error: log–log interpolation of (wall time, own \
         relMSE) between the measured path tracer points that bracket the cache point's own \
         relMSE (the first bracketing pair in spp order); outside them, slope −1 (relMSE ∝ \
         1/time) through the nearest point, marked *extrapolated*. Points whose own relMSE is \
         not positive (within the reference's noise) have none."
    );
    let weight = match info.weight {
        "ward" => "Ward's (`--weight ward`; the accuracy sweep varies a)",
        _ => "Tabellion–Lamorlette (`--weight tl`; the accuracy sweep varies κ = 1/a)",
    };
    let _ = writeln!(
        s,
        "- Cache weight: {weight}; sweeps at the default preset otherwise. {} points, {:.1} s \
         for the whole run\n",
        points.len(),
        info.total_s
    );

    let _ = writeln!(s, "## Pareto front (relMSE against wall time)\n");
    let _ = writeln!(
        s,
        "Points that no other point beats on both time and error, fastest first \
         (subtracting the reference's noise changes no order, so the front is the same on own \
         relMSE).\n"
    );
    let _ = writeln!(
        s,
        "| point | method | wall s | GPU s | relMSE | own relMSE |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    let mut front: Vec<&Point> = points.iter().filter(|p| p.pareto).collect();
    front.sort_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
    for p in front {
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.3} | {:.3e} | {:.3e} |",
            p.label,
            p.method(),
            p.wall_s,
            p.gpu_s,
            p.metrics.relmse,
            p.own_relmse
        );
    }

    let _ = writeln!(s, "\n## The cache against the path tracer\n");
    let _ = writeln!(
        s,
        "| IC point | ladder | wall s | GPU s | records | relMSE | own relMSE | FLIP | PT time to same relMSE (s) | speed-up |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for p in points.iter().filter(|p| p.ic.is_some()) {
        let (pt, ratio) = match_cells(p.matched, p.wall_s);
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.3} | {} | {:.3e} | {:.3e} | {} | {pt} | {ratio} |",
            p.label,
            p.ladder.name(),
            p.wall_s,
            p.gpu_s,
            opt(p.records),
            p.metrics.relmse,
            p.own_relmse,
            p.metrics.flip.map_or("–".into(), |f| format!("{f:.4}")),
        );
    }

    if points.iter().any(|p| p.ladder == Ladder::GlossyPaths) {
        let _ = writeln!(
            s,
            "\n## Glossy lobes: radiance records against per-pixel paths\n\n\
             The presets with the glossy lobes' indirect light from the radiance records (the \
             default) and the per-pixel paths' time to the same own relMSE, read from the \
             `glossy_paths` points as the path tracer's is from its ladder \
             (docs/radiance-caching.md §6).\n"
        );
        let _ = writeln!(
            s,
            "| preset | wall s | own relMSE | per-pixel paths: time to same relMSE (s) | speed-up |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|");
        for p in points.iter().filter(|p| p.ladder == Ladder::Preset) {
            let (t, ratio) = match_cells(p.matched_paths, p.wall_s);
            let _ = writeln!(
                s,
                "| {} | {:.3} | {:.3e} | {t} | {ratio} |",
                p.label, p.wall_s, p.own_relmse
            );
        }
    }
    let ic = points.iter().filter(|p| p.ic.is_some()).count();
    let extrapolated = points
        .iter()
        .filter(|p| p.matched.is_some_and(|m| m.extrapolated))
        .count();
    if extrapolated > 0 {
        let _ = writeln!(
            s,
            "\n{extrapolated} of {ic} cache points lie outside the path tracer's measured errors: \
             their times are extrapolated (a larger `--max-spp` measures them)."
        );
    }
    let _ = writeln!(s, "\n## The path tracer\n");
    let _ = writeln!(
        s,
        "| spp | wall s | GPU s | rays | relMSE | own relMSE | FLIP |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for p in points.iter().filter(|p| p.ic.is_none()) {
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} | {} | {:.3e} | {:.3e} | {} |",
            opt(p.spp),
            p.wall_s,
            p.gpu_s,
            p.rays,
            p.metrics.relmse,
            p.own_relmse,
            p.metrics.flip.map_or("–".into(), |f| format!("{f:.4}")),
        );
    }
    let _ = writeln!(
        s,
        "\nFiles: `points.csv` (every point), `error_vs_time.svg` and `error_vs_time.png` \
         (log–log relMSE against wall time, one series per ladder)."
    );
    s
}
