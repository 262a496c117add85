//! Error metrics between a reference and a candidate image (linear RGB beauty only).
//!
//! Population: a pixel is *non-finite* if any of its three channels is NaN or ±inf. Non-finite
//! pixels are counted per image and excluded — from both images — from every metric except
//! FLIP (see [`crate::flip`]), so one bad pixel does not turn the other figures into NaN/inf.
//! With `N` pixels finite in both and channels `k ∈ {R, G, B}`:
//!
//! - `rmse = sqrt(Σ (c−r)² / 3N)`
//! - `relmse = Σ (c−r)² / (r² + 0.01) / 3N`
//! - `mae = Σ |c−r| / 3N`
//! - `block_rmse`: the image is cut into 8×8-pixel blocks from the top-left corner; blocks at
//!   the right and bottom edges are partial and use the pixels that exist. Each block's mean
//!   (over its compared pixels) is taken per channel in both images; `block_rmse` is the RMSE of
//!   those means over blocks and channels, every block weighing the same whatever its size.
//!   Blocks without compared pixels are left out. This shows low-frequency bias (cache
//!   blotches) that per-pixel noise hides.
//! - `mean_ratio[k] = mean(c_k) / mean(r_k)`; defined as 1 when both means are 0 and as ±inf
//!   when only the reference mean is 0 (serialised to JSON as `null`).
//! - `flip`: mean LDR FLIP, `None` when unavailable.
//!
//! When no pixel is compared (N = 0) the error figures and ratios are NaN, which
//! [`crate::Thresholds::check`] reports as violations.

use std::fmt;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::flip::mean_flip;
use crate::image::Image;

/// Side of the square blocks of [`Metrics::block_rmse`], in pixels.
pub const BLOCK_SIZE: u32 = 8;

/// The result of [`compare`]. See the module docs for definitions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Metrics {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Pixels finite in both images: the population of all metrics but FLIP.
    pub pixels_compared: u64,
    /// Root mean squared error.
    pub rmse: f64,
    /// Relative mean squared error, `(c−r)² / (r² + 0.01)`.
    pub relmse: f64,
    /// Mean absolute error.
    pub mae: f64,
    /// RMSE between 8×8 block means.
    pub block_rmse: f64,
    /// `mean(candidate) / mean(reference)` per channel (R, G, B).
    pub mean_ratio: [f64; 3],
    /// Mean LDR FLIP on the sRGB-encoded images; `None` when unavailable.
    pub flip: Option<f64>,
    /// Non-finite pixels in the candidate.
    pub nonfinite_candidate: u64,
    /// Non-finite pixels in the reference.
    pub nonfinite_reference: u64,
}

impl Metrics {
    /// `max_k |mean_ratio[k] − 1|` (NaN if any ratio is NaN).
    pub fn max_mean_ratio_dev(&self) -> f64 {
        self.mean_ratio
            .iter()
            .map(|r| (r - 1.0).abs())
            .fold(0.0, |acc: f64, d| if d.is_nan() { d } else { acc.max(d) })
    }
}

/// Per-block running sums.
#[derive(Clone, Copy, Default)]
struct BlockSums {
    reference: [f64; 3],
    candidate: [f64; 3],
    count: u64,
}

