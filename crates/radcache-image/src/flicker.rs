//! Temporal stability ("flicker") of a frame sequence.
//!
//! A sequence is `I_0 … I_{T−1}`: `T ≥ 2` frames of one size (linear RGB beauty). Its *pairs* are
//! the consecutive frames `(t, t+1)`, `t = 0 … T−2`, and its temporal differences are
//! `ΔI_t = I_{t+1} − I_t`, per pixel `p` and channel `c ∈ {R, G, B}`. Below, `Σ` runs over the
//! three channels of the pixels *counted* for the pair; arithmetic is in `f64`.
//!
//! # Against a reference ([`FlickerMode::Reference`])
//!
//! The reference `R_0 … R_{T−1}` (e.g. converged renders of the same frames) has the same length
//! and size. A pixel is counted when its beauty is finite in all of `I_t`, `I_{t+1}`, `R_t`,
//! `R_{t+1}`. Per pair:
//!
//! ```text
//! E_t = Σ (ΔI_t − ΔR_t)²        S_t = Σ (R_t² + R_{t+1}²) / 2        flicker_t = sqrt(E_t / S_t)
//! ```
//!
//! the RMS of the change the reference does not have (motion and lighting changes cancel),
//! relative to the RMS reference value. A candidate equal to the reference plus a per-frame
//! constant `o_t` scores `|o_{t+1} − o_t| / RMS(R)`. If `S_t = 0` (the reference is black at every
//! counted pixel) the candidate's own `S'_t = Σ (I_t² + I_{t+1}²) / 2` is the scale instead, and
//! if that is 0 too then `E_t = 0` and `flicker_t = 0`.
//!
//! # Without a reference ([`FlickerMode::Static`])
//!
//! A pixel is counted when its beauty is finite in `I_t` and `I_{t+1}` and it is *static*. Per
//! pair `E_t = Σ ΔI_t²`, `S_t = Σ (I_t² + I_{t+1}²) / 2`, `flicker_t = sqrt(E_t / S_t)`, and 0
//! when `S_t = 0` (then `E_t = 0` too). As `(b − a)² ≤ 2(a² + b²)` it lies in `[0, 2]`; a pixel
//! alternating between 1 and 3 scores `2 / √5`.
//!
//! *Static*: for every AOV layer among [`DEPTH`], [`NORMAL`] and [`ALBEDO`] that both frames carry
//! with the same channels, the pixel's layer vectors `a` (frame `t`) and `b` (frame `t+1`) are
//! equal, or finite with `‖b − a‖₂ ≤ τ · max(‖a‖₂, ‖b‖₂)`, `τ =` [`STATIC_TOLERANCE`] `= 10⁻³`:
//! the same surface is seen. The test is relative, so scene units do not matter, and wider than
//! `f16` rounding. Layers only one frame has are ignored. **Without such layers every finite pixel
//! counts, and the figure measures all change, motion included.**
//!
//! # Common to both
//!
//! - Overall `flicker = sqrt(Σ_t E_t / Σ_t S_t)` with the same fallbacks: pooled, so pairs weigh
//!   by their signal, not a mean of the `flicker_t`.
//! - Multiplying every beauty by a constant `k > 0` leaves every figure unchanged.
//! - A pixel with a NaN or ±inf beauty channel in any image of a pair is counted in that pair's
//!   `nonfinite` and left out; the figures are always finite. Overall `nonfinite = Σ_t nonfinite_t`.
//! - `static_fraction_t` = counted pixels / (width · height) (in reference mode every finite
//!   pixel counts); overall, counted pixels of all pairs / (pairs · width · height). Empty
//!   images give 0 everywhere.

use serde::Serialize;

use crate::error::{Error, Result};
use crate::image::{Image, ALBEDO, DEPTH, NORMAL};

/// Relative tolerance `τ` of the static-pixel test on AOV layers (see the module docs).
pub const STATIC_TOLERANCE: f64 = 1e-3;

/// How flicker is measured (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FlickerMode {
    /// Temporal differences against those of a reference sequence.
    Reference,
    /// Temporal differences over static pixels, without a reference.
    Static,
}

/// Flicker of one pair of consecutive frames.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlickerPair {
    /// Index of the first frame in the sequence.
    pub from: usize,
    /// Index of the second frame (`from + 1`).
    pub to: usize,
    /// `flicker_t`, a finite value ≥ 0.
    pub flicker: f64,
    /// Fraction of the pixels counted.
    pub static_fraction: f64,
    /// Pixels left out for a non-finite beauty value.
    pub nonfinite: u64,
}

