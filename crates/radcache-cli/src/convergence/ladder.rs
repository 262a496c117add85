//! The ladders of `radcache convergence`: which points are rendered (the path tracer over spp,
//! the cache over presets, accuracy and hemisphere size), rendering and measuring one point.

use anyhow::{Context as _, Result};
use radcache_cache::{IcParams, Preset, WeightKind};
use radcache_image::{compare, Image, Metrics};
use radcache_render::{
    render_ic, render_path, Budget, FrameOutput, GlossyLight, GpuScene, IcSettings, PathSettings,
};
use radcache_scene::Scene;
use radcache_vk::{Context, ShaderCompiler};

use radcache_image::equal_error::Match;

/// Seed of the path tracer's ladder points (each point adds its spp, so no two share samples).
pub const PT_SEED: u32 = 1000;
/// Seed of the cache's ladder points.
pub const IC_SEED: u32 = 1;
/// Seed of a reference rendered by the command (shared with no ladder point).
pub const REFERENCE_SEED: u32 = 7919;

/// Which ladder a point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ladder {
    /// The path tracer over spp (powers of two).
    Spp,
    /// The cache's quality presets.
    Preset,
    /// The cache's accuracy around the default preset.
    Accuracy,
    /// The cache's hemisphere strata around the default preset.
    Strata,
    /// The cache's presets with the glossy lobes' indirect light path traced per pixel
    /// (`GlossyLight::Paths`), in scenes with radiance records (docs/radiance-caching.md): the
    /// curve the [`Ladder::Preset`] points' per-pixel time to the same error is read from.
    GlossyPaths,
}

impl Ladder {
    /// The ladder's name in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            Ladder::Spp => "spp",
            Ladder::Preset => "preset",
            Ladder::Accuracy => "accuracy",
            Ladder::Strata => "strata",
            Ladder::GlossyPaths => "glossy_paths",
        }
    }
}

/// One cache point to render.
#[derive(Debug, Clone)]
pub struct IcCase {
    /// Its ladder.
    pub ladder: Ladder,
    /// Short label (CSV, plot, summary).
    pub label: String,
    /// The preset it starts from.
    pub preset: Preset,
    /// Its parameters.
    pub params: IcParams,
    /// Where glossy lobes' indirect light comes from.
    pub glossy: GlossyLight,
}

/// A rendered and measured point of any ladder.
#[derive(Debug, Clone)]
pub struct Point {
    /// Its ladder (the path tracer's is [`Ladder::Spp`]).
    pub ladder: Ladder,
    /// Short label.
    pub label: String,
    /// Samples per pixel (path tracer only).
    pub spp: Option<u32>,
    /// The cache's preset and parameters (cache only).
    pub ic: Option<(Preset, IcParams)>,
    /// Wall time of the frame, s.
    pub wall_s: f64,
    /// GPU time: the sum of the frame's pass timestamps, s.
    pub gpu_s: f64,
    /// Ray queries.
    pub rays: u64,
    /// Records at the end of the frame (cache only).
    pub records: Option<u64>,
    /// The `compare` metrics against the reference.
    pub metrics: Metrics,
    /// relMSE less the reference's own noise.
    pub own_relmse: f64,
    /// The path tracer's time to reach this point's own relMSE (cache only).
    pub matched: Option<Match>,
    /// The per-pixel glossy paths' time to reach this point's own relMSE ([`Ladder::Preset`]
    /// points of scenes with radiance records).
    pub matched_paths: Option<Match>,
    /// On the Pareto front of relMSE against wall time.
    pub pareto: bool,
}

impl Point {
    /// `"path"` or `"ic"`.
    pub fn method(&self) -> &'static str {
        if self.ic.is_some() {
            "ic"
        } else {
            "path"
        }
    }

    /// The path tracer's time to match over this point's wall time.
    pub fn speedup(&self) -> Option<f64> {
        self.matched.map(|m| m.time_s / self.wall_s)
    }
}

