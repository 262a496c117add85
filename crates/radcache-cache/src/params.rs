//! Irradiance-cache parameters and presets (docs/irradiance-cache.md §2.2, §4.3, §5, §8,
//! cited below as a bare §N; docs/cache-frame.md §3.2, §3.3; docs/temporal.md §3.3).
//!
//! | Field | draft | default | high | Source / reason |
//! |---|---|---|---|---|
//! | `weight_kind` | T&L | T&L | T&L | see [`crate::weight`] for why T&L is the default |
//! | `error_control` | split sphere | split sphere | split sphere | §4.1; the Hessian rule (§10) is a measured alternative |
//! | `accuracy` (Ward `a`) | 0.3 | 0.15 | 0.1 | §8.1; RADIANCE `rvu` 0.3, `rtrace` 0.1 |
//! | `kappa` (T&L `κ`) | 0.75 | 0.75 | 1.5 | Mitsuba's κ = 1 with `qualityAdjustment` 0.5 after the overture; default measured (below, §8.2); larger κ = smaller zones |
//! | `min_spacing_px` | 3 | 4 | 1.5 | validity radius floor in pixels; Mitsuba 3; 4 measured (below, §8.2) |
//! | `max_spacing_px` | 32 | 20 | 15 | validity radius cap in pixels (§8.1); pbrt-v2 15 |
//! | `strata_m × strata_n` | 8×24 | 12×36 | 24×72 | §2.2: interactive 192 rays, offline 768; default 432 measured (below); high ≈ 1.7k (`N = 3M`) |
//! | `fine_strata_m × fine_strata_n` | 8×24 | 8×24 | 24×72 | §2.8: irradiance records requested at a level no wider than `R⁻`; default measured (below) |
//! | `strata_falloff` | no | yes | no | §2.8: each level finer than that halves the fine strata's rays (6×18 at 2 px, 4×12 at 1 px); measured (below) |
//! | `hole_threshold` | 0.25 | 0.5 | 0.75 | Σw, in units of [`weight_unit`], below which a pixel is a hole (pbrt-v2 minWeight 0.5) |
//! | `levels` | 5 | 6 | 6 | coarse-to-fine spacings `2^(levels−1) … 1` px (docs/cache-frame.md §3.3: 32, 16, 8, 4, 2, 1) |
//! | `creation_strictness` | 0.7 | 0.7 | 0.7 | docs/cache-frame.md §3.2: create at `a·0.7` (Ward) or `κ/0.7` (T&L) |
//! | `front_tolerance_px` | 0.5 | 0.5 | 0.5 | §5.4: in-front tolerance `0.5·s(p)` |
//! | `temporal_accuracy` (`a_t`) | 0.1 | 0.05 | 0.02 | docs/temporal.md §3.3 |
//! | `max_age_frames` (`Δt_max`) | 8 | 30 | 15 | docs/temporal.md §3.3; draft measured (below) |
//!
//! Draft's `Δt_max` of 20 frames was measured with `cargo xtask bench temporal` (animated scene,
//! 60 frames at 256²): 60 frames gave 9.3 % of a per-frame rebuild's record rays but 3.9× its
//! image error (own relMSE 5.8e-3 against 1.5e-3: records whose first one-frame change was small
//! lived 60 frames while the objects moved nearer); 20 gives 13.3 % and 2.9e-3. With the
//! motion-aware expiry (a record also expires when moving objects' cover of its hemisphere changed
//! by more than `a_t`; `temporal.comp`) 20 gives 14.4 % and 2.6e-3; draft with the default's
//! `a_t = 0.05` and `Δt_max = 60` gave 16.3 % and 4.5e-3 (records living 60 frames go stale in
//! ways neither their one-frame rate nor the moving cover sees). Since records take the radius of
//! each evaluation and are listed the frame before their lifespan ends (2026-12-05), 5 frames
//! give the per-frame rebuild's error (own relMSE 1.45e-3 against 1.46e-3, less flicker) with 26 %
//! of its record rays and 48 % of all its rays; 8 frames 18 % and 1.54e-3; 20 frames about 2.6e-3
//! (docs/temporal.md §5). Since kept records gather through the radiance grid kept over frames
//! (2026-12-06, docs/temporal.md §3.8), their error is below the rebuild's and draft's `Δt_max`
//! is 8: `cargo xtask bench temporal --max-age 5|8` gave own relMSE 8.93e-4 and 9.55e-4 against
//! the rebuild's 1.139e-3, with 16.9 % and 11.4 % of its record rays, and kept frames of 52.8 %
//! and 49.5 % of its time.
//!
//! Draft trades accuracy for speed (2.25× fewer rays at the coarse levels, bigger zones, fewer
//! refreshes); high halves the ray noise (4× rays), shrinks zones and refreshes more often. On
//! lavapipe (≈0.3 Mrays/s for incoherent gather rays, measured) the default's 432 rays per record
//! is the dominant cost, so `draft` is the preset for tests and previews.
//!
//! The default R⁻ of 4 px (§8.2) was measured on the Cornell box at 256² against its 2048-spp
//! reference (`tests/refs/`): 2, 3 and 4 px gave the same relMSE (2.49e-4, 2.51e-4, 2.54e-4) with
//! 8,720, 6,544 and 5,209 records; the records clamped to R⁻ sit along edges and in corners, where
//! the finest creation levels otherwise put one per pixel or two. `high` keeps 1.5 px for scenes
//! with fine geometric detail.
//!
//! The default κ of 0.75 (§8.2; Mitsuba renders with κ = 1 × its `qualityAdjustment` 0.5 after
//! the overture, which our coarse-to-fine creation at κ/0.7 plays the part of) was measured on
//! 2026-12-05 against Mitsuba's 8192-spp references (`radcache render --accuracy 1/κ`, 256²,
//! each timed on its second run): on the courtyard κ = 0.5 left the undersides of ledges and
//! cornices 4 % too dark on average and up to 20 % in bands (zones as wide as the gradient
//! limit `E/|∇E|` allows, over an irradiance that halves across them: the ground's sunlit and
//! shaded patches seen from below); κ = 0.75 gave relMSE 8.13e-4 against 1.07e-3, block RMSE
//! 2.39e-3 against 3.41e-3, FLIP 0.0278 against 0.0325, with 7,150 records against 5,284 (7.27
//! M record rays against 5.83 M) and 10–25 % more time; κ = 1 relMSE 8.36e-4 and block RMSE
//! 2.32e-3 with 8,505 records (8.17 M rays). Halving the gradient limit instead (R ≤
//! E/(2|∇E|), κ = 0.5) mended the undersides with 10 % more records but gained less (9.20e-4,
//! block 2.83e-3), and the Hessian rule at κ = 0.75 gave 8.40e-4 and 2.55e-3.
//! On the Cornell box κ = 0.75 costs 8 % more time for 2 % less relMSE and 8 % less block RMSE
//! (2.72 s against 2.54 s; 2.48e-4 against 2.53e-4; 1.26e-3 against 1.37e-3). The earlier
//! default of 0.5 was chosen on the Cornell box alone (κ = 1 gave relMSE 2.14e-4 in 7.3 s, 0.75
//! 2.16e-4 in 6.4 s, 0.5 2.31e-4 in 4.8 s, a frame three times slower than today's). `draft` keeps
//! 0.75 too, its R⁺ of 32 px making its zones the widest.

