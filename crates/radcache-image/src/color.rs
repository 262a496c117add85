//! Display transforms: exposure, tone curves and the sRGB OETF, per channel.
//!
//! The display pipeline for one linear channel value `x` is
//! `x · 2^exposure → tone curve → clamp to [0, 1] → sRGB OETF → round(v · 255)`.
//! Non-finite and negative inputs never panic: NaN and negative values display as 0, +inf as 1.
//!
//! Tone curves:
//! - [`ToneMap::None`]: identity, then clamp.
//! - [`ToneMap::Filmic`]: the fitted ACES filmic curve of Krzysztof Narkowicz, "ACES Filmic Tone
//!   Mapping Curve" (2015): `f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`, clamped to
//!   [0, 1], applied to each RGB channel. (The curve reaches 1 at x ≈ 7.24; use exposure to
//!   place scene values on it.)
//!
//! The sRGB OETF is the exact piecewise function of IEC 61966-2-1:
//! `v = 12.92 L` for `L ≤ 0.0031308`, otherwise `v = 1.055 L^(1/2.4) − 0.055`.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// Tone curve applied before sRGB encoding.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneMap {
    /// No curve: values are clamped to [0, 1].
    #[default]
    None,
    /// Narkowicz's 2015 fitted ACES filmic curve.
    Filmic,
}

impl fmt::Display for ToneMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::None => "none",
            Self::Filmic => "filmic",
        })
    }
}

impl FromStr for ToneMap {
    type Err = String;

    /// Parses `none` or `filmic` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "none" => Ok(Self::None),
            "filmic" => Ok(Self::Filmic),
            _ => Err(format!(
                "unknown tone map '{s}' (expected 'none' or 'filmic')"
            )),
        }
    }
}

/// Narkowicz's fitted ACES curve, clamped to [0, 1]; NaN and x ≤ 0 give 0, +inf gives 1.
pub fn aces_filmic(x: f32) -> f32 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    if x.is_infinite() {
        return 1.0;
    }
    // f64 so that x² cannot overflow for any finite f32.
    let x = f64::from(x);
    let y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
    y.clamp(0.0, 1.0) as f32
}

/// Applies `tone_map` and clamps to [0, 1]; NaN gives 0.
pub fn tone_map(x: f32, tone_map: ToneMap) -> f32 {
    match tone_map {
        ToneMap::None => clamp01(x),
        ToneMap::Filmic => aces_filmic(x),
    }
}

/// The sRGB OETF (linear → encoded), input clamped to [0, 1] (NaN → 0).
pub fn srgb_encode(linear: f32) -> f32 {
    let l = clamp01(linear);
    if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB OETF (encoded → linear), input clamped to [0, 1].
pub fn srgb_decode(encoded: f32) -> f32 {
    let v = clamp01(encoded);
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// `round(255 · srgb_encode(linear))`.
pub fn srgb_to_u8(linear: f32) -> u8 {
    // In [0, 255.5) after clamping, so the cast cannot truncate.
    (srgb_encode(linear) * 255.0).round() as u8
}

/// The full display transform of one channel value (see the module docs).
pub fn display_u8(linear: f32, exposure_scale: f32, curve: ToneMap) -> u8 {
    srgb_to_u8(tone_map(linear * exposure_scale, curve))
}

/// `2^exposure` (exposure in stops).
pub fn exposure_scale(exposure: f32) -> f32 {
    exposure.exp2()
}

/// Clamps to [0, 1], mapping NaN to 0.
fn clamp01(x: f32) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filmic_reference_values() {
        // f(1) = (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 2.54 / 3.16 = 0.803797...
        assert!((aces_filmic(1.0) - 0.803_797_5).abs() < 1e-6);
        // f(0.18) = 0.18·(0.4518 + 0.03) / (0.18·(0.4374 + 0.59) + 0.14)
        //         = 0.086724 / 0.324932 = 0.266899...
        assert!((aces_filmic(0.18) - 0.266_899).abs() < 1e-5);
        assert_eq!(aces_filmic(f32::MAX), 1.0);
        assert_eq!(aces_filmic(f32::INFINITY), 1.0);
        assert_eq!(aces_filmic(f32::NAN), 0.0);
        assert_eq!(aces_filmic(-1.0), 0.0);
    }

    #[test]
    fn decode_inverts_encode() {
        for i in 0..=100 {
            let l = i as f32 / 100.0;
            assert!((srgb_decode(srgb_encode(l)) - l).abs() < 1e-6, "{l}");
        }
    }

    #[test]
    fn tone_map_names() {
        assert_eq!("Filmic".parse::<ToneMap>(), Ok(ToneMap::Filmic));
        assert_eq!(ToneMap::None.to_string(), "none");
        assert!("aces".parse::<ToneMap>().is_err());
    }
}
