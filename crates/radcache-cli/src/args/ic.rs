//! The cache's options of `radcache render` (`--method ic`): a quality preset, then any of its
//! parameters overridden one by one.

use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use radcache_cache::{ErrorControl, IcParams, Preset, WeightKind};
use radcache_render::{AntiAliasing, IcSettings};

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

/// Whether the fine strata fall off below the first level that takes them
/// (docs/irradiance-cache.md §2.8).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrataFalloffArg {
    /// Each finer level halves their rays (the default preset's).
    On,
    /// Every level from the first takes them whole (draft's and high's).
    Off,
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
    /// A technique switch, `KEY=VALUE` (repeatable; `--set help` lists every key with its
    /// values and default).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// Applies every `--set KEY=VALUE` of `sets` to `settings`, in order (a later one wins).
pub fn apply_sets(sets: &[String], settings: &mut IcSettings) -> Result<()> {
    for text in sets {
        let (key, value) = text
            .split_once('=')
            .with_context(|| format!("--set {text:?}: expected KEY=VALUE (`--set help`)"))?;
        settings
            .set_technique(key.trim(), value.trim())
            .map_err(|e| anyhow::anyhow!("--set {text}: {e}"))?;
    }
    Ok(())
}

/// `radcache render --set help`: every technique switch with its values, default and one line.
pub fn set_help_text() -> String {
    let mut s = String::from(
        "Technique switches of the cache (`--set KEY=VALUE`, repeatable; the default first):\n",
    );
    for t in IcSettings::technique_help() {
        let others: Vec<&str> = t
            .values
            .iter()
            .copied()
            .filter(|v| *v != t.default)
            .collect();
        s.push_str(&format!(
            "  {:<16} {} (or {}): {}\n",
            t.key,
            t.default,
            others.join(", "),
            t.help
        ));
    }
    s
}

/// The error for a technique flag that `--set` replaced (`--sky direct` is now
/// `--set sky=direct`), if `args` holds one.
pub fn removed_flag(args: &[String]) -> Option<String> {
    args.iter().find_map(|arg| {
        let flag = arg.split_once('=').map_or(arg.as_str(), |(f, _)| f);
        IcSettings::TECHNIQUES
            .iter()
            .find(|key| flag == format!("--{}", key.replace('_', "-")))
            .map(|key| {
                format!(
                    "`{flag}` was replaced by `--set {key}=VALUE` (`radcache render --set help` \
                     lists the switches)"
                )
            })
    })
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

    /// Whether `--set help` was asked for.
    pub fn set_help(&self) -> bool {
        self.set.iter().any(|s| s == "help")
    }

    /// Applies every `--set KEY=VALUE` to `settings` ([`apply_sets`]).
    pub fn apply_sets(&self, settings: &mut IcSettings) -> Result<()> {
        apply_sets(&self.set, settings)
    }

    /// The cache options as command-line arguments that give the same configuration: the
    /// quality, every override given, and every technique switch of `settings` (the resolved
    /// ones) as `--set`.
    pub fn config_args(&self, settings: &IcSettings) -> Vec<String> {
        fn name<T: ValueEnum>(v: T) -> String {
            v.to_possible_value()
                .map_or_else(String::new, |p| p.get_name().to_string())
        }
        let mut out = vec!["--quality".to_string(), name(self.quality)];
        let mut push = |flag: &str, value: Option<String>| {
            if let Some(v) = value {
                out.push(flag.to_string());
                out.push(v);
            }
        };
        push("--weight", self.weight.map(name));
        push("--error-control", self.error_control.map(name));
        push("--accuracy", self.accuracy.map(|v| v.to_string()));
        push("--strata", self.strata.clone());
        push("--fine-strata", self.fine_strata.clone());
        push("--strata-falloff", self.strata_falloff.map(name));
        push("--spacing", self.spacing.clone());
        push(
            "--hole-threshold",
            self.hole_threshold.map(|v| v.to_string()),
        );
        push(
            "--temporal-accuracy",
            self.temporal_accuracy.map(|v| v.to_string()),
        );
        push("--max-age", self.max_age.map(|v| v.to_string()));
        push("--sub-frames", self.sub_frames.map(|v| v.to_string()));
        push("--aa-target", self.aa_target.map(|v| v.to_string()));
        push(
            "--max-sub-frames",
            self.max_sub_frames.map(|v| v.to_string()),
        );
        push("--aa-scope", Some(name(self.aa_scope)));
        push(
            "--direct-samples",
            self.direct_samples.map(|v| v.to_string()),
        );
        for (key, value) in settings.techniques() {
            push("--set", Some(format!("{key}={value}")));
        }
        out
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