//!
//! The default's 12×36 strata (432 rays; the course's offline 16×48 until 2026-12-05) were
//! measured at equal wall time against Mitsuba 3 (`cargo xtask bench peer`, one run each, the
//! ratios within each run): the relMSE ratio Mitsuba/radcache went from 11.1 to 14.4 on the
//! Cornell box, 3.33 to 3.69 on the courtyard and 2.92 to 3.25 on `metal_spheres`; the 8×8-block
//! RMSE ratio radcache/Mitsuba from 0.95 to 0.93 on the courtyard and 1.14 to 1.08 on
//! `metal_spheres` (0.31 to 0.35 on the Cornell box); FLIP from 0.996 to 0.98 on the courtyard.
//! On the Cornell box alone (`radcache render --seed 1|2`, 256²) 12×36 cut the record rays by
//! 34 % and the frame by about 25 % for relMSE +6 % and block RMSE +9 %. Each record is noisier,
//! but the frame is cheaper by more than its error grows (docs/cache-frame.md §7.1).
//!
//! The default's fine strata (§2.8) were measured at 256² against the references (`radcache
//! render --seed S`, the Cornell box's seeds 1–3; the courtyard with the CLI's adaptive
//! anti-aliasing): 8×24 at the levels of spacing 4, 2 and 1 px cut the courtyard's record rays
//! from 14.1 M to 5.8 M (−59 %) for relMSE 1.426e-3 against 1.337e-3 (+7 %; block RMSE +1.5 %),
//! and the Cornell box's by 26 % for +2–4 %. 8×24 from spacing 2 px only cut 39 % for +3 %;
//! 4×12 from 2 px, 6×18 from 4 px and 8×24 at every level (the draft's strata) lost 17–23 %.
//!
//! The default's strata falloff (§2.8; 2026-12-06, once the radiance grid and adaptive
//! anti-aliasing had made the frame's other costs smaller) was measured on the courtyard at 256²
//! with the CLI's defaults, seeds 0, 2 and 3 (`radcache render … --seed S [--strata-falloff
//! off]`, own relMSE net of the reference's noise): record rays −27 % (4.03 M → 2.98 M at seed
//! 0) for own relMSE +8 to +9 % and block RMSE +1 to +4 %; on the Cornell box −7 % for +3 %.
//! Steeper splits cost more error than they save: 6×18 already at 4 px and 4×12 at 1 px gave
//! 2.65 M rays and +14 % (block RMSE +7 %), 4×12 at every fine level 2.01 M and +53 %.

