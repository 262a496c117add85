//! The harness every `cargo xtask bench` shares: the device, the shader compiler, the warm-up,
//! the leak check and the rows of `bench/results.csv`.
//!
//! A benchmark opens a [`Bench`] (the device `RADCACHE_DEVICE` names, the preferred one
//! otherwise; validation off unless `RADCACHE_VALIDATION` is set, as it costs CPU time per
//! call), renders a small frame of each method it times with [`Bench::warm_up_ic`] /
//! [`Bench::warm_up_path`] (shader compilation and pipeline creation are not part of the
//! figures), collects its [`Figure`]s and ends with [`Bench::finish`]: the figures are appended
//! to `bench/results.csv` (one row per figure, `date,commit,device,bench,case,metric,value,unit`),
//! the device is shut down and any GPU allocation still alive fails the benchmark.

use std::io::Write;
use std::process::Command;

use anyhow::{Context as _, Result};
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcSettings, PathSettings};
use radcache_scene::Scene;
use radcache_vk::{Context, ShaderCompiler};

/// Width and height of the warm-up frames.
const WARM_UP_SIZE: u32 = 16;

/// One benchmark run: its device and shader compiler.
pub struct Bench {
    /// The name in the CSV's `bench` column.
    name: &'static str,
    ctx: Context,
    shaders: ShaderCompiler,
    /// The CSV's `device` column: the device's name unless a benchmark says otherwise.
    device: String,
}

impl Bench {
    /// Opens the device and the shader compiler on `shaders/` for the benchmark `name`.
    pub fn new(name: &'static str) -> Result<Bench> {
        if std::env::var_os("RADCACHE_VALIDATION").is_none() {
            std::env::set_var("RADCACHE_VALIDATION", "0");
        }
        let ctx = Context::new()?;
        let device = ctx.info().name.clone();
        let shaders = ShaderCompiler::new(crate::root().join("shaders"))?;
        Ok(Bench {
            name,
            ctx,
            shaders,
            device,
        })
    }

    pub fn ctx(&self) -> &Context {
        &self.ctx
    }

    pub fn shaders(&self) -> &ShaderCompiler {
        &self.shaders
    }

    /// The device's name.
    pub fn device(&self) -> &str {
        &self.device
    }

    /// Replaces the device's name in the CSV's `device` column (`bench rays` adds the driver).
    pub fn set_device_label(&mut self, label: String) {
        self.device = label;
    }

    /// Warm-up of the cache: one sub-frame of `settings` at 16².
    pub fn warm_up_ic(
        &self,
        scene: &Scene,
        gpu: &mut GpuScene,
        settings: IcSettings,
    ) -> Result<()> {
        let warm = IcSettings {
            width: WARM_UP_SIZE,
            height: WARM_UP_SIZE,
            sub_frames: 1,
            ..settings
        };
        render_ic(&self.ctx, &self.shaders, scene, gpu, &warm, &mut |_| {})?;
        Ok(())
    }

    /// Warm-up of the path tracer: one sample per pixel at 16².
    pub fn warm_up_path(&self, scene: &Scene, gpu: &mut GpuScene) -> Result<()> {
        let warm = PathSettings {
            width: WARM_UP_SIZE,
            height: WARM_UP_SIZE,
            budget: Budget::Samples(1),
            ..PathSettings::default()
        };
        render_path(&self.ctx, &self.shaders, scene, gpu, &warm, &mut |_| {})?;
        Ok(())
    }

    /// Appends `figures` to `bench/results.csv`, shuts the device down and fails if a GPU
    /// allocation outlived the benchmark (every GPU object must be dropped before this call).
    pub fn finish(self, figures: &[Figure]) -> Result<()> {
        append(self.name, &self.device, figures)?;
        let report = self.ctx.shutdown();
        anyhow::ensure!(
            report.leaked.is_empty(),
            "bench {}: leaked GPU allocations: {:?}",
            self.name,
            report.leaked
        );
        Ok(())
    }
}

/// One measured figure.
#[derive(Debug, Clone)]
pub struct Figure {
    pub case: String,
    pub metric: &'static str,
    pub value: f64,
    pub unit: &'static str,
}

impl Figure {
    pub fn new(
        case: impl Into<String>,
        metric: &'static str,
        value: f64,
        unit: &'static str,
    ) -> Self {
        Figure {
            case: case.into(),
            metric,
            value,
            unit,
        }
    }
}

fn commit() -> String {
    let out = Command::new("git")
        .args(["rev-parse", "--short=10", "HEAD"])
        .current_dir(crate::root())
        .output();
    let hash = out
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    let dirty = Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .current_dir(crate::root())
        .output()
        .is_ok_and(|o| !o.stdout.is_empty());
    match hash {
        Some(h) if dirty => format!("{h}-dirty"),
        Some(h) => h,
        None => "unknown".into(),
    }
}

/// UTC date and time, ISO 8601, from the system clock (civil-from-days, H. Hinnant).
fn now_utc() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let (days, rem) = (secs.div_euclid(86400), secs.rem_euclid(86400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// Appends the figures of one benchmark run to `bench/results.csv` (creating it with a header).
fn append(bench: &str, device: &str, figures: &[Figure]) -> Result<()> {
    let path = crate::root().join("bench/results.csv");
    std::fs::create_dir_all(path.parent().unwrap_or(&crate::root()))?;
    let new = !path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    if new {
        writeln!(f, "date,commit,device,bench,case,metric,value,unit")?;
    }
    let (date, commit) = (now_utc(), commit());
    let device = device.replace(',', ";");
    for fig in figures {
        writeln!(
            f,
            "{date},{commit},{device},{bench},{},{},{:.6},{}",
            fig.case, fig.metric, fig.value, fig.unit
        )?;
    }
    println!("appended {} figures to {}", figures.len(), path.display());
    Ok(())
}