/// Compares `candidate` against `reference`; errors when their sizes differ.
pub fn compare(reference: &Image, candidate: &Image) -> Result<Metrics> {
    let (width, height) = (reference.width(), reference.height());
    if (width, height) != (candidate.width(), candidate.height()) {
        return Err(Error::SizeMismatch {
            reference: (width, height),
            candidate: (candidate.width(), candidate.height()),
        });
    }

    let blocks_x = width.div_ceil(BLOCK_SIZE) as usize;
    let blocks_y = height.div_ceil(BLOCK_SIZE) as usize;
    let mut blocks = vec![BlockSums::default(); blocks_x * blocks_y];
    let (mut squared, mut relative, mut absolute) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut sum_ref, mut sum_cand) = ([0.0_f64; 3], [0.0_f64; 3]);
    let (mut compared, mut bad_ref, mut bad_cand) = (0_u64, 0_u64, 0_u64);

    let pixels = reference
        .rgb()
        .chunks_exact(3)
        .zip(candidate.rgb().chunks_exact(3));
    for (index, (r, c)) in pixels.enumerate() {
        let r_ok = r.iter().all(|v| v.is_finite());
        let c_ok = c.iter().all(|v| v.is_finite());
        bad_ref += u64::from(!r_ok);
        bad_cand += u64::from(!c_ok);
        if !(r_ok && c_ok) {
            continue;
        }
        compared += 1;
        let (x, y) = (index % width as usize, index / width as usize);
        let block = &mut blocks[(y / BLOCK_SIZE as usize) * blocks_x + x / BLOCK_SIZE as usize];
        block.count += 1;
        for k in 0..3 {
            let (rv, cv) = (f64::from(r[k]), f64::from(c[k]));
            let d = cv - rv;
            squared += d * d;
            relative += d * d / (rv * rv + 0.01);
            absolute += d.abs();
            sum_ref[k] += rv;
            sum_cand[k] += cv;
            block.reference[k] += rv;
            block.candidate[k] += cv;
        }
    }

    let samples = 3.0 * compared as f64;
    let (mut block_squared, mut block_count) = (0.0_f64, 0_u64);
    for block in blocks.iter().filter(|b| b.count > 0) {
        let n = block.count as f64;
        for k in 0..3 {
            let d = block.candidate[k] / n - block.reference[k] / n;
            block_squared += d * d;
        }
        block_count += 1;
    }
    let mean_ratio = std::array::from_fn(|k| {
        if compared == 0 {
            f64::NAN
        } else {
            ratio(sum_cand[k], sum_ref[k])
        }
    });

    Ok(Metrics {
        width,
        height,
        pixels_compared: compared,
        rmse: (squared / samples).sqrt(),
        relmse: relative / samples,
        mae: absolute / samples,
        block_rmse: (block_squared / (3.0 * block_count as f64)).sqrt(),
        mean_ratio,
        flip: mean_flip(reference, candidate),
        nonfinite_candidate: bad_cand,
        nonfinite_reference: bad_ref,
    })
}

/// `candidate / reference` for channel sums (equal to the ratio of means).
fn ratio(candidate: f64, reference: f64) -> f64 {
    if reference != 0.0 {
        candidate / reference
    } else if candidate == 0.0 {
        1.0
    } else {
        f64::INFINITY.copysign(candidate)
    }
}

impl fmt::Display for Metrics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pixels = u64::from(self.width) * u64::from(self.height);
        writeln!(
            f,
            "{:<18} {}x{} ({} pixels, {} compared)",
            "image", self.width, self.height, pixels, self.pixels_compared
        )?;
        writeln!(f, "{:<18} {:.6e}", "RMSE", self.rmse)?;
        writeln!(f, "{:<18} {:.6e}", "relMSE", self.relmse)?;
        writeln!(f, "{:<18} {:.6e}", "MAE", self.mae)?;
        writeln!(f, "{:<18} {:.6e}", "block RMSE (8x8)", self.block_rmse)?;
        let [r, g, b] = self.mean_ratio;
        writeln!(f, "{:<18} R {r:.6}  G {g:.6}  B {b:.6}", "mean ratio c/r")?;
        match self.flip {
            Some(flip) => writeln!(f, "{:<18} {flip:.6}", "FLIP (LDR mean)")?,
            None => writeln!(f, "{:<18} n/a", "FLIP (LDR mean)")?,
        }
        write!(
            f,
            "{:<18} candidate {}, reference {}",
            "non-finite pixels", self.nonfinite_candidate, self.nonfinite_reference
        )
    }
}