use crate::radius::radius_bounds;
use crate::weight::{coverage_threshold, validity_scale, weight_unit, WeightKind};

/// Named parameter presets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Preset {
    /// Fast previews and tests.
    Draft,
    /// The default preset (§8.1).
    #[default]
    Default,
    /// Offline quality.
    High,
}

/// How a record's radius `R` is chosen before the gradient limit and the clamps (§4.1, §10).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ErrorControl {
    /// Ward's split sphere: `R = max(R_harm, R_min_restricted)` (§4.1). The default.
    #[default]
    SplitSphere,
    /// Schwarzhaupt et al.'s Hessian error control: `R` from the largest eigenvalue of the
    /// irradiance Hessian (§10; the record pass compiles it in with the define `IC_HESSIAN`).
    Hessian,
}

/// Parameters of the irradiance cache (see the module table for values and sources).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IcParams {
    /// Interpolation weight (§5).
    pub weight_kind: WeightKind,
    /// Radius rule (§4.1, §10); not stored in cache files.
    pub error_control: ErrorControl,
    /// Ward accuracy `a` (§5.2); used when `weight_kind` is Ward.
    pub accuracy: f32,
    /// Tabellion–Lamorlette `κ` (§5.3); used when `weight_kind` is T&L.
    pub kappa: f32,
    /// Smallest validity radius, in pixel footprints (§4.3, `R⁻`).
    pub min_spacing_px: f32,
    /// Largest validity radius, in pixel footprints (§4.3, `R⁺`).
    pub max_spacing_px: f32,
    /// Polar strata `M` (§2.2).
    pub strata_m: u32,
    /// Azimuthal strata `N` (§2.2).
    pub strata_n: u32,
    /// Polar strata of the records requested at a creation level whose spacing is at most
    /// `R⁻` ([`IcParams::fine_level`]) but for those made for glossy lobes (§2.8).
    pub fine_strata_m: u32,
    /// Azimuthal strata of those records (§2.8).
    pub fine_strata_n: u32,
    /// Whether each level finer than [`IcParams::fine_level`] halves the fine strata's rays
    /// (`M` and `N` over √2 per level: [`falloff_strata`]; §2.8).
    pub strata_falloff: bool,
    /// Σw, in units of [`weight_unit`], below which a pixel counts as a hole (§5.6;
    /// docs/cache-frame.md §3.3).
    pub hole_threshold: f32,
    /// Number of coarse-to-fine creation levels; the coarsest spacing is `2^(levels−1)` px
    /// (docs/cache-frame.md §3.3).
    pub levels: u32,
    /// Creation-pass strictness `s` (docs/cache-frame.md §3.2): records are created with `a·s`
    /// (Ward) or `κ/s` (T&L).
    pub creation_strictness: f32,
    /// In-front test tolerance in pixel footprints (§5.4).
    pub front_tolerance_px: f32,
    /// Temporal accuracy `a_t` (docs/temporal.md §3.3).
    pub temporal_accuracy: f32,
    /// Largest record lifespan `Δt_max`, in frames (docs/temporal.md §3.3).
    pub max_age_frames: f32,
}

