//! The sampling error of a frame's mean over its sub-frames, for adaptive anti-aliasing
//! ([`crate::AntiAliasing`], docs/cache-frame.md §7.1).
//!
//! Each pixel's sub-frames are `n` samples `l_i` of its box-filtered radiance (jittered
//! positions, direct-light samples); the records are the same in all of them. With the sums
//! `S = Σ l_i` and `Q = Σ l_i²` per channel, the sample variance is `s² = (Q − S²/n)/(n − 1)` and
//! the variance of the mean of `n` independent samples `s²/n`. Divided by `m² + 0.01`
//! (`m = S/n`) and averaged over pixels and channels, as `radcache compare`'s relMSE, it
//! estimates the relMSE that the sub-frame sampling leaves in the image. The jitters are not
//! independent (the R2 sequence: their means converge faster than `1/n`), so for edges it is an
//! overestimate: 2.9× on the Cornell box at 48² (tests/tests/ic_anti_aliasing.rs), a frame stops
//! later than it needs to, never earlier. (The difference of the even and odd sub-frames' means
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
    let mut total = 0.0f64;
    for (s, q) in sums.iter().zip(squares) {
        let n = f64::from(s[3]);
        if n < 2.0 {
            continue;
        }
        for c in 0..3 {
            let (sum, sq) = (f64::from(s[c]), f64::from(q[c]));
            let mean = sum / n;
            let variance = ((sq - sum * mean) / (n - 1.0)).max(0.0);
            let term = variance / n / (mean * mean + REL_EPS);
            if term.is_finite() {
                total += term;
            }
        }
    }
    total / (3.0 * sums.len() as f64)
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
    fn the_next_count_reaches_the_target_within_the_limit() {
        assert_eq!(next_sub_frames(8, 2e-3, 5e-4, 64), 36);
        assert_eq!(next_sub_frames(8, 5.01e-4, 5e-4, 64), 9);
        assert_eq!(next_sub_frames(8, 1.0, 5e-4, 64), 64);
        assert_eq!(next_sub_frames(63, f64::INFINITY, 5e-4, 64), 64);
    }
}
