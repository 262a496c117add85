//! The log–log plot of relMSE against wall time, one series per ladder, as SVG and PNG
//! (plotters). Text is laid out and rasterised with `ab_glyph` from a TrueType font read at run
//! time: `RADCACHE_FONT`, else DejaVu Sans (Debian's `fonts-dejavu-core`, installed by
//! `scripts/setup.sh`) or Liberation Sans. The PNG is plotters' RGB buffer encoded by `png`.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context as _, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use super::ladder::{accuracy_of, Ladder, Point};

/// Size of both images, pixels.
pub const PLOT_SIZE: (u32, u32) = (960, 640);

/// Where a font is looked for when `RADCACHE_FONT` is not set.
const FONT_PATHS: [&str; 4] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// The font family the plot asks for (registered by [`load_font`]).
const FAMILY: &str = "sans-serif";

/// Finds, reads and registers the plot's font. Called before any rendering, so that a machine
/// without a font fails at once with what to install.
pub fn load_font() -> Result<PathBuf> {
    let path = match std::env::var_os("RADCACHE_FONT") {
        Some(p) => PathBuf::from(p),
        None => FONT_PATHS
            .iter()
            .map(PathBuf::from)
            .find(|p| p.is_file())
            .ok_or_else(|| {
                anyhow!(
                    "no TrueType font for the plot's text (looked for {}): install Debian's \
                     fonts-dejavu-core (scripts/setup.sh does) or set RADCACHE_FONT=FILE.ttf",
                    FONT_PATHS.join(", ")
                )
            })?,
    };
    let bytes = std::fs::read(&path)
        .with_context(|| format!("reading the plot's font {}", path.display()))?;
    // plotters keeps fonts for the whole process: the bytes live as long (one font per run).
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    if register_font(FAMILY, FontStyle::Normal, bytes).is_err() {
        bail!("{} is not a TrueType/OpenType font", path.display());
    }
    Ok(path)
}

/// A ladder's series: its name, colour and points (in order of time for the sweeps).
struct Series {
    name: String,
    color: RGBColor,
    points: Vec<(f64, f64)>,
}

/// The order of a point along the line of the series of `ladder`: spp, the presets as listed,
/// the accuracy, the strata count.
fn order_key(p: &Point, ladder: Ladder) -> f64 {
    match (&p.ic, ladder) {
        (None, _) => f64::from(p.spp.unwrap_or(0)),
        (Some((preset, _)), Ladder::Preset | Ladder::Spp | Ladder::GlossyPaths) => {
            f64::from(*preset as u8)
        }
        (Some((_, params)), Ladder::Accuracy) => f64::from(accuracy_of(params)),
        (Some((_, params)), Ladder::Strata) => f64::from(params.strata_m * params.strata_n),
    }
}

fn series(points: &[Point]) -> Vec<Series> {
    // The sweeps' lines pass through the default preset, their centre.
    let pick = |ladder: Ladder, through_default: bool| -> Vec<(f64, f64)> {
        let mut chosen: Vec<&Point> = points
            .iter()
            .filter(|p| {
                p.ladder == ladder
                    || (through_default && p.ladder == Ladder::Preset && p.label == "default")
            })
            .collect();
        chosen.sort_by(|a, b| order_key(a, ladder).total_cmp(&order_key(b, ladder)));
        chosen
            .into_iter()
            .map(|p| (p.wall_s, p.metrics.relmse))
            .collect()
    };
    let mut out = vec![
        Series {
            name: "path tracer (1, 2, 4, ... spp)".into(),
            color: RGBColor(0, 0, 0),
            points: pick(Ladder::Spp, false),
        },
        Series {
            name: "IC presets (draft, default, high)".into(),
            color: RGBColor(214, 39, 40),
            points: pick(Ladder::Preset, false),
        },
        Series {
            name: "IC accuracy sweep (through default)".into(),
            color: RGBColor(31, 119, 180),
            points: pick(Ladder::Accuracy, true),
        },
        Series {
            name: "IC hemisphere strata sweep (through default)".into(),
            color: RGBColor(44, 160, 44),
            points: pick(Ladder::Strata, true),
        },
    ];
    // Scenes with radiance records: the presets with per-pixel glossy paths.
    if points.iter().any(|p| p.ladder == Ladder::GlossyPaths) {
        out.push(Series {
            name: "IC presets, glossy lobes path traced per pixel".into(),
            color: RGBColor(148, 103, 189),
            points: pick(Ladder::GlossyPaths, false),
        });
    }
    out
}