impl Default for IcParams {
    fn default() -> Self {
        Self::preset(Preset::Default)
    }
}

impl IcParams {
    /// Parameters of a named preset.
    pub fn preset(preset: Preset) -> Self {
        let base = Self {
            weight_kind: WeightKind::default(),
            error_control: ErrorControl::default(),
            accuracy: 0.15,
            kappa: 0.75,
            min_spacing_px: 4.0,
            max_spacing_px: 20.0,
            strata_m: 12,
            strata_n: 36,
            fine_strata_m: 8,
            fine_strata_n: 24,
            strata_falloff: true,
            hole_threshold: 0.5,
            levels: 6,
            creation_strictness: 0.7,
            front_tolerance_px: 0.5,
            temporal_accuracy: 0.05,
            max_age_frames: 30.0,
        };
        match preset {
            Preset::Default => base,
            Preset::Draft => Self {
                accuracy: 0.3,
                kappa: 0.75,
                min_spacing_px: 3.0,
                max_spacing_px: 32.0,
                strata_m: 8,
                strata_n: 24,
                fine_strata_m: 8,
                fine_strata_n: 24,
                strata_falloff: false,
                hole_threshold: 0.25,
                levels: 5,
                temporal_accuracy: 0.1,
                max_age_frames: 8.0,
                ..base
            },
            Preset::High => Self {
                accuracy: 0.1,
                kappa: 1.5,
                min_spacing_px: 1.5,
                max_spacing_px: 15.0,
                strata_m: 24,
                strata_n: 72,
                fine_strata_m: 24,
                fine_strata_n: 72,
                strata_falloff: false,
                hole_threshold: 0.75,
                temporal_accuracy: 0.02,
                max_age_frames: 15.0,
                ..base
            },
        }
    }

    /// The `draft` preset.
    pub fn draft() -> Self {
        Self::preset(Preset::Draft)
    }

    /// The `high` preset.
    pub fn high() -> Self {
        Self::preset(Preset::High)
    }

    /// The weight parameter of the selected kind: `a` (Ward) or `κ` (T&L).
    pub fn weight_param(&self) -> f32 {
        match self.weight_kind {
            WeightKind::Ward => self.accuracy,
            WeightKind::TabellionLamorlette => self.kappa,
        }
    }

    /// Validity radius / `R` for the selected kind (§5.6).
    pub fn validity_scale(&self) -> f32 {
        validity_scale(self.weight_kind, self.weight_param())
    }

    /// `(R⁻, R⁺)` for a record whose pixel footprint is `footprint` (§4.3).
    pub fn radius_bounds(&self, footprint: f32) -> (f32, f32) {
        radius_bounds(
            footprint,
            self.min_spacing_px,
            self.max_spacing_px,
            self.validity_scale(),
        )
    }

    /// Σw below which a pixel is a hole (§5.6).
    pub fn coverage_threshold(&self) -> f32 {
        coverage_threshold(self.weight_kind, self.weight_param(), self.hole_threshold)
    }

    /// Weight of one full record for the selected kind ([`weight_unit`]).
    pub fn weight_unit(&self) -> f32 {
        weight_unit(self.weight_kind, self.weight_param())
    }

    /// In-front tolerance in world units at a point with pixel footprint `footprint` (§5.4).
    pub fn front_tolerance(&self, footprint: f32) -> f32 {
        self.front_tolerance_px * footprint.max(0.0)
    }

    /// The stricter parameters used while creating records (docs/cache-frame.md §3.2): `a·s` and
    /// `κ/s`.
    pub fn for_creation(&self) -> Self {
        let s = self.creation_strictness.clamp(0.05, 1.0);
        Self {
            accuracy: self.accuracy * s,
            kappa: self.kappa / s,
            ..*self
        }
    }

    /// Rays per record, `M·N`.
    pub fn sample_count(&self) -> u32 {
        self.strata_m * self.strata_n
    }

