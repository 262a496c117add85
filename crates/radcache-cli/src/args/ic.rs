//! The cache's options of `radcache render` (`--method ic`): a quality preset, then any of its
//! parameters overridden one by one.

use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use radcache_cache::{ErrorControl, IcParams, Preset, WeightKind};
use radcache_render::{
    AntiAliasing, EmitterLight, EmitterShadows, GlossyLight, GlossySpacing, PathGridMode, SkyLight,
    SpecularPaths, SplatMode,
};

/// Cache quality preset.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    /// Fast previews (Tabellion–Lamorlette κ = 0.75, Ward's a = 0.3 with `--weight ward`; 8×24
    /// strata).
    Draft,
    /// The default (κ = 0.75, Ward's a = 0.15; 12×36 strata, 8×24 where records are at least as
    /// dense as R⁻).
    Default,
    /// Offline quality (κ = 1.5, Ward's a = 0.1; 24×72 strata).
    High,
}

/// Interpolation weight of the cache.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weight {
    /// Tabellion–Lamorlette (default): bounded, continuous at the zone's edge.
    Tl,
    /// Ward's split-sphere weight.
    Ward,
}

/// Where a constant environment's light (a sky) enters a cache frame.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sky {
    /// Through the records (default): the sky's irradiance is interpolated with the indirect
    /// light and the direct pass casts no ray for it.
    Records,
    /// Sampled by the direct pass at every pixel.
    Direct,
}

/// How the direct pass estimates the light of emissive triangles.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Emitters {
    /// The unshadowed light in closed form, its shadows sampled (default; where the plan allows:
    /// a few untextured emitters, see `radcache info`).
    Analytic,
    /// Light and BSDF sampling with MIS.
    Sampled,
}

/// How many shadow rays the closed-form emitters' light casts after the first sub-frame.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum EmitterShadowsArg {
    /// After the first sub-frame, a quarter of the direct samples in penumbrae (as the
    /// sub-frames so far saw them), one ray where the emitters were wholly visible or wholly
    /// hidden, none (and no punctual light's shadow ray) where the pixel's whole 3×3
    /// neighbourhood saw the same in the first sub-frame (default; docs/cache-frame.md §8.2).
    Adaptive,
    /// A quarter of the direct samples at every pixel, every punctual light's shadow ray at
    /// every sub-frame.
    Fixed,
}

/// Where glossy lobes take their indirect light from in a cache frame.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Glossy {
    /// Radiance records for lobes of roughness ≥ 0.6 (default; where the plan has such
    /// materials, see `radcache info`), sharper lobes path traced per pixel.
    Records,
    /// As `records`, each record's coefficients constant over its zone (no gradients): for
    /// measuring what the gradients bring.
    RecordsNoGradients,
    /// Every lobe's indirect light path traced per pixel.
    Paths,
}

/// How records for glossy lobes from the cache are spaced (docs/radiance-caching.md §9).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum GlossySpacingArg {
    /// Also by the glossy gradient limit: density follows the incoming radiance's directional
    /// detail (default).
    Lobe,
    /// By the irradiance's rule alone, as every other record.
    Irradiance,
}

/// How often a cache frame splats its records (docs/cache-frame.md §6.5).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Splat {
    /// Once per frame at the pixel centres; the other sub-frames interpolate each sample's
    /// cached light between the nearest centres that match it (default).
    Once,
    /// At every sub-frame's own samples (one splat and one hole-filling pass per sub-frame).
    PerSubFrame,
}

/// Whether the gathers of new records share a radiance grid (docs/cache-frame.md §4.1).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathGridArg {
    /// Where every material is Lambertian, a gather path ends at a vertex whose grid cell holds
    /// enough continuations with their mean (default).
    On,
    /// Every gather path continues to its end.
    Off,
}

/// Whether the fine strata fall off below the first level that takes them
/// (docs/irradiance-cache.md §2.8).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrataFalloffArg {
    /// Each finer level halves their rays (the default preset's).
    On,
    /// Every level from the first takes them whole (draft's and high's).
    Off,
}

/// Whose paths a pixel's specular lobe takes its indirect light from (docs/materials.md §10).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecularPathsArg {
    /// Its own and those of its 3×3 neighbours whose lobes overlap its own (default).
    Pooled,
    /// Its own alone.
    PerPixel,
}

/// What adaptive anti-aliasing's added sub-frames shade (docs/cache-frame.md §7.1, §7.2).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum AaScope {
    /// Only the pixels whose own sampling error still needs samples, each batch as far as
    /// they need (default).
    Pixel,
    /// Every pixel, until the whole frame's estimate meets the target.
    Frame,
}

