//! `compare` on small hand-made images against figures computed by hand, plus thresholds,
//! FLIP and serialisation.

use radcache_image::{compare, Error, Image, Metrics, Thresholds};

fn close(actual: f64, expected: f64) -> bool {
    (actual - expected).abs() <= 1e-12 * expected.abs().max(1.0)
}

macro_rules! assert_close {
    ($actual:expr, $expected:expr) => {
        assert!(
            close($actual, $expected),
            "{} = {} but expected {}",
            stringify!($actual),
            $actual,
            $expected
        )
    };
}

/// 2×2, dyadic values so every figure is exact:
///
/// ```text
///           p0 (0,0)      p1 (1,0)      p2 (0,1)   p3 (1,1)
/// ref       (1, 0, 0)     (0, 1, 0)     (0, 0, 1)  (1, 1, 1)
/// cand      (1.25, 0, 0)  (0, 1, 0.5)   (0, 0, 1)  (0.5, 1, 1)
/// c − r     (0.25, 0, 0)  (0, 0, 0.5)   0          (−0.5, 0, 0)
/// ```
fn two_by_two() -> (Image, Image) {
    let reference = vec![1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.];
    let candidate = vec![1.25, 0., 0., 0., 1., 0.5, 0., 0., 1., 0.5, 1., 1.];
    (
        Image::from_rgb(2, 2, reference).unwrap(),
        Image::from_rgb(2, 2, candidate).unwrap(),
    )
}

#[test]
fn two_by_two_hand_computed() {
    let (reference, candidate) = two_by_two();
    let m = compare(&reference, &candidate).unwrap();
    assert_eq!((m.width, m.height, m.pixels_compared), (2, 2, 4));
    // Σ(c−r)² = 0.0625 + 0.25 + 0.25 = 0.5625 over 3·4 = 12 samples → MSE 0.046875.
    assert_close!(m.rmse, 0.046_875_f64.sqrt());
    // Σ|c−r| = 0.25 + 0.5 + 0.5 = 1.25 → 1.25 / 12.
    assert_close!(m.mae, 1.25 / 12.0);
    // (c−r)²/(r²+0.01): p0.R 0.0625/1.01, p1.B 0.25/0.01 = 25, p3.R 0.25/1.01.
    assert_close!(m.relmse, (0.0625 / 1.01 + 25.0 + 0.25 / 1.01) / 12.0);
    // One partial 8×8 block holding the 4 pixels.
    // ref means  R (1+0+0+1)/4 = 0.5, G (0+1+0+1)/4 = 0.5, B (0+0+1+1)/4 = 0.5
    // cand means R (1.25+0+0+0.5)/4 = 0.4375, G 0.5, B (0+0.5+1+1)/4 = 0.625
    // differences −0.0625, 0, 0.125 → sqrt((0.00390625 + 0 + 0.015625) / 3)
    assert_close!(m.block_rmse, (0.019_531_25_f64 / 3.0).sqrt());
    // mean ratios 0.4375/0.5, 0.5/0.5, 0.625/0.5.
    assert_eq!(m.mean_ratio, [0.875, 1.0, 1.25]);
    assert_eq!(m.max_mean_ratio_dev(), 0.25);
    assert_eq!((m.nonfinite_candidate, m.nonfinite_reference), (0, 0));
}

/// 12×8 (two 8×8 blocks, the right one partial: 4×8 pixels), reference 1 everywhere;
/// candidate 1.5 in the left block, 0.75 in the right block; the candidate has NaN in G at
/// (9, 0), the reference has +inf in R at (10, 0). Those two pixels are excluded from both.
fn twelve_by_eight() -> (Image, Image) {
    let reference = Image::from_rgb(12, 8, vec![1.0; 12 * 8 * 3]).unwrap();
    let mut candidate = Image::new(12, 8);
    for y in 0..8 {
        for x in 0..12 {
            let v = if x < 8 { 1.5 } else { 0.75 };
            candidate.set_pixel(x, y, [v, v, v]);
        }
    }
    candidate.set_pixel(9, 0, [0.75, f32::NAN, 0.75]);
    let mut reference = reference;
    reference.set_pixel(10, 0, [f32::INFINITY, 1.0, 1.0]);
    (reference, candidate)
}

#[test]
fn partial_block_and_non_finite_pixels_hand_computed() {
    let (reference, candidate) = twelve_by_eight();
    let m = compare(&reference, &candidate).unwrap();
    // 96 pixels − 2 non-finite = 94 compared: 64 left (c−r = 0.5), 30 right (c−r = −0.25).
    assert_eq!(m.pixels_compared, 94);
    assert_eq!((m.nonfinite_candidate, m.nonfinite_reference), (1, 1));
    let samples: f64 = 3.0 * 94.0;
    // Σ(c−r)² = 64·3·0.25 + 30·3·0.0625 = 48 + 5.625 = 53.625
    assert_close!(m.rmse, (53.625 / samples).sqrt());
    // r = 1 everywhere: Σ(c−r)²/(1 + 0.01)
    assert_close!(m.relmse, 53.625 / 1.01 / samples);
    // Σ|c−r| = 64·3·0.5 + 30·3·0.25 = 96 + 22.5 = 118.5
    assert_close!(m.mae, 118.5 / samples);
    // Block means: left 1.5 vs 1 (Δ 0.5), right (partial, 30 compared pixels) 0.75 vs 1
    // (Δ −0.25), each block weighing the same: sqrt((3·0.25 + 3·0.0625) / 6) = sqrt(0.15625).
    assert_close!(m.block_rmse, 0.15625_f64.sqrt());
    // mean(c) = (64·1.5 + 30·0.75) / 94 = 118.5 / 94, mean(r) = 1.
    for ratio in m.mean_ratio {
        assert_close!(ratio, 118.5 / 94.0);
    }
}