/// The path tracer's spp ladder: 1, 2, 4, …, `max_spp` (a power of two).
pub fn pt_ladder(max_spp: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&s| s.checked_mul(2))
        .take_while(|&s| s <= max_spp)
        .collect()
}

/// The `--accuracy` value of `params` for its weight kind: Ward's `a`, or `1/κ` for T&L.
pub fn accuracy_of(params: &IcParams) -> f32 {
    match params.weight_kind {
        WeightKind::Ward => params.accuracy,
        WeightKind::TabellionLamorlette => 1.0 / params.kappa,
    }
}

/// The weight kind's name on the command line.
pub fn weight_name(kind: WeightKind) -> &'static str {
    match kind {
        WeightKind::Ward => "ward",
        WeightKind::TabellionLamorlette => "tl",
    }
}

/// The preset's name on the command line and in the CSV.
pub fn preset_name(preset: Preset) -> &'static str {
    match preset {
        Preset::Draft => "draft",
        Preset::Default => "default",
        Preset::High => "high",
    }
}

/// The cache's points: the three presets; the accuracy of `weight` (Ward's `a`, or T&L's `κ`
/// through `a = 1/κ`) at the default preset's value × 2, 1.5, 0.75 and 0.5 (`quick`: × 2 and
/// 0.5); the strata 4×12, 8×24 and 24×72 (`quick`: 4×12 and 8×24) at the default preset
/// otherwise. The default preset (12×36) is the centre of both sweeps. With `glossy` (the scene
/// has radiance records) the three presets again with per-pixel glossy paths
/// ([`Ladder::GlossyPaths`]).
pub fn ic_cases(weight: WeightKind, quick: bool, glossy: bool) -> Vec<IcCase> {
    let with_weight = |preset| IcParams {
        weight_kind: weight,
        ..IcParams::preset(preset)
    };
    let mut cases: Vec<IcCase> = [Preset::Draft, Preset::Default, Preset::High]
        .into_iter()
        .map(|preset| IcCase {
            ladder: Ladder::Preset,
            label: preset_name(preset).to_string(),
            preset,
            params: with_weight(preset),
            glossy: GlossyLight::Records,
        })
        .collect();
    if glossy {
        for preset in [Preset::Draft, Preset::Default, Preset::High] {
            cases.push(IcCase {
                ladder: Ladder::GlossyPaths,
                label: format!("{} glossy paths", preset_name(preset)),
                preset,
                params: with_weight(preset),
                glossy: GlossyLight::Paths,
            });
        }
    }
    let base = with_weight(Preset::Default);
    let factors: &[f32] = if quick {
        &[2.0, 0.5]
    } else {
        &[2.0, 1.5, 0.75, 0.5]
    };
    for &f in factors {
        let a = accuracy_of(&base) * f;
        let mut params = base;
        let label = match weight {
            WeightKind::Ward => {
                params.accuracy = a;
                format!("a={}", short(a))
            }
            WeightKind::TabellionLamorlette => {
                params.kappa = 1.0 / a;
                format!("kappa={}", short(params.kappa))
            }
        };
        cases.push(IcCase {
            ladder: Ladder::Accuracy,
            label,
            preset: Preset::Default,
            params,
            glossy: GlossyLight::Records,
        });
    }
    let strata: &[(u32, u32)] = if quick {
        &[(4, 12), (8, 24)]
    } else {
        &[(4, 12), (8, 24), (24, 72)]
    };
    for &(m, n) in strata {
        let params = base.with_strata(m, n);
        cases.push(IcCase {
            ladder: Ladder::Strata,
            label: format!("strata {m}x{n}"),
            preset: Preset::Default,
            params,
            glossy: GlossyLight::Records,
        });
    }
    cases
}

