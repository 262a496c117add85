//! Pass/fail limits on [`Metrics`].
//!
//! Every limit is optional; an unset limit is not checked. A metric that is NaN (no pixel
//! compared) violates any limit set on it, and a FLIP limit is violated when FLIP is
//! unavailable, so a check can never pass by accident. `max_nonfinite` limits the candidate's
//! non-finite pixel count (the reference's is reported by [`Metrics`] but not checked).

use serde::{Deserialize, Serialize};

use crate::metrics::Metrics;

/// Upper limits for [`Metrics`]; see the module docs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Thresholds {
    /// Limit on [`Metrics::rmse`].
    pub max_rmse: Option<f64>,
    /// Limit on [`Metrics::relmse`].
    pub max_relmse: Option<f64>,
    /// Limit on [`Metrics::mae`].
    pub max_mae: Option<f64>,
    /// Limit on [`Metrics::block_rmse`].
    pub max_block_rmse: Option<f64>,
    /// Limit on [`Metrics::flip`].
    pub max_flip: Option<f64>,
    /// Limit on [`Metrics::max_mean_ratio_dev`] (`max |mean ratio − 1|`).
    pub max_mean_ratio_dev: Option<f64>,
    /// Limit on [`Metrics::nonfinite_candidate`].
    pub max_nonfinite: Option<u64>,
}

impl Thresholds {
    /// One human-readable line per violated limit; empty when everything passes.
    pub fn check(&self, metrics: &Metrics) -> Vec<String> {
        let mut violations = Vec::new();
        let mut limit = |name: &str, value: f64, max: Option<f64>| {
            // A NaN value is within no limit.
            if let Some(max) = max.filter(|max| value.is_nan() || value > *max) {
                violations.push(format!("{name} {value:.6e} exceeds the limit {max:.6e}"));
            }
        };
        limit("RMSE", metrics.rmse, self.max_rmse);
        limit("relMSE", metrics.relmse, self.max_relmse);
        limit("MAE", metrics.mae, self.max_mae);
        limit("block RMSE", metrics.block_rmse, self.max_block_rmse);
        limit(
            "mean ratio deviation",
            metrics.max_mean_ratio_dev(),
            self.max_mean_ratio_dev,
        );
        match (metrics.flip, self.max_flip) {
            (Some(flip), max) => limit("FLIP", flip, max),
            (None, Some(max)) => {
                violations.push(format!("FLIP limit {max:.6e} set, but FLIP is unavailable"))
            }
            (None, None) => {}
        }
        if let Some(max) = self.max_nonfinite {
            if metrics.nonfinite_candidate > max {
                violations.push(format!(
                    "{} non-finite candidate pixels exceed the limit {max}",
                    metrics.nonfinite_candidate
                ));
            }
        }
        violations
    }
}
