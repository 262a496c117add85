//! The sampling error of a frame's mean over its sub-frames, for adaptive anti-aliasing
//! ([`crate::AntiAliasing`], docs/cache-frame.md §7.1).
//!
//! Each pixel's sub-frames are `n` samples `l_i` of its box-filtered radiance (jittered
//! positions, direct-light samples); the records are the same in all of them. With the sums
//! `S = Σ l_i` and `Q = Σ l_i²` per channel, the sample variance is `s² = (Q − S²/n)/(n − 1)` and
//! the variance of the mean of `n` independent samples `s²/n`. Divided by `m² + 0.01`
//! (`m = S/n`) and averaged over pixels and channels, as `radcache compare`'s relMSE, it
//! estimates the relMSE that the sub-frame sampling leaves in the image. The jitters are not
//! independent (the R2 sequence in antithetic pairs: their means converge faster than `1/n`), so
//! for edges it is an overestimate: 4.5× on the Cornell box at 48²
//! (tests/tests/ic_anti_aliasing.rs), a frame stops later than it needs to, never earlier. (With
//! the plain sequence it was 2.9×, and the difference of the even and odd sub-frames' means
//! overestimated more, 5.2×: each half is a sparser set of the sequence.)

/// The relMSE offset, as `radcache_image::Metrics::relmse`.
const REL_EPS: f64 = 0.01;

/// The estimated sampling relMSE of the mean image from each pixel's sums `(Σl rgb, n)` and
/// `(Σl² rgb, ·)`. Pixels with fewer than two samples, or non-finite sums, count as 0 (they are
/// in the mean's denominator: the estimate is per image pixel).
pub fn sampling_relmse(sums: &[[f32; 4]], squares: &[[f32; 4]]) -> f64 {
    if sums.is_empty() {
        return 0.0;
    }
    let total: f64 = sums
        .iter()
        .zip(squares)
        .filter(|(s, _)| s[3] >= 2.0)
        .map(|(s, q)| relative_variance(s, q) / f64::from(s[3]))
        .sum();
    total / sums.len() as f64
}

/// The sub-frames to shade next, from `done` with the estimate `estimate` against `target`:
/// as many as `1/n` predicts with 10 % to spare, at least one more, at most `max`.
pub fn next_sub_frames(done: u32, estimate: f64, target: f64, max: u32) -> u32 {
    let wanted = (1.1 * f64::from(done) * estimate / target).ceil();
    let wanted = if wanted.is_finite() {
        wanted.min(f64::from(u32::MAX)) as u32
    } else {
        max
    };
    wanted.max(done + 1).min(max)
}

/// Each pixel's relative variance per sample, `(1/3) Σ_c s_c² / (m_c² + 0.01)` from its sums
/// (0 with fewer than two samples or non-finite sums): its term of [`sampling_relmse`] is this
/// over its sample count.
fn relative_variance(s: &[f32; 4], q: &[f32; 4]) -> f64 {
    let n = f64::from(s[3]);
    if n < 2.0 {
        return 0.0;
    }
    let mut v = 0.0;
    for c in 0..3 {
        let (sum, sq) = (f64::from(s[c]), f64::from(q[c]));
        let mean = sum / n;
        let term = ((sq - sum * mean) / (n - 1.0)).max(0.0) / (mean * mean + REL_EPS);
        if term.is_finite() {
            v += term;
        }
    }
    v / 3.0
}

/// The mean of the pixels' sample counts (the `w` of each pixel's sums).
pub fn mean_count(sums: &[[f32; 4]]) -> f64 {
    if sums.is_empty() {
        return 0.0;
    }
    sums.iter().map(|s| f64::from(s[3])).sum::<f64>() / sums.len() as f64
}

/// What per-pixel adaptive anti-aliasing shades next (docs/cache-frame.md §7.2).
#[derive(Debug, Clone, PartialEq)]
pub struct PixelPlan {
    /// Per pixel (row-major), 1 where the next sub-frames shade it, else 0.
    pub mask: Vec<u32>,
    /// Pixels with a 1.
    pub active: usize,
    /// The sub-frame count to shade up to (exclusive end of the next batch).
    pub next: u32,
}

