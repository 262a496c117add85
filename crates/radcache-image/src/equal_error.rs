//! The path tracer's time to the same error, for the convergence report (`radcache
//! convergence`) and `cargo xtask bench ic` alike: the reference's own noise, the path tracer's
//! time to reach an error (log–log interpolation between its measured points), and the Pareto
//! front of error against time. Free of the GPU.
//!
//! Error model: the path tracer is unbiased, so its expected relMSE against the true image is
//! `c / spp`. A reference rendered by the path tracer with `S` spp adds its own independent noise
//! `e_ref = c / S` to every relMSE measured against it, so a point's own error is
//! `relMSE − e_ref`; `c` is the median over the path tracer's points of
//! `relMSE_i / (1/spp_i + 1/S)`. A reference of unknown spp is taken as noise-free (`e_ref = 0`).

/// One measured point of the path tracer's ladder, as the interpolation sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PtPoint {
    /// Samples per pixel.
    pub spp: u32,
    /// Wall time of the frame, s.
    pub time_s: f64,
    /// Own relMSE (measured relMSE less the reference's noise).
    pub error: f64,
}

/// The path tracer's time to reach an error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Time in seconds.
    pub time_s: f64,
    /// The error lies outside the measured points' range: the time comes from the slope −1
    /// extrapolation (relMSE ∝ 1/time) through the nearest measured point.
    pub extrapolated: bool,
}

/// The median of `values` (the mean of the two middle values for an even count); `None` when
/// empty or when a value is not finite.
pub fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    Some(if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    })
}

/// The constant `c` of `relMSE = c/spp + c/S` fitted to the path tracer's measured points
/// `(spp, relMSE)` against a reference of `reference_spp` samples (`None`: noise-free): the
/// median of `relMSE_i / (1/spp_i + 1/S)`.
pub fn noise_constant(points: &[(u32, f64)], reference_spp: Option<u32>) -> Option<f64> {
    let inv_ref = reference_spp.map_or(0.0, |s| 1.0 / f64::from(s.max(1)));
    let estimates: Vec<f64> = points
        .iter()
        .map(|&(spp, relmse)| relmse / (1.0 / f64::from(spp.max(1)) + inv_ref))
        .collect();
    median(&estimates)
}

/// The reference's own relMSE `c / S` (0 for a reference of unknown spp or without a fit).
pub fn reference_noise(c: Option<f64>, reference_spp: Option<u32>) -> f64 {
    match (c, reference_spp) {
        (Some(c), Some(s)) => c / f64::from(s.max(1)),
        _ => 0.0,
    }
}

/// The path tracer's time to reach the own relMSE `target`, from its measured points.
///
/// The rule: points whose own error is not positive and finite are left out (their error is
/// within the reference's noise); the rest are taken in order of spp, `(t_i, e_i)`.
/// - `target ≥ e_0`: `t = t_0 · e_0 / target` (extrapolated when `target > e_0`);
/// - else, at the first `i` with `e_{i+1} ≤ target` (so `e_i > target`): interpolate linearly
///   in log–log, `ln t = ln t_i + (ln target − ln e_i)/(ln e_{i+1} − ln e_i) · (ln t_{i+1} − ln t_i)`;
/// - no such `i` (every point's error is above `target`): `t = t_last · e_last / target`,
///   extrapolated.
///
/// `None` when `target` is not positive and finite or no point is usable.
pub fn pt_time_to_match(points: &[PtPoint], target: f64) -> Option<Match> {
    if !(target.is_finite() && target > 0.0) {
        return None;
    }
    let mut usable: Vec<PtPoint> = points
        .iter()
        .copied()
        .filter(|p| p.error.is_finite() && p.error > 0.0 && p.time_s.is_finite() && p.time_s > 0.0)
        .collect();
    usable.sort_by_key(|p| p.spp);
    let first = *usable.first()?;
    if target >= first.error {
        return Some(Match {
            time_s: first.time_s * first.error / target,
            extrapolated: target > first.error,
        });
    }
    for pair in usable.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b.error <= target {
            let f = (target.ln() - a.error.ln()) / (b.error.ln() - a.error.ln());
            let ln_t = a.time_s.ln() + f * (b.time_s.ln() - a.time_s.ln());
            return Some(Match {
                time_s: ln_t.exp(),
                extrapolated: false,
            });
        }
    }
    let last = *usable.last()?;
    Some(Match {
        time_s: last.time_s * last.error / target,
        extrapolated: true,
    })
}

