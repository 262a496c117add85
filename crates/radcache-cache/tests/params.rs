//! Tests of `IcParams` and its presets (docs/irradiance-cache.md §2.2, §8.1;
//! docs/cache-frame.md §3.2).

use radcache_cache::weight::{splat_radius, WeightKind};
use radcache_cache::{falloff_strata, IcParams, Preset};

#[test]
fn presets_are_valid_and_ordered() {
    let (d, n, h) = (IcParams::draft(), IcParams::default(), IcParams::high());
    for p in [d, n, h] {
        assert!(p.is_valid(), "{p:?}");
        assert_eq!(p.weight_kind, WeightKind::TabellionLamorlette);
        assert!(p.strata_n >= 3 * p.strata_m, "N ≈ πM (§2.2)");
    }
    assert_eq!(IcParams::preset(Preset::Default), n);
    assert_eq!(
        (n.strata_m, n.strata_n, n.accuracy, n.kappa),
        (12, 36, 0.15, 0.75),
        "§8.1 values; κ measured (§8.2)"
    );
    assert_eq!(
        (
            n.min_spacing_px,
            n.max_spacing_px,
            n.temporal_accuracy,
            n.max_age_frames
        ),
        (4.0, 20.0, 0.05, 30.0),
        "R⁻ measured (params.rs), the rest §8.1"
    );
    assert_eq!((d.strata_m, d.strata_n), (8, 24), "§2.2 interactive");
    // Fine strata (§2.8): the default's dense levels gather as the draft does; draft and high
    // keep their own strata everywhere.
    assert_eq!(
        (n.fine_strata_m, n.fine_strata_n),
        (8, 24),
        "measured (params.rs)"
    );
    assert_eq!((d.fine_strata_m, d.fine_strata_n), (d.strata_m, d.strata_n));
    assert_eq!((h.fine_strata_m, h.fine_strata_n), (h.strata_m, h.strata_n));
    assert!(
        n.strata_falloff && !d.strata_falloff && !h.strata_falloff,
        "measured (params.rs)"
    );
    assert!(d.sample_count() < n.sample_count() && n.sample_count() < h.sample_count());
    assert!(d.accuracy > n.accuracy && n.accuracy > h.accuracy);
    assert!(
        n.kappa < h.kappa && d.kappa < h.kappa,
        "high has the smallest zones"
    );
    assert!(d.max_spacing_px > n.max_spacing_px && n.max_spacing_px > h.max_spacing_px);
}

/// The fine strata start at the first level whose spacing is at most R⁻, and never for records
/// made for glossy lobes.
#[test]
fn fine_strata_follow_the_level_spacing() {
    let n = IcParams::default();
    // Spacings 32, 16, 8, 4, 2, 1 px against R⁻ = 4 px.
    assert_eq!(n.fine_level(), 3);
    // 8×24 at 4 px, then half the rays per level: 6×18 at 2 px, 4×12 at 1 px.
    let fine = [(12, 36), (12, 36), (12, 36), (8, 24), (6, 18), (4, 12)];
    for level in 0..6 {
        let expected = fine[level as usize];
        assert_eq!(n.strata_at(level, false), expected, "level {level}");
        let whole = IcParams {
            strata_falloff: false,
            ..n
        };
        let expected = if level >= 3 { (8, 24) } else { (12, 36) };
        assert_eq!(whole.strata_at(level, false), expected, "level {level}");
        assert_eq!(
            n.strata_at(level, true),
            (12, 36),
            "radiance, level {level}"
        );
    }
    // R⁻ = 1.5 px: only the 1-px level; R⁻ below every spacing: none.
    assert_eq!(IcParams::high().fine_level(), 5);
    let sparse = IcParams {
        min_spacing_px: 0.5,
        ..n
    };
    assert_eq!(sparse.fine_level(), 6);
    assert_eq!(sparse.strata_at(5, false), (12, 36));
    let wide = IcParams {
        min_spacing_px: 40.0,
        ..n
    };
    assert_eq!(wide.fine_level(), 0);
    // with_strata: fine strata with fewer rays stay, others follow.
    assert_eq!(n.with_strata(24, 72).strata_at(3, false), (8, 24));
    assert_eq!(n.with_strata(24, 72).strata_at(0, false), (24, 72));
    assert_eq!(n.with_strata(4, 12).strata_at(3, false), (4, 12));
    assert_eq!(n.with_strata(4, 12).strata_at(5, false), (2, 6));
    let bad = IcParams {
        fine_strata_n: 2,
        ..n
    };
    assert!(!bad.is_valid());
}

/// `falloff_strata`: `M'` the integer nearest `m/√2^steps` (f64 reference), `N'` keeps the shape,
/// the rays halve per level while the strata are many, and never below 1 × 3.
#[test]
fn the_strata_falloff_halves_the_rays_per_level() {
    assert_eq!(falloff_strata(8, 24, 0), (8, 24));
    assert_eq!(falloff_strata(8, 24, 1), (6, 18));
    assert_eq!(falloff_strata(8, 24, 2), (4, 12));
    assert_eq!(falloff_strata(24, 72, 2), (12, 36));
    assert_eq!(falloff_strata(1, 3, 9), (1, 3));
    for m in 1..=1728u32 {
        for steps in 0..=20u32 {
            let n = 3 * m.min(576) + m % 5;
            let (m2, n2) = falloff_strata(m, n, steps);
            let x = f64::from(m) / 2f64.powf(f64::from(steps) / 2.0);
            assert!(
                (f64::from(m2) - x).abs() <= 0.5 || m2 == 1,
                "{m} {steps}: {m2} vs {x}"
            );
            let shape = f64::from(n) * f64::from(m2) / f64::from(m);
            assert!(
                (f64::from(n2) - shape).abs() <= 0.5 || n2 == 3,
                "{m}×{n}: {n2}"
            );
            if steps == 1 && m >= 16 {
                let ratio = f64::from(m2 * n2) / f64::from(m * n);
                assert!((ratio - 0.5).abs() < 0.1, "{m}×{n}: {ratio}");
            }
        }
    }
}

#[test]
fn derived_quantities() {
    let p = IcParams::default();
    assert_eq!(p.weight_param(), 0.75);
    assert!((p.validity_scale() - 0.5 / 0.75).abs() < 1e-6, "σ = 1/(2κ)");
    assert_eq!(p.coverage_threshold(), 0.5);
    assert_eq!(
        (
            p.level_spacing_px(0),
            p.level_spacing_px(5),
            p.level_spacing_px(9)
        ),
        (32, 1, 1)
    );
    let s = 0.003;
    let (lo, hi) = p.radius_bounds(s);
    let vr = |r| splat_radius(p.weight_kind, r, p.weight_param(), 0.0);
    assert!(
        (vr(lo) - p.min_spacing_px * s).abs() < 1e-6
            && (vr(hi) - p.max_spacing_px * s).abs() < 1e-6,
        "validity radius in pixels"
    );
    assert!((p.front_tolerance(s) - 0.5 * s).abs() < 1e-9);
    let c = p.for_creation();
    assert!(
        c.kappa > p.kappa && c.accuracy < p.accuracy,
        "creation is stricter (docs/cache-frame.md §3.2)"
    );
    assert!((c.kappa - p.kappa / 0.7).abs() < 1e-6);
    let ward = IcParams {
        weight_kind: WeightKind::Ward,
        ..p
    };
    assert_eq!(ward.weight_param(), 0.15);
    assert!((ward.coverage_threshold() - 0.5 / 0.15).abs() < 1e-5);
    assert!(!IcParams {
        min_spacing_px: 30.0,
        ..p
    }
    .is_valid());
}