/// The rule that sets a record's radius.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorControlArg {
    /// Ward's split sphere: the harmonic-mean hit distance (default).
    SplitSphere,
    /// Schwarzhaupt et al.'s Hessian error control (docs/irradiance-cache.md §10).
    Hessian,
}

/// The cache's command-line options.
#[derive(Args, Debug)]
pub struct IcArgs {
    /// Cache quality preset (`--method ic`).
    #[arg(long, value_enum, default_value_t = Quality::Default)]
    pub quality: Quality,
    /// Cache interpolation weight (`--method ic`).
    #[arg(long, value_enum)]
    pub weight: Option<Weight>,
    /// Record radius rule (`--method ic`): split-sphere (default) or hessian.
    #[arg(long, value_enum)]
    pub error_control: Option<ErrorControlArg>,
    /// Cache accuracy, smaller is more accurate: 1/κ for the default Tabellion–Lamorlette weight
    /// (the presets: 1.33, 1.33, 0.67), Ward's a with `--weight ward` (0.3, 0.15, 0.1).
    #[arg(long)]
    pub accuracy: Option<f32>,
    /// Hemisphere strata of a record, polar × azimuthal (`--strata 16x48`); M·N ≤ 1728. The
    /// fine strata stay the preset's where they have fewer rays, else become these too.
    #[arg(long, value_name = "MxN")]
    pub strata: Option<String>,
    /// Strata of the records requested at creation levels no wider than R⁻, but those made for
    /// glossy lobes (`--fine-strata 8x24`; docs/irradiance-cache.md §2.8).
    #[arg(long, value_name = "MxN")]
    pub fine_strata: Option<String>,
    /// Whether each creation level finer than the first that takes the fine strata halves their
    /// rays (`on` in the default preset; docs/irradiance-cache.md §2.8).
    #[arg(long, value_enum)]
    pub strata_falloff: Option<StrataFalloffArg>,
    /// Record validity radius bounds R⁻,R⁺ in pixels (`--spacing 2,20`).
    #[arg(long, value_name = "MIN,MAX")]
    pub spacing: Option<String>,
    /// Σw (in units of one full record) below which a pixel is a hole that gets a record.
    #[arg(long)]
    pub hole_threshold: Option<f32>,
    /// Temporal accuracy `a_t` of records kept across frames with moving geometry or lights: a
    /// record is evaluated again once its light may have changed by this fraction (smaller is
    /// more accurate); default 0.1 (draft), 0.05 (default), 0.02 (high); docs/temporal.md §3.3.
    #[arg(long, value_name = "A_T")]
    pub temporal_accuracy: Option<f32>,
    /// The longest life of a record kept across frames with moving geometry or lights, in
    /// frames (`Δt_max`); default 8 (draft), 30 (default), 15 (high); docs/temporal.md §3.3.
    #[arg(long, value_name = "FRAMES")]
    pub max_age: Option<f32>,
    /// Jittered sub-frames of the cache (anti-aliasing); default 8.
    #[arg(long)]
    pub sub_frames: Option<u32>,
    /// Adaptive anti-aliasing (`--method ic`): after the cache's sub-frames, shade more until
    /// the estimated relMSE of the sub-frame sampling is at most this (0: exactly
    /// `--sub-frames`); default 2e-3 (draft), 5e-4 (default), 2e-4 (high).
    #[arg(long, value_name = "RELMSE")]
    pub aa_target: Option<f64>,
    /// The most sub-frames adaptive anti-aliasing shades (`--method ic`); default 64.
    #[arg(long, value_name = "N")]
    pub max_sub_frames: Option<u32>,
    /// What adaptive anti-aliasing shades after the cache's sub-frames (`--method ic`).
    #[arg(long, value_enum, default_value_t = AaScope::Pixel)]
    pub aa_scope: AaScope,
    /// Direct-lighting samples per pixel and sub-frame (`--method ic`; one ray each); default 16.
    #[arg(long)]
    pub direct_samples: Option<u32>,
    /// Where a constant environment's light (a sky) enters the frame (`--method ic`).
    #[arg(long, value_enum, default_value_t = Sky::Records)]
    pub sky: Sky,
    /// How the direct pass estimates the light of emissive triangles (`--method ic`).
    #[arg(long, value_enum, default_value_t = Emitters::Analytic)]
    pub emitters: Emitters,
    /// How many shadow rays the closed-form emitters cast after the first sub-frame
    /// (`--method ic`, `--emitters analytic`).
    #[arg(long, value_enum, default_value_t = EmitterShadowsArg::Adaptive)]
    pub emitter_shadows: EmitterShadowsArg,
    /// Where glossy lobes take their indirect light from (`--method ic`).
    #[arg(long, value_enum, default_value_t = Glossy::Records)]
    pub glossy: Glossy,
    /// How records for glossy lobes from the cache are spaced (`--method ic`).
    #[arg(long, value_enum, default_value_t = GlossySpacingArg::Lobe)]
    pub glossy_spacing: GlossySpacingArg,
    /// How often the records are splatted (`--method ic`).
    #[arg(long, value_enum, default_value_t = Splat::Once)]
    pub splat: Splat,
    /// Whether the records' gather paths share a radiance grid (`--method ic`).
    #[arg(long, value_enum, default_value_t = PathGridArg::On)]
    pub path_grid: PathGridArg,
    /// Whose paths a pixel's specular lobe takes its indirect light from (`--method ic`).
    #[arg(long, value_enum, default_value_t = SpecularPathsArg::Pooled)]
    pub specular_paths: SpecularPathsArg,
}

