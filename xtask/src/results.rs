//! `bench/results.csv`: one row per figure, `date,commit,device,bench,case,metric,value,unit`.

use std::io::Write;
use std::process::Command;

use anyhow::{Context, Result};

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
pub fn append(bench: &str, device: &str, figures: &[Figure]) -> Result<()> {
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