/// A log axis range over the positive finite `values`, widened to whole decades (at least one).
fn log_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi > 0.0) {
        return None;
    }
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil()).max(lo * 10.0);
    // A hair wider, so that rounding in `powf` cannot drop the end decades' labels.
    Some((lo * (1.0 - 1e-9), hi * (1.0 + 1e-9)))
}

/// A decade's label: `0.01`, `1`, `100`, or `1e-5` outside 10⁻³…10⁴.
fn tick(v: &f64) -> String {
    let v = *v;
    if (1e-3..1e4).contains(&v) {
        let decimals = (-v.log10().floor()).max(0.0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.0e}")
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    points: &[Point],
    reference_noise: f64,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing the plot: {e}");
    root.fill(&WHITE).map_err(fail)?;
    let x = log_range(points.iter().map(|p| p.wall_s)).context("no point has a positive time")?;
    let noise = (reference_noise > 0.0).then_some(reference_noise);
    let y = log_range(points.iter().map(|p| p.metrics.relmse).chain(noise))
        .context("no point has a positive relMSE")?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FAMILY, 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(fail)?;
    chart
        .configure_mesh()
        .x_desc("wall time per frame (s)")
        .y_desc("relMSE against the reference")
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 16))
        .draw()
        .map_err(fail)?;
    for s in series(points) {
        if s.points.is_empty() {
            continue;
        }
        let color = s.color;
        chart
            .draw_series(LineSeries::new(s.points.clone(), color.stroke_width(2)))
            .map_err(fail)?
            .label(s.name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2))
            });
        chart
            .draw_series(
                s.points
                    .iter()
                    .map(|&(px, py)| Circle::new((px, py), 4, color.filled())),
            )
            .map_err(fail)?;
    }
    if let Some(e) = noise {
        let grey = RGBColor(128, 128, 128);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x.0, e), (x.1, e)],
                6,
                4,
                grey.stroke_width(1),
            ))
            .map_err(fail)?
            .label("reference's own relMSE (estimated)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(fail)?;
    root.present().map_err(fail)?;
    Ok(())
}

/// Writes the plot as `svg` and `png` ([`PLOT_SIZE`]); [`load_font`] must have run.
pub fn write(
    svg: &Path,
    png: &Path,
    title: &str,
    points: &[Point],
    reference_noise: f64,
) -> Result<()> {
    {
        let root = SVGBackend::new(svg, PLOT_SIZE).into_drawing_area();
        draw(&root, title, points, reference_noise)?;
    }
    let (w, h) = PLOT_SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, PLOT_SIZE).into_drawing_area();
        draw(&root, title, points, reference_noise)?;
    }
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, w, h);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().context("encoding the plot's PNG")?;
        writer
            .write_image_data(&rgb)
            .context("encoding the plot's PNG")?;
    }
    std::fs::write(png, bytes).with_context(|| format!("writing {}", png.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{log_range, tick};

    #[test]
    fn log_range_covers_the_values_in_whole_decades_and_skips_bad_values() {
        let (lo, hi) = log_range([2.0, 3.0, f64::NAN, -1.0, 0.0].into_iter()).unwrap();
        assert!(
            (lo - 1.0).abs() < 1e-6 && (hi - 10.0).abs() < 1e-6,
            "{lo} {hi}"
        );
        assert!(lo <= 1.0 && hi >= 10.0, "{lo} {hi}");
        let (lo, hi) = log_range([0.048, 1.8].into_iter()).unwrap();
        assert!(
            (lo - 0.01).abs() < 1e-9 && (hi - 10.0).abs() < 1e-6,
            "{lo} {hi}"
        );
        // A single exact decade still spans one decade.
        let (lo, hi) = log_range([1.0].into_iter()).unwrap();
        assert!(
            (lo - 1.0).abs() < 1e-6 && (hi - 10.0).abs() < 1e-6,
            "{lo} {hi}"
        );
        assert_eq!(log_range([0.0, f64::INFINITY].into_iter()), None);
    }

    #[test]
    fn decade_labels_are_short() {
        assert_eq!(tick(&0.010000000000000002), "0.01");
        assert_eq!(tick(&1.0), "1");
        assert_eq!(tick(&100.0), "100");
        assert_eq!(tick(&1e-5), "1e-5");
    }
}
