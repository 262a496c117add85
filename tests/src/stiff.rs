//! The stiff and extreme suite's renders and figures (issue 8), shared by the `stiff` tests and
//! `cargo xtask stiff`: a scene of `radcache_scene::assets::stiff` rendered by one method, and
//! compared with what the scene is checked against.
//!
//! Figures of one render against its reference (`radcache_image::compare`): relMSE, 8×8-block
//! RMSE, the non-finite pixel count (pixels the readback found non-finite, plus any left in the
//! output: both must be 0), and the **leak**: the candidate's mean luminance over the pixels that
//! must be dark. For a [`StiffCheck::Dark`] scene that is every pixel and the leak is absolute
//! (W/(sr·m²)); for a path-traced reference the dark pixels are the 8×8 blocks whose reference
//! mean luminance is at most 2 % of the reference's image mean, and the leak is relative to that
//! mean (the reference's own value over the same pixels is subtracted, so an exact render leaks 0
//! within noise).
//! Scenes without dark pixels, and analytic ones, have no leak figure.

use std::time::Instant;

use radcache_cache::{IcParams, Preset};
use radcache_image::{compare, Image, Metrics};
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcSettings, PathSettings};
use radcache_scene::assets::stiff::StiffCheck;
use radcache_scene::Scene;
use radcache_vk::{Context, ShaderCompiler};

/// A rendering method of the suite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The irradiance cache at a preset.
    Ic(Preset),
    /// The path tracer at this many samples per pixel.
    Path(u32),
}

impl Method {
    /// The table label: `ic-draft`, `ic-default`, `ic-high`, `path-64`.
    pub fn label(&self) -> String {
        match self {
            Method::Ic(p) => format!("ic-{}", format!("{p:?}").to_lowercase()),
            Method::Path(spp) => format!("path-{spp}"),
        }
    }
}

/// Image size and effort of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Effort {
    /// Square image side, pixels.
    pub size: u32,
    /// Cache sub-frames.
    pub sub_frames: u32,
    /// Cache direct-light samples per pixel and sub-frame.
    pub direct_samples: u32,
    /// Seed.
    pub seed: u32,
}

/// One render: its pixels, how many were non-finite, and its wall time.
#[derive(Clone, Debug)]
pub struct Render {
    /// The image.
    pub image: Image,
    /// Non-finite pixels (readback count plus any left in the output).
    pub nonfinite: u64,
    /// Wall time, s.
    pub time_s: f64,
    /// Records of a cache render (0 for the path tracer).
    pub records: u64,
}

/// Renders `scene` with `method`.
pub fn render(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    method: Method,
    effort: Effort,
) -> Result<Render, radcache_render::Error> {
    let start = Instant::now();
    let (out, records) = match method {
        Method::Ic(preset) => {
            let settings = IcSettings {
                width: effort.size,
                height: effort.size,
                params: IcParams::preset(preset),
                sub_frames: effort.sub_frames,
                direct_samples: effort.direct_samples,
                seed: effort.seed,
                ..IcSettings::default()
            };
            let (out, stats) = render_ic(ctx, shaders, scene, gpu, &settings, &mut |_| {})?;
            (out, stats.records)
        }
        Method::Path(spp) => {
            let settings = PathSettings {
                width: effort.size,
                height: effort.size,
                budget: Budget::Samples(spp),
                seed: effort.seed,
                chunk_target_ms: 200.0,
                ..PathSettings::default()
            };
            (
                render_path(ctx, shaders, scene, gpu, &settings, &mut |_| {})?,
                0,
            )
        }
    };
    let time_s = start.elapsed().as_secs_f64();
    let left = out
        .pixels
        .iter()
        .filter(|p| p.iter().any(|c| !c.is_finite()))
        .count() as u64;
    let image = Image::from_pixels(out.width, out.height, out.pixels)
        .expect("the renderer returns width × height pixels");
    Ok(Render {
        image,
        nonfinite: out.nonfinite_pixels + left,
        time_s,
        records,
    })
}