    /// These parameters with `m × n` strata, and fine strata of no more rays than those (the
    /// fine strata kept where they have fewer, else `m × n` too).
    pub fn with_strata(self, m: u32, n: u32) -> Self {
        let fine = if self.fine_strata_m * self.fine_strata_n < m * n {
            (self.fine_strata_m, self.fine_strata_n)
        } else {
            (m, n)
        };
        Self {
            strata_m: m,
            strata_n: n,
            fine_strata_m: fine.0,
            fine_strata_n: fine.1,
            ..self
        }
    }

    /// The first creation level whose spacing is at most `R⁻` ([`IcParams::level_spacing_px`]
    /// against `min_spacing_px`), or `levels` when none is: records requested there take the
    /// fine strata (§2.8).
    pub fn fine_level(&self) -> u32 {
        (0..self.levels)
            .find(|&l| self.level_spacing_px(l) as f32 <= self.min_spacing_px)
            .unwrap_or(self.levels)
    }

    /// The strata `(M, N)` of a record requested at creation level `level`; `glossy`: it is
    /// made for a glossy lobe from the cache (`RECORD_FLAG_GLOSSY`), whose radiance
    /// coefficients keep `strata_m × strata_n` at every level (§2.8).
    /// With `strata_falloff`, the fine strata fall off below the fine level ([`falloff_strata`]).
    pub fn strata_at(&self, level: u32, glossy: bool) -> (u32, u32) {
        let fine_level = self.fine_level();
        if level < fine_level || glossy {
            (self.strata_m, self.strata_n)
        } else if self.strata_falloff {
            falloff_strata(self.fine_strata_m, self.fine_strata_n, level - fine_level)
        } else {
            (self.fine_strata_m, self.fine_strata_n)
        }
    }

    /// Candidate spacing in pixels of creation level `level` (0 = coarsest): `2^(levels−1−level)`.
    pub fn level_spacing_px(&self, level: u32) -> u32 {
        1u32 << self.levels.saturating_sub(1).saturating_sub(level).min(15)
    }

    /// True when every field is in its meaningful range (positive accuracies and strata,
    /// `min_spacing_px <= max_spacing_px`, …).
    pub fn is_valid(&self) -> bool {
        self.accuracy > 0.0
            && self.kappa >= crate::KAPPA_MIN
            && self.min_spacing_px > 0.0
            && self.min_spacing_px <= self.max_spacing_px
            && self.strata_m >= 1
            && self.strata_n >= 3
            && self.fine_strata_m >= 1
            && self.fine_strata_n >= 3
            && self.hole_threshold >= 0.0
            && self.levels >= 1
            && self.creation_strictness > 0.0
            && self.creation_strictness <= 1.0
            && self.front_tolerance_px >= 0.0
            && self.temporal_accuracy >= 0.0
            && self.max_age_frames >= 0.0
    }
}

/// The strata `(M', N')` of a record `steps` levels finer than the fine level, from the fine
/// strata `m × n` (§2.8): `M' = round(m / √2^steps)` (at least 1), `N' = round(n · M'/m)` (at
/// least 3), so the rays halve per level and the strata keep their shape. The rounding is exact:
/// `M'` is the integer `k` nearest to `x = m/√2^steps`, found by comparing `(k ± ½)²` with
/// `x² = m²/2^steps`, all exact in `f32` for `m ≤ 1728` and `steps ≤ 30` (the GLSL twin `falloff_strata` of
/// shaders/common/ircache_math.glsl computes the same in the same way).
pub fn falloff_strata(m: u32, n: u32, steps: u32) -> (u32, u32) {
    if steps == 0 || m == 0 {
        return (m, n);
    }
    // Halving is exact (m² < 2²⁴, far from the subnormals).
    let mut x2 = (m * m) as f32;
    for _ in 0..steps.min(30) {
        x2 *= 0.5;
    }
    let mut k = x2.sqrt().round() as u32;
    while (k as f32 + 0.5) * (k as f32 + 0.5) <= x2 {
        k += 1;
    }
    while k > 0 && (k as f32 - 0.5) * (k as f32 - 0.5) > x2 {
        k -= 1;
    }
    let m2 = k.max(1);
    let n2 = ((2 * n * m2 + m) / (2 * m)).max(3);
    (m2, n2)
}