/// The pixels that still need samples after `done` sub-frames, and how far to shade them,
/// from each pixel's sums `(Σl rgb, n)` and `(Σl² rgb, ·)` of a `width × height` frame.
///
/// The image's sampling relMSE is `(1/P) Σ_p v_p / n_p` ([`sampling_relmse`]; `v_p` the
/// pixel's relative variance per sample). For a given total of samples it is smallest with
/// `n_p ∝ √v_p` (Lagrange), which meets `target` at `n_p = √v_p · Σ_q √v_q / (P · target)`. A
/// pixel is shaded on while that is above the samples it has. `v_p` is the largest of its 3×3
/// neighbourhood's: a pixel whose few samples happened to agree beside an edge or a noisy
/// neighbour keeps going, and the estimate errs toward more samples. The batch ends at the
/// smallest count that brings the image's predicted estimate to `target` with 10 % to spare:
/// each active pixel's own term falling as `1/n` while it is shaded, the others' staying
/// (at least `done + 1`, at most `max`; the estimates are remade after each batch).
pub fn plan_pixels(
    sums: &[[f32; 4]],
    squares: &[[f32; 4]],
    width: u32,
    height: u32,
    done: u32,
    target: f64,
    max: u32,
) -> PixelPlan {
    let (w, h) = (width as usize, height as usize);
    let pixels = (w * h).min(sums.len()).min(squares.len());
    let own: Vec<f64> = (0..pixels)
        .map(|i| relative_variance(&sums[i], &squares[i]))
        .collect();
    let mut dilated = vec![0.0f64; pixels];
    for (i, d) in dilated.iter_mut().enumerate() {
        let (x, y) = (i % w, i / w);
        for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
            for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                if let Some(&v) = own.get(ny * w + nx) {
                    *d = d.max(v);
                }
            }
        }
    }
    let root_sum: f64 = dilated.iter().map(|v| v.sqrt()).sum();
    let scale = if target > 0.0 && pixels > 0 {
        root_sum / (pixels as f64 * target)
    } else {
        f64::INFINITY
    };
    let mut mask = vec![0u32; w * h];
    let mut active = 0usize;
    for i in 0..pixels {
        if dilated[i].sqrt() * scale > f64::from(sums[i][3]) {
            mask[i] = 1;
            active += 1;
        }
    }
    // The image's estimate once the active pixels have `next` samples (monotone in `next`).
    let predicted = |next: u32| -> f64 {
        let total: f64 = (0..pixels)
            .filter(|&i| own[i] > 0.0)
            .map(|i| {
                let n = f64::from(sums[i][3]);
                let n = if mask[i] == 1 {
                    n.max(f64::from(next))
                } else {
                    n
                };
                own[i] / n
            })
            .sum();
        total / pixels.max(1) as f64
    };
    let (mut lo, mut hi) = (done.saturating_add(1).min(max), max);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if predicted(mid) <= target / 1.1 {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    PixelPlan {
        mask,
        active,
        next: lo,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sums `(Σl, n)` and `(Σl², ·)` of a pixel's samples.
    fn moments(samples: &[[f32; 3]]) -> ([f32; 4], [f32; 4]) {
        let mut s = [0.0; 4];
        let mut q = [0.0; 4];
        for l in samples {
            for c in 0..3 {
                s[c] += l[c];
                q[c] += l[c] * l[c];
            }
            s[3] += 1.0;
        }
        (s, q)
    }

    #[test]
    fn constant_pixels_have_no_sampling_error() {
        let (s, q) = moments(&[[0.5, 1.0, 2.0]; 8]);
        assert!(sampling_relmse(&[s; 4], &[q; 4]) < 1e-12);
    }

    #[test]
    fn an_edge_pixel_gives_the_variance_of_its_mean() {
        // Half the samples 1, half 0: s² = n/(4(n−1)), variance of the mean s²/n, mean 0.5 →
        // divided by 0.26; one such pixel among four.
        let n = 8.0;
        let samples: Vec<[f32; 3]> = (0..8)
            .map(|i| if i % 2 == 0 { [1.0; 3] } else { [0.0; 3] })
            .collect();
        let (s, q) = moments(&samples);
        let flat = moments(&[[0.5; 3]; 8]);
        let expected = n / (4.0 * (n - 1.0)) / n / 0.26 / 4.0;
        let got = sampling_relmse(&[s, flat.0, flat.0, flat.0], &[q, flat.1, flat.1, flat.1]);
        assert!((got - expected).abs() < 1e-9 * expected, "{got}");
    }

    #[test]
    fn independent_samples_give_the_variance_of_the_mean() {
        // Uniform samples on [10, 12]: σ² = 1/3, mean 11 → σ²/n / 121.01 (a mean far from 0, so
        // that its own noise in the normalisation does not matter).
        let mut state = 12345u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            10.0 + ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0
        };
        for n in [8usize, 9, 32] {
            let (all, squares): (Vec<_>, Vec<_>) = (0..20_000)
                .map(|_| {
                    let v: Vec<[f32; 3]> =
                        (0..n).map(|_| [uniform(), uniform(), uniform()]).collect();
                    moments(&v)
                })
                .unzip();
            let got = sampling_relmse(&all, &squares);
            let expected = 1.0 / 3.0 / n as f64 / 121.01;
            assert!(
                (got / expected - 1.0).abs() < 0.03,
                "n = {n}: {got} against {expected}"
            );
        }
    }

    #[test]
    fn bad_pixels_and_single_samples_count_as_zero() {
        let nan = [f32::NAN, 0.0, 0.0, 8.0];
        let one = [1.0, 1.0, 1.0, 1.0];
        assert_eq!(sampling_relmse(&[nan, one], &[nan, one]), 0.0);
        assert_eq!(sampling_relmse(&[], &[]), 0.0);
    }

    #[test]
    fn pixels_with_noise_go_on_and_flat_ones_stop() {
        // An 8×8 frame after 8 sub-frames: one pixel alternates 0 and 1 (an edge), the rest is
        // flat. The edge and its 3×3 neighbours go on; every other pixel stops.
        let (w, h) = (8u32, 8u32);
        let flat = moments(&[[0.5; 3]; 8]);
        let edge_samples: Vec<[f32; 3]> = (0..8)
            .map(|i| if i % 2 == 0 { [1.0; 3] } else { [0.0; 3] })
            .collect();
        let edge = moments(&edge_samples);
        let mut sums = vec![flat.0; 64];
        let mut squares = vec![flat.1; 64];
        sums[3 * 8 + 3] = edge.0;
        squares[3 * 8 + 3] = edge.1;
        let plan = plan_pixels(&sums, &squares, w, h, 8, 5e-4, 64);
        for y in 0..8usize {
            for x in 0..8usize {
                let near = x.abs_diff(3) <= 1 && y.abs_diff(3) <= 1;
                assert_eq!(plan.mask[y * 8 + x], u32::from(near), "pixel ({x}, {y})");
            }
        }
        assert_eq!(plan.active, 9);
        // v = (2/7)/0.26 ≈ 1.099 over the 9 pixels: each wants √v · 9√v / (64 · 5e-4) ≈ 309
        // samples; the image's estimate, the edge's v/n/64, meets 5e-4/1.1 from n = 38.
        assert_eq!(plan.next, 38);
        assert_eq!(plan_pixels(&sums, &squares, w, h, 8, 5e-4, 32).next, 32);
    }

    #[test]
    fn the_wanted_counts_follow_square_root_allocation() {
        // Two noisy pixels (v = 4 and v = 1, flat neighbours far away) in a 16×1 frame: with
        // n ∝ √v the counts that meet the target are √v · (Σ√v over every dilated pixel) /
        // (P · target). Pixel 2 (v = 4, dilated over 1…3) and pixel 12 (v = 1, over 11…13):
        // Σ√v = 3·2 + 3·1 = 9; at target 0.02 the wanted counts are 56.25 and 28.1.
        let frame = |n: usize| -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
            // Mean 0 (m² + 0.01 = 0.01) and sample variance 0.01·v from n samples ±a.
            let noisy = |v: f32| {
                let a = (0.01 * v * (n as f32 - 1.0) / n as f32).sqrt();
                let samples: Vec<[f32; 3]> = (0..n)
                    .map(|i| if i % 2 == 0 { [a; 3] } else { [-a; 3] })
                    .collect();
                moments(&samples)
            };
            let flat = moments(&vec![[0.0; 3]; n]);
            let (mut sums, mut squares) = (vec![flat.0; 16], vec![flat.1; 16]);
            (sums[2], squares[2]) = noisy(4.0);
            (sums[12], squares[12]) = noisy(1.0);
            (sums, squares)
        };
        let on =
            |plan: &PixelPlan| -> Vec<usize> { (0..16).filter(|&i| plan.mask[i] == 1).collect() };
        let target = 0.02;
        let (sums, squares) = frame(8);
        let plan = plan_pixels(&sums, &squares, 16, 1, 8, target, 64);
        assert_eq!(on(&plan), vec![1, 2, 3, 11, 12, 13]);
        // Both shaded on: (4 + 1)/(16 n) ≤ 0.02/1.1 from n = 17.2, so 18.
        assert_eq!(plan.next, 18);
        // At 32 samples pixel 12's neighbourhood (want 28.1) stops and pixel 2's goes on; the
        // estimate is already below the target, so one more sub-frame is the batch.
        let (sums, squares) = frame(32);
        let later = plan_pixels(&sums, &squares, 16, 1, 32, target, 64);
        assert_eq!(on(&later), vec![1, 2, 3]);
        assert_eq!(later.next, 33);
    }

    #[test]
    fn a_flat_frame_needs_no_more_samples() {
        let flat = moments(&[[0.25; 3]; 8]);
        let plan = plan_pixels(&[flat.0; 4], &[flat.1; 4], 2, 2, 8, 5e-4, 64);
        assert_eq!((plan.active, plan.mask), (0, vec![0; 4]));
    }

    #[test]
    fn the_next_count_reaches_the_target_within_the_limit() {
        assert_eq!(next_sub_frames(8, 2e-3, 5e-4, 64), 36);
        assert_eq!(next_sub_frames(8, 5.01e-4, 5e-4, 64), 9);
        assert_eq!(next_sub_frames(8, 1.0, 5e-4, 64), 64);
        assert_eq!(next_sub_frames(63, f64::INFINITY, 5e-4, 64), 64);
    }
}
