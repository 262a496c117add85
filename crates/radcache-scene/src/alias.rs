//! Walker/Vose alias table: O(1) sampling of a discrete distribution.
//!
//! Built in O(n) with Vose's method (f64 arithmetic). For GPU upload use the plain arrays
//! [`AliasTable::prob`] and [`AliasTable::alias`] (plus [`AliasTable::pmf`] for the pdf):
//! with `u` uniform in `[0, 1)`, `x = u·n`, `i = min(⌊x⌋, n−1)`, pick `i` when `x − i < prob[i]`,
//! else `alias[i]`. [`AliasTable::sample`] is the CPU twin.

/// An alias table over `n` outcomes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AliasTable {
    /// Probability of keeping column `i` (else take `alias[i]`).
    pub prob: Vec<f32>,
    /// Alternative outcome of column `i`.
    pub alias: Vec<u32>,
    /// Normalized probability of each outcome.
    pub pmf: Vec<f32>,
    /// Sum of the input weights.
    pub total_weight: f64,
}

impl AliasTable {
    /// Builds the table; negative or non-finite weights count as zero. An all-zero (or empty)
    /// input yields an empty table.
    pub fn new(weights: &[f32]) -> AliasTable {
        let w: Vec<f64> = weights
            .iter()
            .map(|&x| {
                if x.is_finite() && x > 0.0 {
                    f64::from(x)
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = w.iter().sum();
        let n = w.len();
        if n == 0 || total <= 0.0 {
            return AliasTable::default();
        }
        let mut scaled: Vec<f64> = w.iter().map(|x| x * n as f64 / total).collect();
        let mut prob = vec![1.0f32; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(&l), Some(&g)) = (small.last(), large.last()) {
            small.pop();
            prob[l] = scaled[l] as f32;
            alias[l] = g as u32;
            scaled[g] = (scaled[g] + scaled[l]) - 1.0;
            if scaled[g] < 1.0 {
                large.pop();
                small.push(g);
            }
        }
        // Leftovers (numerically ~1) keep prob = 1.
        AliasTable {
            prob,
            alias,
            pmf: w.iter().map(|x| (x / total) as f32).collect(),
            total_weight: total,
        }
    }

    /// Number of outcomes (0 for an empty table).
    pub fn len(&self) -> usize {
        self.prob.len()
    }

    /// True when there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.prob.is_empty()
    }

    /// Samples an outcome from one uniform number `u ∈ [0, 1)`; returns `(index, pmf)`, or `None`
    /// for an empty table.
    pub fn sample(&self, u: f32) -> Option<(usize, f32)> {
        let n = self.prob.len();
        if n == 0 {
            return None;
        }
        let x = f64::from(u.clamp(0.0, 1.0)) * n as f64;
        let i = (x as usize).min(n - 1);
        let frac = (x - i as f64) as f32;
        let k = if frac < self.prob[i] {
            i
        } else {
            self.alias[i] as usize
        };
        Some((k, self.pmf[k]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_the_distribution() {
        let weights = [1.0, 0.0, 3.0, 0.5, 5.5];
        let table = AliasTable::new(&weights);
        let mut counts = [0usize; 5];
        let n = 200_000;
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let (i, pmf) = table.sample(u).unwrap();
            assert!((pmf - weights[i] / 10.0).abs() < 1e-6);
            counts[i] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let expected = weights[i] / 10.0;
            assert!((c as f32 / n as f32 - expected).abs() < 2e-3, "{i}: {c}");
        }
        assert!(AliasTable::new(&[0.0, 0.0]).sample(0.5).is_none());
    }
}