/// A parameter value with at most three decimals and no trailing zeros.
fn short(v: f32) -> String {
    let text = format!("{v:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// What every point of a run shares: the GPU, the scene, the frame, the reference.
pub struct Bench<'a> {
    /// The one GPU context of the run.
    pub ctx: &'a Context,
    /// The shader compiler (its cache keeps the compiled shaders after the warm-up).
    pub shaders: &'a ShaderCompiler,
    /// The scene.
    pub scene: &'a Scene,
    /// Image size.
    pub size: (u32, u32),
    /// Frame number.
    pub frame: u32,
    /// Scene time of the frame, s.
    pub time: f32,
    /// The technique switches of every cache point (`--set KEY=VALUE`).
    pub sets: &'a [String],
}

impl std::fmt::Debug for Bench<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bench")
            .field("size", &self.size)
            .field("frame", &self.frame)
            .field("time", &self.time)
            .finish_non_exhaustive()
    }
}

impl Bench<'_> {
    fn path_settings(&self, spp: u32, seed: u32) -> PathSettings {
        PathSettings {
            width: self.size.0,
            height: self.size.1,
            budget: Budget::Samples(spp),
            seed,
            frame: self.frame,
            time: self.time,
            ..PathSettings::default()
        }
    }

    /// Renders both methods once at a small size, so that no point's time holds shader
    /// compilation (the compiler caches by source and defines; the cache's parameters are push
    /// constants, so one warm-up covers every point).
    pub fn warm_up(&self, gpu: &mut GpuScene) -> Result<()> {
        let mut ic = IcSettings {
            width: 16,
            height: 16,
            params: IcParams::draft(),
            sub_frames: 1,
            frame: self.frame,
            time: self.time,
            ..IcSettings::default()
        };
        crate::args::ic::apply_sets(self.sets, &mut ic)?;
        render_ic(self.ctx, self.shaders, self.scene, gpu, &ic, &mut |_| {})
            .context("warm-up frame of the cache")?;
        if self.scene.plan().radiance_cache() {
            let paths = IcSettings {
                glossy: GlossyLight::Paths,
                ..ic
            };
            render_ic(self.ctx, self.shaders, self.scene, gpu, &paths, &mut |_| {})
                .context("warm-up frame of the cache with per-pixel glossy paths")?;
        }
        let mut pt = self.path_settings(1, REFERENCE_SEED);
        (pt.width, pt.height) = (16, 16);
        render_path(self.ctx, self.shaders, self.scene, gpu, &pt, &mut |_| {})
            .context("warm-up frame of the path tracer")?;
        Ok(())
    }

    /// Renders the reference with the path tracer at `spp` (seed [`REFERENCE_SEED`]).
    pub fn reference(
        &self,
        gpu: &mut GpuScene,
        spp: u32,
        progress: &mut dyn FnMut(u32, u32, f64),
    ) -> Result<(Image, FrameOutput)> {
        let settings = self.path_settings(spp, REFERENCE_SEED);
        let out = render_path(
            self.ctx,
            self.shaders,
            self.scene,
            gpu,
            &settings,
            &mut |p| progress(p.done, p.total, p.elapsed_s),
        )
        .context("rendering the reference")?;
        let image = Image::from_pixels(out.width, out.height, out.pixels.clone())?;
        Ok((image, out))
    }

    /// Renders and measures the path tracer at `spp`.
    pub fn path(&self, gpu: &mut GpuScene, reference: &Image, spp: u32) -> Result<Point> {
        let settings = self.path_settings(spp, PT_SEED + spp);
        let out = render_path(
            self.ctx,
            self.shaders,
            self.scene,
            gpu,
            &settings,
            &mut |_| {},
        )
        .with_context(|| format!("path tracer at {spp} spp"))?;
        let mut point = measure(out, reference, Ladder::Spp, format!("pt {spp} spp"))?;
        point.spp = Some(spp);
        Ok(point)
    }

    /// Renders and measures one cache point.
    pub fn ic(&self, gpu: &mut GpuScene, reference: &Image, case: &IcCase) -> Result<Point> {
        let mut settings = IcSettings {
            width: self.size.0,
            height: self.size.1,
            params: case.params,
            seed: IC_SEED,
            frame: self.frame,
            time: self.time,
            ..IcSettings::preset(case.preset)
        };
        crate::args::ic::apply_sets(self.sets, &mut settings)?;
        settings.glossy = case.glossy;
        let (out, stats) = render_ic(
            self.ctx,
            self.shaders,
            self.scene,
            gpu,
            &settings,
            &mut |_| {},
        )
        .with_context(|| format!("cache point {}", case.label))?;
        let mut point = measure(out, reference, case.ladder, case.label.clone())?;
        point.ic = Some((case.preset, case.params));
        point.records = Some(stats.records);
        Ok(point)
    }
}

