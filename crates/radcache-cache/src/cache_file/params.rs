//! The cache parameters in a cache file's header: 13 words in declaration order, with their
//! names for messages and reports.

use super::Refusal;
use crate::params::IcParams;
use crate::weight::WeightKind;

/// A cache parameter's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    /// An integer (strata, levels, the weight kind's GLSL constant).
    Int(u32),
    /// A real.
    Real(f32),
}

impl std::fmt::Display for ParamValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamValue::Int(v) => write!(f, "{v}"),
            ParamValue::Real(v) => write!(f, "{v}"),
        }
    }
}

/// The cache parameters as 13 words, with their names, in declaration order.
pub(super) fn param_words(p: &IcParams) -> [(&'static str, u32, ParamValue); 13] {
    let f = |name, v: f32| (name, v.to_bits(), ParamValue::Real(v));
    let u = |name, v: u32| (name, v, ParamValue::Int(v));
    [
        u("weight_kind", p.weight_kind as u32),
        f("accuracy", p.accuracy),
        f("kappa", p.kappa),
        f("min_spacing_px", p.min_spacing_px),
        f("max_spacing_px", p.max_spacing_px),
        u("strata_m", p.strata_m),
        u("strata_n", p.strata_n),
        f("hole_threshold", p.hole_threshold),
        u("levels", p.levels),
        f("creation_strictness", p.creation_strictness),
        f("front_tolerance_px", p.front_tolerance_px),
        f("temporal_accuracy", p.temporal_accuracy),
        f("max_age_frames", p.max_age_frames),
    ]
}

pub(super) fn params_from_words(w: &[u32; 13]) -> Result<IcParams, Refusal> {
    let weight_kind = WeightKind::from_u32(w[0]);
    if weight_kind as u32 != w[0] {
        return Err(Refusal::Corrupt(format!("unknown weight kind {}", w[0])));
    }
    let f = f32::from_bits;
    Ok(IcParams {
        weight_kind,
        // Not one of the file's words (docs/irradiance-cache.md §10.5).
        error_control: crate::params::ErrorControl::default(),
        accuracy: f(w[1]),
        kappa: f(w[2]),
        min_spacing_px: f(w[3]),
        max_spacing_px: f(w[4]),
        strata_m: w[5],
        strata_n: w[6],
        hole_threshold: f(w[7]),
        levels: w[8],
        creation_strictness: f(w[9]),
        front_tolerance_px: f(w[10]),
        temporal_accuracy: f(w[11]),
        max_age_frames: f(w[12]),
    })
}