/// The result of [`flicker`] or [`FlickerMeter::finish`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FlickerReport {
    /// Whether a reference sequence was used.
    pub mode: FlickerMode,
    /// Frames in the sequence.
    pub frames: usize,
    /// One entry per consecutive pair, in order.
    pub pairs: Vec<FlickerPair>,
    /// Overall flicker, pooled over all pairs.
    pub flicker: f64,
    /// Fraction of the pixels counted over all pairs.
    pub static_fraction: f64,
    /// Sum of the pairs' `nonfinite`.
    pub nonfinite: u64,
}

/// Sums of one pair, or of several.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    /// `E`.
    error: f64,
    /// `S`.
    signal: f64,
    /// `S'`, the candidate's own signal: the scale when `S = 0`, as always without a reference.
    fallback: f64,
    counted: u64,
    pixels: u64,
    nonfinite: u64,
}

impl Sums {
    fn flicker(&self) -> f64 {
        let scale = Some(self.signal).filter(|&s| s > 0.0);
        let scale = scale.unwrap_or(self.fallback);
        if self.error > 0.0 && scale > 0.0 {
            (self.error / scale).sqrt().min(f64::MAX)
        } else {
            0.0
        }
    }

    fn fraction(&self) -> f64 {
        self.counted as f64 / self.pixels.max(1) as f64
    }
}

/// Measures the flicker of `frames`, against `reference` when given (see the module docs).
///
/// Errors when there are fewer than 2 frames, when the reference has another length, or when a
/// frame of either sequence differs in size from `frames[0]` (naming the frame).
pub fn flicker(frames: &[Image], reference: Option<&[Image]>) -> Result<FlickerReport> {
    if let Some(r) = reference.filter(|r| r.len() != frames.len()) {
        return Err(Error::SequenceLengthMismatch {
            frames: frames.len(),
            reference: r.len(),
        });
    }
    let mut tally = Tally::default();
    for (t, frame) in frames.iter().enumerate() {
        let previous = t
            .checked_sub(1)
            .map(|p| (&frames[p], reference.map(|r| &r[p])));
        tally.push(previous, frame, reference.map(|r| &r[t]))?;
    }
    tally.report()
}

/// Measures flicker frame by frame, holding only the previous frame (and reference frame) in
/// memory; gives the same result as [`flicker`] on the whole sequence.
#[derive(Debug, Default)]
pub struct FlickerMeter {
    previous: Option<(Image, Option<Image>)>,
    tally: Tally,
}

impl FlickerMeter {
    /// A meter that has seen no frame.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the next frame with, in reference mode, the matching reference frame: either every
    /// call gives a reference or none does ([`Error::SequenceLengthMismatch`] otherwise). Errors
    /// when a frame differs in size from the first, leaving the meter unchanged.
    pub fn push(&mut self, frame: Image, reference: Option<Image>) -> Result<()> {
        let previous = self.previous.as_ref().map(|(f, r)| (f, r.as_ref()));
        self.tally.push(previous, &frame, reference.as_ref())?;
        self.previous = Some((frame, reference));
        Ok(())
    }

    /// The report over the frames pushed so far; errors when there are fewer than 2.
    pub fn finish(&self) -> Result<FlickerReport> {
        self.tally.report()
    }
}

/// What [`flicker`] and [`FlickerMeter`] know of the frames seen so far.
#[derive(Debug, Default)]
struct Tally {
    size: (u32, u32),
    frames: usize,
    references: usize,
    pairs: Vec<Sums>,
}

impl Tally {
    /// Checks the next frame and measures its pair with `previous`; errors change nothing.
    fn push(
        &mut self,
        previous: Option<(&Image, Option<&Image>)>,
        frame: &Image,
        reference: Option<&Image>,
    ) -> Result<()> {
        let index = self.frames;
        let references = self.references + usize::from(reference.is_some());
        if references != 0 && references != index + 1 {
            return Err(Error::SequenceLengthMismatch {
                frames: index + 1,
                reference: references,
            });
        }
        let size = if index == 0 { dims(frame) } else { self.size };
        let checks = [("sequence", Some(frame)), ("reference", reference)];
        for (sequence, image) in checks {
            if let Some(found) = image.map(dims).filter(|&found| found != size) {
                return Err(Error::FrameSizeMismatch {
                    sequence,
                    frame: index,
                    found,
                    expected: size,
                });
            }
        }
        if let Some((previous, previous_reference)) = previous {
            let refs = previous_reference.zip(reference);
            self.pairs.push(pair_sums(previous, frame, refs));
        }
        (self.size, self.frames, self.references) = (size, index + 1, references);
        Ok(())
    }

