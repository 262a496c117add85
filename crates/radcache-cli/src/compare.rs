//! `radcache compare REFERENCE CANDIDATE`: image error metrics, optionally as JSON, with limits.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context as _, Result};
use clap::Args;
use radcache_image::{compare, read_exr, Thresholds};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The reference EXR.
    reference: PathBuf,
    /// The EXR to judge.
    candidate: PathBuf,
    /// Print the metrics as JSON.
    #[arg(long)]
    json: bool,
    /// Fail (exit code 1) when the RMSE exceeds this.
    #[arg(long)]
    max_rmse: Option<f64>,
    /// Fail when the relative MSE exceeds this.
    #[arg(long)]
    max_relmse: Option<f64>,
    /// Fail when the MAE exceeds this.
    #[arg(long)]
    max_mae: Option<f64>,
    /// Fail when the 8×8-block RMSE exceeds this.
    #[arg(long)]
    max_block_rmse: Option<f64>,
    /// Fail when the mean FLIP exceeds this.
    #[arg(long)]
    max_flip: Option<f64>,
    /// Fail when a channel's mean ratio differs from 1 by more than this.
    #[arg(long)]
    max_mean_ratio_dev: Option<f64>,
    /// Fail when the candidate has more non-finite pixels than this.
    #[arg(long)]
    max_nonfinite: Option<u64>,
}

pub fn run(args: &CompareArgs) -> Result<ExitCode> {
    let (reference, _) = read_exr(&args.reference)?;
    let (candidate, _) = read_exr(&args.candidate)?;
    let metrics = compare(&reference, &candidate).with_context(|| {
        format!(
            "comparing {} with {}",
            args.reference.display(),
            args.candidate.display()
        )
    })?;
    let limits = Thresholds {
        max_rmse: args.max_rmse,
        max_relmse: args.max_relmse,
        max_mae: args.max_mae,
        max_block_rmse: args.max_block_rmse,
        max_flip: args.max_flip,
        max_mean_ratio_dev: args.max_mean_ratio_dev,
        max_nonfinite: args.max_nonfinite,
    };
    let exceeded = limits.check(&metrics);
    if args.json {
        let value = serde_json::json!({
            "reference": args.reference,
            "candidate": args.candidate,
            "metrics": metrics,
            "exceeded": exceeded,
        });
        crate::output::emit(&format!("{}\n", serde_json::to_string_pretty(&value)?))?;
    } else {
        crate::output::emit(&metrics.to_string())?;
        for e in &exceeded {
            eprintln!("limit exceeded: {e}");
        }
    }
    Ok(if exceeded.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