#[test]
fn mean_ratio_with_black_reference() {
    let black = Image::new(2, 1);
    let mut lit = Image::new(2, 1);
    lit.set_pixel(0, 0, [0.0, 2.0, -2.0]);
    let m = compare(&black, &lit).unwrap();
    // R: 0/0 → 1 by definition; G: 2/0 → +inf; B: −2/0 → −inf.
    assert_eq!(m.mean_ratio, [1.0, f64::INFINITY, f64::NEG_INFINITY]);
    assert_eq!(m.max_mean_ratio_dev(), f64::INFINITY);
}

#[test]
fn all_pixels_non_finite_gives_nan_figures_that_fail_every_limit() {
    let reference = Image::new(2, 2);
    let candidate = Image::from_rgb(2, 2, vec![f32::NAN; 12]).unwrap();
    let m = compare(&reference, &candidate).unwrap();
    assert_eq!((m.pixels_compared, m.nonfinite_candidate), (0, 4));
    assert!(m.rmse.is_nan() && m.relmse.is_nan() && m.mae.is_nan() && m.block_rmse.is_nan());
    assert!(m.mean_ratio.iter().all(|r| r.is_nan()));
    let limits = Thresholds {
        max_rmse: Some(1.0),
        max_relmse: Some(1.0),
        max_mae: Some(1.0),
        max_block_rmse: Some(1.0),
        max_mean_ratio_dev: Some(1.0),
        max_nonfinite: Some(3),
        ..Thresholds::default()
    };
    assert_eq!(limits.check(&m).len(), 6, "{:?}", limits.check(&m));
}

#[test]
fn size_mismatch_names_both_sizes() {
    let err = compare(&Image::new(2, 2), &Image::new(3, 2)).unwrap_err();
    assert!(matches!(err, Error::SizeMismatch { .. }));
    let message = err.to_string();
    assert!(
        message.contains("2x2") && message.contains("3x2"),
        "{message}"
    );
}

#[test]
fn thresholds_report_each_violation() {
    let (reference, candidate) = two_by_two();
    let m = compare(&reference, &candidate).unwrap();
    assert!(Thresholds::default().check(&m).is_empty());
    let limits = Thresholds {
        max_rmse: Some(0.1),             // 0.2165 → violated
        max_mae: Some(0.2),              // 0.1042 → ok
        max_mean_ratio_dev: Some(0.2),   // 0.25   → violated
        max_nonfinite: Some(0),          // 0      → ok
        max_block_rmse: Some(0.080_688), // 0.080687 → ok
        ..Thresholds::default()
    };
    let violations = limits.check(&m);
    assert_eq!(violations.len(), 2, "{violations:?}");
    assert!(violations[0].starts_with("RMSE"));
    assert!(violations[1].starts_with("mean ratio deviation"));

    let no_flip = Metrics { flip: None, ..m };
    let flip_limit = Thresholds {
        max_flip: Some(0.5),
        ..Thresholds::default()
    };
    assert_eq!(flip_limit.check(&no_flip).len(), 1);
}

#[cfg(feature = "flip")]
#[test]
fn flip_is_zero_for_identical_images_and_positive_otherwise() {
    let (reference, candidate) = twelve_by_eight();
    let same = compare(&reference, &reference).unwrap();
    assert_eq!(same.flip, Some(0.0));
    assert_eq!(same.rmse, 0.0);
    // Clamped display values: 1.5 and 1 both show as white, 0.75 shows darker.
    let flip = compare(&reference, &candidate).unwrap().flip.unwrap();
    assert!(flip > 0.0 && flip <= 1.0, "{flip}");

    // A non-finite pixel takes the other image's value and adds no FLIP error.
    let white = Image::from_rgb(16, 16, vec![1.0; 16 * 16 * 3]).unwrap();
    let mut with_nan = white.clone();
    with_nan.set_pixel(3, 3, [f32::NAN, 0.0, 0.0]);
    let m = compare(&white, &with_nan).unwrap();
    assert_eq!((m.flip, m.nonfinite_candidate), (Some(0.0), 1));

    // Black against white is a large difference.
    let black_flip = compare(&white, &Image::new(16, 16)).unwrap().flip.unwrap();
    assert!(black_flip > 0.5, "{black_flip}");
}

#[test]
fn metrics_serialise_and_display() {
    let (reference, candidate) = two_by_two();
    let m = compare(&reference, &candidate).unwrap();
    let json = serde_json::to_value(&m).unwrap();
    for key in [
        "rmse",
        "relmse",
        "mae",
        "block_rmse",
        "mean_ratio",
        "flip",
        "nonfinite_candidate",
    ] {
        assert!(json.get(key).is_some(), "{key}");
    }
    assert_eq!(json["mean_ratio"][2], 1.25);
    let table = m.to_string();
    for row in [
        "RMSE",
        "relMSE",
        "MAE",
        "block RMSE",
        "mean ratio",
        "FLIP",
        "non-finite",
    ] {
        assert!(table.contains(row), "{table}");
    }
}