/// A constant image of radiance `value`.
pub fn constant_image(size: u32, value: f32) -> Image {
    Image::from_pixels(size, size, vec![[value; 3]; (size * size) as usize])
        .expect("size × size pixels")
}

fn luminance(p: [f32; 3]) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// Mean luminance of an image (non-finite pixels left out).
pub fn mean_luminance(image: &Image) -> f64 {
    let (sum, n) = image
        .pixels()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .fold((0.0, 0u64), |(s, n), p| (s + luminance(p), n + 1));
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// The leak figure of `candidate` (module docs); `None` when the scene has no dark pixels.
pub fn leak(check: &StiffCheck, reference: &Image, candidate: &Image) -> Option<f64> {
    match check {
        StiffCheck::Dark => Some(mean_luminance(candidate)),
        StiffCheck::Reference(_) => {
            let mean = mean_luminance(reference);
            if mean <= 0.0 {
                return Some(mean_luminance(candidate));
            }
            let dark = dark_blocks(reference, DARK_FRACTION * mean);
            let (mut sum_c, mut sum_r, mut n) = (0.0, 0.0, 0u64);
            for (i, (r, c)) in reference.pixels().zip(candidate.pixels()).enumerate() {
                let (x, y) = (i as u32 % reference.width(), i as u32 / reference.width());
                let (lr, lc) = (luminance(r), luminance(c));
                if dark.contains(&(x / BLOCK, y / BLOCK)) && lr.is_finite() && lc.is_finite() {
                    sum_c += lc;
                    sum_r += lr;
                    n += 1;
                }
            }
            (n > 0).then(|| (sum_c - sum_r) / n as f64 / mean)
        }
        _ => None,
    }
}

/// Side of the blocks of the dark region, pixels.
const BLOCK: u32 = 8;
/// A block is dark when its reference mean luminance is at most this fraction of the image's.
pub const DARK_FRACTION: f64 = 0.02;

/// The 8×8 blocks (block coordinates) whose mean luminance is at most `threshold`. Blocks, not
/// pixels: a noisy reference has many pixels near zero by chance, and picking them would bias the
/// figure; a block's mean carries 64 samples.
fn dark_blocks(image: &Image, threshold: f64) -> Vec<(u32, u32)> {
    let (bw, bh) = (
        image.width().div_ceil(BLOCK),
        image.height().div_ceil(BLOCK),
    );
    let mut sums = vec![(0.0f64, 0u32); (bw * bh) as usize];
    for (i, p) in image.pixels().enumerate() {
        let (x, y) = (i as u32 % image.width(), i as u32 / image.width());
        let l = luminance(p);
        if l.is_finite() {
            let s = &mut sums[((y / BLOCK) * bw + x / BLOCK) as usize];
            s.0 += l;
            s.1 += 1;
        }
    }
    (0..bw * bh)
        .filter(|&b| {
            let (sum, n) = sums[b as usize];
            n > 0 && sum / f64::from(n) <= threshold
        })
        .map(|b| (b % bw, b / bw))
        .collect()
}

/// The figures of one render against its reference.
#[derive(Clone, Debug)]
pub struct Figures {
    /// relMSE, block RMSE and the rest (`radcache_image::compare`).
    pub metrics: Metrics,
    /// The leak figure, when the scene has dark pixels.
    pub leak: Option<f64>,
    /// Mean luminance of the render.
    pub mean: f64,
}

/// Compares `candidate` with `reference` under `check`.
pub fn figures(check: &StiffCheck, reference: &Image, candidate: &Image) -> Figures {
    Figures {
        metrics: compare(reference, candidate).expect("images of the same size"),
        leak: leak(check, reference, candidate),
        mean: mean_luminance(candidate),
    }
}

/// The reference image of a check that needs no rendering (analytic or dark), else `None`.
pub fn closed_form_reference(check: &StiffCheck, size: u32) -> Option<Image> {
    match check {
        StiffCheck::Analytic(v) => Some(constant_image(size, *v)),
        StiffCheck::Dark => Some(constant_image(size, 0.0)),
        _ => None,
    }
}