/// The point of a rendered frame: its times, rays and metrics against `reference`.
fn measure(out: FrameOutput, reference: &Image, ladder: Ladder, label: String) -> Result<Point> {
    let gpu_s = out.passes_ms.values().sum::<f64>() / 1000.0;
    let rays = out.rays.values().sum();
    let wall_s = out.time_s;
    let image = Image::from_pixels(out.width, out.height, out.pixels)?;
    let metrics = compare(reference, &image).with_context(|| format!("measuring {label}"))?;
    Ok(Point {
        ladder,
        label,
        spp: None,
        ic: None,
        wall_s,
        gpu_s,
        rays,
        records: None,
        own_relmse: metrics.relmse,
        metrics,
        matched: None,
        matched_paths: None,
        pareto: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spp_ladder_is_the_powers_of_two_up_to_the_maximum() {
        assert_eq!(pt_ladder(1), vec![1]);
        assert_eq!(pt_ladder(16), vec![1, 2, 4, 8, 16]);
    }

    #[test]
    fn accuracy_sweep_varies_the_selected_weights_parameter() {
        let tl = ic_cases(WeightKind::TabellionLamorlette, true, false);
        let labels: Vec<&str> = tl.iter().map(|c| c.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "draft",
                "default",
                "high",
                "kappa=0.375",
                "kappa=1.5",
                "strata 4x12",
                "strata 8x24"
            ]
        );
        assert_eq!(tl[3].params.kappa, IcParams::default().kappa / 2.0);
        assert_eq!(tl[3].params.accuracy, IcParams::default().accuracy);
        let ward = ic_cases(WeightKind::Ward, false, false);
        let sweep: Vec<f32> = ward
            .iter()
            .filter(|c| c.ladder == Ladder::Accuracy)
            .map(|c| c.params.accuracy)
            .collect();
        let expected = [0.3, 0.225, 0.1125, 0.075];
        assert_eq!(sweep.len(), expected.len());
        for (a, b) in sweep.iter().zip(expected) {
            assert!((a - b).abs() < 1e-6, "{sweep:?}");
        }
        assert!(ward
            .iter()
            .all(|c| c.params.weight_kind == WeightKind::Ward));
        assert!(ward.iter().all(|c| c.params.is_valid()));
        assert!(ward.iter().all(|c| c.glossy == GlossyLight::Records));
    }

    #[test]
    fn glossy_scenes_add_the_presets_with_per_pixel_paths() {
        let cases = ic_cases(WeightKind::TabellionLamorlette, true, true);
        let paths: Vec<&IcCase> = cases
            .iter()
            .filter(|c| c.ladder == Ladder::GlossyPaths)
            .collect();
        let labels: Vec<&str> = paths.iter().map(|c| c.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "draft glossy paths",
                "default glossy paths",
                "high glossy paths"
            ]
        );
        assert!(paths.iter().all(|c| c.glossy == GlossyLight::Paths));
        let presets: Vec<&IcCase> = cases
            .iter()
            .filter(|c| c.ladder == Ladder::Preset)
            .collect();
        assert_eq!(presets.len(), 3);
        assert!(presets.iter().all(|c| c.glossy == GlossyLight::Records));
    }
}