    fn report(&self) -> Result<FlickerReport> {
        if self.frames < 2 {
            return Err(Error::TooFewFrames {
                frames: self.frames,
            });
        }
        let mut total = Sums::default();
        for s in &self.pairs {
            total.error += s.error;
            total.signal += s.signal;
            total.fallback += s.fallback;
            total.counted += s.counted;
            total.pixels += s.pixels;
            total.nonfinite += s.nonfinite;
        }
        let pairs = self.pairs.iter().enumerate().map(|(t, s)| FlickerPair {
            from: t,
            to: t + 1,
            flicker: s.flicker(),
            static_fraction: s.fraction(),
            nonfinite: s.nonfinite,
        });
        Ok(FlickerReport {
            mode: if self.references > 0 {
                FlickerMode::Reference
            } else {
                FlickerMode::Static
            },
            frames: self.frames,
            pairs: pairs.collect(),
            flicker: total.flicker(),
            static_fraction: total.fraction(),
            nonfinite: total.nonfinite,
        })
    }
}

fn dims(image: &Image) -> (u32, u32) {
    (image.width(), image.height())
}

/// The sums of the pair `a → b` (and `r0 → r1`); all images have the same size.
fn pair_sums(a: &Image, b: &Image, refs: Option<(&Image, &Image)>) -> Sums {
    // (data of a, data of b, channels) of the AOV layers both frames carry; static mode only.
    let layers: Vec<(&[f32], &[f32], usize)> = match refs {
        Some(_) => Vec::new(),
        None => [DEPTH, NORMAL, ALBEDO]
            .iter()
            .filter_map(|name| {
                let (la, lb) = (a.layer(name)?, b.layer(name)?);
                let k = la.channels().len();
                (la.channels() == lb.channels()).then_some((la.data(), lb.data(), k))
            })
            .collect(),
    };
    let pixels = a.pixel_count();
    let mut sums = Sums {
        pixels: pixels as u64,
        ..Sums::default()
    };
    let rgb = |image: &Image, p: usize| -> [f32; 3] {
        let v = &image.rgb()[3 * p..3 * p + 3];
        [v[0], v[1], v[2]]
    };
    for p in 0..pixels {
        let (i0, i1) = (rgb(a, p), rgb(b, p));
        // Without a reference the formulas are those of a black one (see `Sums::flicker`).
        let r = refs.map_or([[0.0; 3]; 2], |(r0, r1)| [rgb(r0, p), rgb(r1, p)]);
        if !i0
            .iter()
            .chain(&i1)
            .chain(r.iter().flatten())
            .all(|v| v.is_finite())
        {
            sums.nonfinite += 1;
            continue;
        }
        let same_surface = layers
            .iter()
            .all(|&(la, lb, k)| unchanged(&la[k * p..k * (p + 1)], &lb[k * p..k * (p + 1)]));
        if !same_surface {
            continue;
        }
        sums.counted += 1;
        for c in 0..3 {
            let [x0, x1, y0, y1] = [i0[c], i1[c], r[0][c], r[1][c]].map(f64::from);
            let e = (x1 - x0) - (y1 - y0);
            sums.error += e * e;
            sums.signal += (y0 * y0 + y1 * y1) / 2.0;
            sums.fallback += (x0 * x0 + x1 * x1) / 2.0;
        }
    }
    sums
}

