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
//! Why each default is what it is, in a sentence each (the measurements behind them, with their
//! commands, are in `bench/history.md`, *IcParams presets*):
//! - draft trades accuracy for speed (fewer rays, bigger zones, fewer refreshes) and is the
//!   preset of tests and previews: on lavapipe the rays per record are the dominant cost;
//! - the default R⁻ of 4 px gave the Cornell box the relMSE of 2 px with 40 % fewer records;
//! - the default κ of 0.75 mends the too-dark bands that κ = 0.5's wide zones leave under the
//!   courtyard's ledges (relMSE −24 %, block RMSE −30 % for 10–25 % more time);
//! - 12×36 strata rather than the course's 16×48 make the frame cheaper by more than its error
//!   grows (docs/cache-frame.md §7.1), and the fine 8×24 strata at the levels no wider than R⁻
//!   cut the courtyard's record rays by 59 % for 7 % more relMSE;
//! - the default's strata falloff cuts another 27 % of the courtyard's record rays for 8–9 % more
//!   own relMSE;
//! - draft's `Δt_max` of 8 frames keeps the kept records' error below a per-frame rebuild's
//!   with about a ninth of its record rays (docs/temporal.md §5).

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
