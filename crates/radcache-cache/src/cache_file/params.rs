//! The cache parameters in a cache file's header: 13 words in declaration order (the strata
//! words also carry the fine strata from format version 3, the levels word the strata falloff
//! from version 4), and the parameters by name for messages and reports.

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

impl ParamValue {
    /// The value's bits: two parameters are the same when these are.
    pub fn bits(self) -> u32 {
        match self {
            ParamValue::Int(v) => v,
            ParamValue::Real(v) => v.to_bits(),
        }
    }
}

impl std::fmt::Display for ParamValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamValue::Int(v) => write!(f, "{v}"),
            ParamValue::Real(v) => write!(f, "{v}"),
        }
    }
}

/// The cache parameters by name, as reports and refusals show them: the 13 header words'
/// fields in declaration order, then the fine strata and their falloff.
pub(super) fn param_values(p: &IcParams) -> Vec<(&'static str, ParamValue)> {
    let f = |name, v: f32| (name, ParamValue::Real(v));
    let u = |name, v: u32| (name, ParamValue::Int(v));
    vec![
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
        u("fine_strata_m", p.fine_strata_m),
        u("fine_strata_n", p.fine_strata_n),
        u("strata_falloff", u32::from(p.strata_falloff)),
    ]
}

/// The cache parameters as the header's 13 words, in declaration order; from version 3 the
/// strata words carry the fine strata in their high 16 bits, from version 4 the levels word the
/// strata falloff in bit 16.
pub(super) fn param_words(p: &IcParams) -> [u32; 13] {
    let packed = |coarse: u32, fine: u32| (coarse & 0xffff) | (fine << 16);
    [
        p.weight_kind as u32,
        p.accuracy.to_bits(),
        p.kappa.to_bits(),
        p.min_spacing_px.to_bits(),
        p.max_spacing_px.to_bits(),
        packed(p.strata_m, p.fine_strata_m),
        packed(p.strata_n, p.fine_strata_n),
        p.hole_threshold.to_bits(),
        (p.levels & 0xffff) | (u32::from(p.strata_falloff) << 16),
        p.creation_strictness.to_bits(),
        p.front_tolerance_px.to_bits(),
        p.temporal_accuracy.to_bits(),
        p.max_age_frames.to_bits(),
    ]
}

/// The parameters of a file of format `version`: before version 3 every record had the same
/// strata, which are then also the fine ones; before version 4 the fine strata had no falloff.
pub(super) fn params_from_words(w: &[u32; 13], version: u32) -> Result<IcParams, Refusal> {
    let weight_kind = WeightKind::from_u32(w[0]);
    if weight_kind as u32 != w[0] {
        return Err(Refusal::Corrupt(format!("unknown weight kind {}", w[0])));
    }
    let (strata_m, strata_n, fine_strata_m, fine_strata_n) = if version >= 3 {
        let (m, n) = (w[5] & 0xffff, w[6] & 0xffff);
        let (fine_m, fine_n) = (w[5] >> 16, w[6] >> 16);
        if fine_m == 0 || fine_n == 0 {
            return Err(Refusal::Corrupt(format!(
                "fine strata {fine_m}×{fine_n} in a version-{version} header"
            )));
        }
        (m, n, fine_m, fine_n)
    } else {
        (w[5], w[6], w[5], w[6])
    };
    let (levels, strata_falloff) = if version >= 4 {
        if w[8] >> 17 != 0 {
            return Err(Refusal::Corrupt(format!(
                "levels word {:#x} in a version-{version} header",
                w[8]
            )));
        }
        (w[8] & 0xffff, w[8] >> 16 == 1)
    } else {
        (w[8], false)
    };
    let f = f32::from_bits;
    Ok(IcParams {
        weight_kind,
        // Not one of the file's words (docs/irradiance-cache.md §10.5).
        error_control: crate::params::ErrorControl::default(),
        accuracy: f(w[1]),
        kappa: f(w[2]),
        min_spacing_px: f(w[3]),
        max_spacing_px: f(w[4]),
        strata_m,
        strata_n,
        fine_strata_m,
        fine_strata_n,
        strata_falloff,
        hole_threshold: f(w[7]),
        levels,
        creation_strictness: f(w[9]),
        front_tolerance_px: f(w[10]),
        temporal_accuracy: f(w[11]),
        max_age_frames: f(w[12]),
    })
}