fn pair<T: std::str::FromStr>(text: &str, sep: char, flag: &str) -> Result<(T, T)> {
    let (a, b) = text
        .split_once(sep)
        .with_context(|| format!("{flag} {text:?}: expected two values separated by {sep:?}"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<T>()
            .ok()
            .with_context(|| format!("{flag} {text:?}: {v:?} is not a number"))
    };
    Ok((parse(a)?, parse(b)?))
}

impl IcArgs {
    /// The quality preset.
    pub fn preset(&self) -> Preset {
        match self.quality {
            Quality::Draft => Preset::Draft,
            Quality::Default => Preset::Default,
            Quality::High => Preset::High,
        }
    }

    /// Adaptive anti-aliasing (docs/cache-frame.md §7.1; defaults `AntiAliasing::preset`),
    /// `None` with `--aa-target 0`.
    pub fn anti_aliasing(&self) -> Result<Option<AntiAliasing>> {
        let preset = AntiAliasing::preset(self.preset());
        let target = self.aa_target.unwrap_or(preset.target);
        if !(target.is_finite() && target >= 0.0) {
            bail!(
                "--aa-target {target}: expected a relMSE ≥ 0 (0 turns adaptive anti-aliasing off)"
            );
        }
        let max_sub_frames = self.max_sub_frames.unwrap_or(preset.max_sub_frames);
        if max_sub_frames == 0 {
            bail!("--max-sub-frames 0: expected at least 1");
        }
        Ok((target > 0.0).then_some(AntiAliasing {
            target,
            max_sub_frames,
            per_pixel: self.aa_scope == AaScope::Pixel,
        }))
    }

    /// How the emitters' direct light is estimated.
    pub fn emitter_light(&self) -> EmitterLight {
        match self.emitters {
            Emitters::Analytic => EmitterLight::Analytic,
            Emitters::Sampled => EmitterLight::Sampled,
        }
    }

    /// How many shadow rays the closed-form emitters cast after the first sub-frame.
    pub fn emitter_shadows(&self) -> EmitterShadows {
        match self.emitter_shadows {
            EmitterShadowsArg::Adaptive => EmitterShadows::Adaptive,
            EmitterShadowsArg::Fixed => EmitterShadows::Fixed,
        }
    }

    /// Where glossy lobes' indirect light comes from.
    pub fn glossy_light(&self) -> GlossyLight {
        match self.glossy {
            Glossy::Records => GlossyLight::Records,
            Glossy::RecordsNoGradients => GlossyLight::RecordsWithoutGradients,
            Glossy::Paths => GlossyLight::Paths,
        }
    }

    /// How often the records are splatted.
    pub fn splat_mode(&self) -> SplatMode {
        match self.splat {
            Splat::Once => SplatMode::Once,
            Splat::PerSubFrame => SplatMode::PerSubFrame,
        }
    }

    /// Whether the gathers share a radiance grid.
    pub fn path_grid_mode(&self) -> PathGridMode {
        match self.path_grid {
            PathGridArg::On => PathGridMode::On,
            PathGridArg::Off => PathGridMode::Off,
        }
    }

    /// Whose paths the specular lobes take.
    pub fn specular_paths(&self) -> SpecularPaths {
        match self.specular_paths {
            SpecularPathsArg::Pooled => SpecularPaths::Pooled,
            SpecularPathsArg::PerPixel => SpecularPaths::PerPixel,
        }
    }

    /// How records for glossy lobes are spaced.
    pub fn glossy_spacing(&self) -> GlossySpacing {
        match self.glossy_spacing {
            GlossySpacingArg::Lobe => GlossySpacing::Lobe,
            GlossySpacingArg::Irradiance => GlossySpacing::Irradiance,
        }
    }

    /// Where the sky's light goes.
    pub fn sky_light(&self) -> SkyLight {
        match self.sky {
            Sky::Records => SkyLight::Records,
            Sky::Direct => SkyLight::Direct,
        }
    }

    /// The cache parameters: the preset with the overrides applied, checked.
    pub fn params(&self) -> Result<IcParams> {
        let mut params = IcParams::preset(self.preset());
        if let Some(w) = self.weight {
            params.weight_kind = match w {
                Weight::Tl => WeightKind::TabellionLamorlette,
                Weight::Ward => WeightKind::Ward,
            };
        }
        if let Some(e) = self.error_control {
            params.error_control = match e {
                ErrorControlArg::SplitSphere => ErrorControl::SplitSphere,
                ErrorControlArg::Hessian => ErrorControl::Hessian,
            };
        }
        if let Some(a) = self.accuracy {
            if !(a.is_finite() && a > 0.0) {
                bail!("--accuracy must be a positive number, got {a}");
            }
            params.accuracy = a;
            params.kappa = 1.0 / a;
        }
        let strata = |text: &String, flag: &str| -> Result<(u32, u32)> {
            let (m, n) = pair::<u32>(&text.to_lowercase(), 'x', flag)?;
            if m < 1 || n < 3 || m.saturating_mul(n) > 1728 {
                bail!("{flag} {text}: need M ≥ 1, N ≥ 3 and M·N ≤ 1728");
            }
            Ok((m, n))
        };
        if let Some(text) = &self.strata {
            let (m, n) = strata(text, "--strata")?;
            params = params.with_strata(m, n);
        }
        if let Some(text) = &self.fine_strata {
            (params.fine_strata_m, params.fine_strata_n) = strata(text, "--fine-strata")?;
        }
        if let Some(falloff) = self.strata_falloff {
            params.strata_falloff = falloff == StrataFalloffArg::On;
        }
        if let Some(text) = &self.spacing {
            let (lo, hi) = pair::<f32>(text, ',', "--spacing")?;
            if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi) {
                bail!("--spacing {text}: need 0 < MIN ≤ MAX");
            }
            (params.min_spacing_px, params.max_spacing_px) = (lo, hi);
        }
        if let Some(t) = self.hole_threshold {
            if !(t.is_finite() && (0.0..=1.0).contains(&t)) {
                bail!("--hole-threshold must lie in [0, 1], got {t}");
            }
            params.hole_threshold = t;
        }
        if let Some(a) = self.temporal_accuracy {
            if !(a.is_finite() && a > 0.0) {
                bail!("--temporal-accuracy must be a positive number, got {a}");
            }
            params.temporal_accuracy = a;
        }
        if let Some(f) = self.max_age {
            if !(f.is_finite() && f >= 1.0) {
                bail!("--max-age must be at least 1 frame, got {f}");
            }
            params.max_age_frames = f;
        }
        if !params.is_valid() {
            bail!("invalid cache parameters: {params:?}");
        }
        Ok(params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        ic: IcArgs,
    }

    fn params(args: &[&str]) -> Result<IcParams> {
        let cli = Cli::try_parse_from(std::iter::once("radcache").chain(args.iter().copied()))?;
        cli.ic.params()
    }

    #[test]
    fn temporal_accuracy_and_max_age_override_the_preset() {
        let draft = IcParams::preset(Preset::Draft);
        let p = params(&["--quality", "draft"]).unwrap();
        assert_eq!(
            (p.temporal_accuracy, p.max_age_frames),
            (draft.temporal_accuracy, draft.max_age_frames)
        );
        let p = params(&[
            "--quality",
            "draft",
            "--temporal-accuracy",
            "0.03",
            "--max-age",
            "10",
        ])
        .unwrap();
        assert_eq!((p.temporal_accuracy, p.max_age_frames), (0.03, 10.0));
        for (flag, bad) in [
            ("--temporal-accuracy", "0"),
            ("--temporal-accuracy", "NaN"),
            ("--max-age", "0.5"),
            ("--max-age", "inf"),
        ] {
            let err = params(&[flag, bad]).unwrap_err().to_string();
            assert!(err.contains(flag), "{flag} {bad}: {err}");
        }
    }
}