/// The Pareto front of `(time, error)` points, as indices in order of time: a point is on it
/// when no other point is at least as fast and at least as accurate and better in one of the two;
/// of exactly equal points the first listed stays. Points with a non-finite coordinate are left
/// out.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_finite() && points[i].1.is_finite())
        .collect();
    order.sort_by(|&i, &j| {
        let (a, b) = (points[i], points[j]);
        a.0.total_cmp(&b.0)
            .then(a.1.total_cmp(&b.1))
            .then(i.cmp(&j))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(spp: u32, time_s: f64, error: f64) -> PtPoint {
        PtPoint { spp, time_s, error }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[1.0, f64::NAN]), None);
    }

    #[test]
    fn noise_constant_and_reference_noise() {
        // relMSE = c/spp + c/S with c = 2, S = 8: 1 spp → 2.25, 2 spp → 1.25, 4 spp → 0.75.
        let points = [(1, 2.25), (2, 1.25), (4, 0.75)];
        let c = noise_constant(&points, Some(8)).unwrap();
        assert!(close(c, 2.0), "{c}");
        assert!(close(reference_noise(Some(c), Some(8)), 0.25));
        // Noise-free reference: relMSE·spp = 2.25, 2.5, 3 → median 2.5; no noise subtracted.
        assert!(close(noise_constant(&points, None).unwrap(), 2.5));
        assert_eq!(reference_noise(Some(2.5), None), 0.0);
    }

    #[test]
    fn interpolates_in_log_log_between_bracketing_points() {
        // (1 s, 0.1) and (4 s, 0.001): the log–log line has slope ln(4)/ln(0.01); at 0.01,
        // halfway in ln(error), the time is halfway in ln(time): 2 s.
        let points = [pt(1, 1.0, 0.1), pt(2, 4.0, 0.001)];
        let m = pt_time_to_match(&points, 0.01).unwrap();
        assert!(close(m.time_s, 2.0), "{m:?}");
        assert!(!m.extrapolated);
        // A measured point's own error gives its own time.
        let m = pt_time_to_match(&points, 0.001).unwrap();
        assert!(close(m.time_s, 4.0) && !m.extrapolated, "{m:?}");
        let m = pt_time_to_match(&points, 0.1).unwrap();
        assert!(close(m.time_s, 1.0) && !m.extrapolated, "{m:?}");
    }

    #[test]
    fn extrapolates_with_slope_minus_one_outside_the_points() {
        let points = [pt(4, 2.0, 0.05), pt(1, 0.5, 0.2), pt(2, 1.0, 0.1)];
        // Below the last (4 spp) point: 2 s · 0.05 / 0.01 = 10 s.
        let m = pt_time_to_match(&points, 0.01).unwrap();
        assert!(close(m.time_s, 10.0) && m.extrapolated, "{m:?}");
        // Above the first (1 spp) point: 0.5 s · 0.2 / 0.4 = 0.25 s.
        let m = pt_time_to_match(&points, 0.4).unwrap();
        assert!(close(m.time_s, 0.25) && m.extrapolated, "{m:?}");
    }

    #[test]
    fn takes_the_first_crossing_and_skips_unusable_points() {
        // Not monotonic: 0.2, 0.1, 0.15, 0.05. Target 0.12 first crosses between 1 and 2 spp:
        // f = ln(0.12/0.2)/ln(0.1/0.2), t = 1 · 2^f.
        let points = [
            pt(1, 1.0, 0.2),
            pt(2, 2.0, 0.1),
            pt(4, 4.0, 0.15),
            pt(8, 8.0, 0.05),
            pt(16, 16.0, -0.01),
        ];
        let m = pt_time_to_match(&points, 0.12).unwrap();
        let f = (0.12f64 / 0.2).ln() / (0.5f64).ln();
        assert!(close(m.time_s, 2f64.powf(f)), "{m:?}");
        // The 16-spp point (error within the reference's noise) is not used: below 0.05 the
        // extrapolation starts from the 8-spp point: 8 · 0.05 / 0.025 = 16 s.
        let m = pt_time_to_match(&points, 0.025).unwrap();
        assert!(close(m.time_s, 16.0) && m.extrapolated, "{m:?}");
        assert_eq!(pt_time_to_match(&points, 0.0), None);
        assert_eq!(pt_time_to_match(&points, f64::NAN), None);
        assert_eq!(pt_time_to_match(&[pt(1, 1.0, 0.0)], 0.1), None);
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_in_time_order() {
        let points = [
            (1.0, 0.5),      // 0: fastest
            (2.0, 0.6),      // 1: dominated by 0
            (3.0, 0.2),      // 2: on the front
            (3.0, 0.1),      // 3: same time as 2, better: dominates 2
            (5.0, 0.1),      // 4: same error as 3, slower: dominated
            (8.0, 0.01),     // 5: on the front
            (8.0, 0.01),     // 6: duplicate of 5: the first listed stays
            (f64::NAN, 0.0), // 7: not finite: left out
        ];
        assert_eq!(pareto_front(&points), vec![0, 3, 5]);
        assert!(pareto_front(&[]).is_empty());
    }
}