/// Whether AOV vectors `a` and `b` are equal within [`STATIC_TOLERANCE`].
fn unchanged(a: &[f32], b: &[f32]) -> bool {
    if a == b {
        return true;
    }
    if !a.iter().chain(b).all(|v| v.is_finite()) {
        return false;
    }
    let (mut diff, mut norm_a, mut norm_b) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (&x, &y) in a.iter().zip(b) {
        let (x, y) = (f64::from(x), f64::from(y));
        diff += (y - x) * (y - x);
        norm_a += x * x;
        norm_b += y * y;
    }
    diff.sqrt() <= STATIC_TOLERANCE * norm_a.max(norm_b).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Layer;

    /// A 2×1 image with grey pixels `values`.
    fn grey(values: [f32; 2]) -> Image {
        Image::from_pixels(2, 1, values.iter().map(|&v| [v; 3]).collect()).unwrap()
    }

    /// `frames` with `f` applied to every beauty value of frame `t`.
    fn map(frames: &[Image], f: impl Fn(usize, f32) -> f32) -> Vec<Image> {
        let mut frames = frames.to_vec();
        for (t, frame) in frames.iter_mut().enumerate() {
            frame.rgb_mut().iter_mut().for_each(|v| *v = f(t, *v));
        }
        frames
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    fn per_pair(report: &FlickerReport) -> Vec<f64> {
        report.pairs.iter().map(|p| p.flicker).collect()
    }

    /// Frames with motion: the two pixels swap values 1 and 3 every frame.
    fn moving() -> Vec<Image> {
        vec![grey([1.0, 3.0]), grey([3.0, 1.0]), grey([1.0, 3.0])]
    }

    #[test]
    fn constant_sequence_is_zero() {
        let r = flicker(&vec![grey([0.25, 4.0]); 4], None).unwrap();
        assert_eq!((r.mode, r.frames, r.flicker), (FlickerMode::Static, 4, 0.0));
        assert_eq!(per_pair(&r), [0.0; 3]);
        assert_eq!((r.static_fraction, r.nonfinite), (1.0, 0));
    }

    #[test]
    fn alternating_sequence_has_the_hand_computed_value() {
        // Pixel 0 alternates 1 ↔ 3, pixel 1 stays 2: E = 3·2² = 12, S = 3·((1+9)/2 + (4+4)/2) = 27.
        let (a, b) = (grey([1.0, 2.0]), grey([3.0, 2.0]));
        let r = flicker(&[a.clone(), b.clone(), a, b], None).unwrap();
        assert!(close(r.flicker, 2.0 / 3.0), "{r:?}");
        assert!(per_pair(&r).iter().all(|&f| close(f, 2.0 / 3.0)), "{r:?}");
        assert_eq!((r.pairs[2].from, r.pairs[2].to), (2, 3));
    }

    #[test]
    fn candidate_equal_to_reference_is_zero_despite_motion() {
        let r = flicker(&moving(), Some(&moving())).unwrap();
        assert_eq!(r.mode, FlickerMode::Reference);
        assert_eq!((r.flicker, per_pair(&r)), (0.0, vec![0.0; 2]));
        // Without the reference the motion itself counts: E = 6·2², S = 3·(1+9+9+1)/2 → 2/√5.
        let own = flicker(&moving(), None).unwrap();
        assert!(close(own.flicker, 2.0 / 5.0_f64.sqrt()), "{own:?}");
    }

    #[test]
    fn per_frame_offsets_give_the_exact_value() {
        // Offsets o = 0, 0.5, 0.25: E_t = 6·(o_{t+1} − o_t)², S_t = 30, so flicker_t = |Δo| / √5
        // and overall sqrt(6·(0.25 + 0.0625) / 60).
        let candidate = map(&moving(), |t, v| v + [0.0, 0.5, 0.25][t]);
        let r = flicker(&candidate, Some(&moving())).unwrap();
        let sqrt5 = 5.0_f64.sqrt();
        assert!(close(r.pairs[0].flicker, 0.5 / sqrt5), "{r:?}");
        assert!(close(r.pairs[1].flicker, 0.25 / sqrt5), "{r:?}");
        assert!(close(r.flicker, 0.03125_f64.sqrt()), "{r:?}");
        // Against a black reference the candidate's own scale is used: 1 → 3 gives 2/√5.
        let black = map(&moving(), |_, _| 0.0);
        let r = flicker(&map(&moving(), |t, _| [1.0, 3.0, 3.0][t]), Some(&black)).unwrap();
        assert!(close(r.pairs[0].flicker, 2.0 / sqrt5), "{r:?}");
        assert_eq!(flicker(&black, Some(&black)).unwrap().flicker, 0.0);
    }

    #[test]
    fn figures_are_scale_invariant() {
        let frames = vec![grey([1.0, 2.0]), grey([3.0, 2.5]), grey([0.5, 2.0])];
        let big = |frames: &[Image]| map(frames, |_, v| v * 1000.0);
        for reference in [None, Some(moving())] {
            let r = flicker(&frames, reference.as_deref()).unwrap();
            let big_reference = reference.as_deref().map(big);
            let s = flicker(&big(&frames), big_reference.as_deref()).unwrap();
            assert!(
                r.flicker > 0.1 && close(s.flicker, r.flicker),
                "{r:?} vs {s:?}"
            );
            let pairs = per_pair(&r).into_iter().zip(per_pair(&s));
            assert!(pairs.clone().all(|(x, y)| close(x, y)), "{r:?} vs {s:?}");
        }
    }

    #[test]
    fn pixels_whose_depth_changes_are_not_static() {
        // Pixel 0 sees the same surface (depth 1 → 1.0005, within τ) and goes 1 → 3; pixel 1
        // moves to another surface (depth 1 → 2) and goes 5 → 0. Only pixel 0 counts:
        // E = 3·4, S = 3·(1+9)/2, flicker = sqrt(0.8).
        let a = grey([1.0, 5.0]).with_layer(Layer::depth(vec![1.0, 1.0]));
        let b = grey([3.0, 0.0]).with_layer(Layer::depth(vec![1.0005, 2.0]));
        let (a, b) = (a.unwrap(), b.unwrap());
        let r = flicker(&[a.clone(), b.clone()], None).unwrap();
        assert!(close(r.flicker, 0.8_f64.sqrt()), "{r:?}");
        assert_eq!(r.pairs[0].static_fraction, 0.5);
        // A normal that turns excludes pixel 0 as well; nothing is left to count.
        let normals = |n: [f32; 3]| Layer::normal([n, [0.0, 0.0, 1.0]].concat());
        let a = a.with_layer(normals([0.0, 0.0, 1.0])).unwrap();
        let b = b.with_layer(normals([0.0, 1.0, 0.0])).unwrap();
        let r = flicker(&[a, b], None).unwrap();
        assert_eq!((r.flicker, r.static_fraction), (0.0, 0.0));
    }

    #[test]
    fn nonfinite_pixels_are_counted_and_excluded() {
        let (a, b) = (grey([1.0, 2.0]), grey([3.0, 2.0]));
        let mut bad = b.clone();
        bad.set_pixel(1, 0, [f32::NAN, 0.0, f32::INFINITY]);
        // Pixel 1 is left out of both pairs: pixel 0 alone gives E = 12, S = 15.
        let r = flicker(&[a.clone(), bad.clone(), a.clone()], None).unwrap();
        assert!(close(r.flicker, 0.8_f64.sqrt()), "{r:?}");
        assert_eq!((r.nonfinite, r.pairs[0].nonfinite), (2, 1));
        // The same in the reference; pixel 0 follows the reference exactly.
        let r = flicker(&[a.clone(), b, a.clone()], Some(&[a.clone(), bad, a])).unwrap();
        assert_eq!((r.flicker, r.nonfinite, r.static_fraction), (0.0, 2, 0.5));
    }

    #[test]
    fn meter_matches_and_bad_sequences_are_errors() {
        let frames = vec![grey([1.0, 2.0]), grey([3.0, 2.5]), grey([0.5, 2.0])];
        let mut meter = FlickerMeter::new();
        for (f, r) in frames.iter().zip(moving()) {
            meter.push(f.clone(), Some(r)).unwrap();
        }
        let expected = flicker(&frames, Some(&moving())).unwrap();
        assert_eq!(meter.finish().unwrap(), expected);
        let err = meter.push(grey([0.0, 0.0]), None).unwrap_err().to_string();
        assert_eq!(err, "the sequence has 4 frames but its reference has 3");
        let err = meter
            .push(Image::new(1, 2), Some(Image::new(1, 2)))
            .unwrap_err();
        let size_error = "sequence frame 3 is 1x2, but frame 0 of the sequence is 2x1";
        assert_eq!(err.to_string(), size_error);
        assert_eq!(meter.finish().unwrap(), expected);
        let err = FlickerMeter::new().finish().unwrap_err();
        assert!(matches!(err, Error::TooFewFrames { frames: 0 }), "{err}");

        let err = flicker(&frames[..1], None).unwrap_err();
        assert!(matches!(err, Error::TooFewFrames { frames: 1 }), "{err}");
        let err = flicker(&frames, Some(&frames[..2]))
            .unwrap_err()
            .to_string();
        assert_eq!(err, "the sequence has 3 frames but its reference has 2");
        let mut odd = frames.clone();
        odd[2] = Image::new(1, 2);
        let err = flicker(&odd, None).unwrap_err().to_string();
        let size_error = "sequence frame 2 is 1x2, but frame 0 of the sequence is 2x1";
        assert_eq!(err, size_error);
        let err = flicker(&frames, Some(&odd)).unwrap_err().to_string();
        assert!(err.starts_with("reference frame 2 is 1x2"), "{err}");
    }
}
