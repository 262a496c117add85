//! The environment (light from infinitely far away, seen by rays that leave the scene).
//!
//! Sources, highest priority first: `--env-map file.exr` ([`EnvOverride::map`]), then
//! `--env-radiance r,g,b` ([`EnvOverride::radiance`]), then the scene's
//! `scenes[i].extras.environment.radiance = [r, g, b]` (W/(sr·m²), linear RGB); `--env-scale k`
//! multiplies whichever is chosen. This crate only records the choice; the EXR is read elsewhere.
//!
//! **Equirectangular convention** (for environment maps): a unit direction `(x, y, z)`, +Y up, maps
//! to `u = 0.5 + atan2(x, −z) / (2π)`, `v = acos(y) / π`, with `v = 0` at the top row (zenith,
//! +Y) and `v = 1` at the nadir; the image centre `u = 0.5` looks down −Z and `u` grows towards +X.
//! See [`direction_to_equirect`] and [`equirect_to_direction`].

use std::f32::consts::PI;
use std::path::PathBuf;

use glam::{Vec2, Vec3};

/// Environment overrides from the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvOverride {
    /// An equirectangular EXR map (takes precedence).
    pub map: Option<PathBuf>,
    /// A constant radiance, replacing the scene's.
    pub radiance: Option<[f32; 3]>,
    /// Multiplier applied to the chosen environment (default 1).
    pub scale: f32,
}

impl Default for EnvOverride {
    fn default() -> Self {
        EnvOverride {
            map: None,
            radiance: None,
            scale: 1.0,
        }
    }
}

/// The chosen environment.
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// Black: rays leaving the scene carry no light.
    None,
    /// Uniform radiance (already scaled), W/(sr·m²).
    Constant(Vec3),
    /// An equirectangular map file, to be multiplied by `scale`.
    Map {
        /// The EXR file.
        path: PathBuf,
        /// Radiance multiplier.
        scale: f32,
    },
}

impl Environment {
    /// Resolves the environment from the overrides and the scene's extras value (if any).
    pub fn resolve(overrides: &EnvOverride, scene_radiance: Option<Vec3>) -> Environment {
        let scale = overrides.scale;
        if let Some(path) = &overrides.map {
            return Environment::Map {
                path: path.clone(),
                scale,
            };
        }
        let radiance = overrides.radiance.map(Vec3::from).or(scene_radiance);
        match radiance {
            Some(l) if (l * scale).max_element() > 0.0 => Environment::Constant(l * scale),
            _ => Environment::None,
        }
    }

    /// Short kind name: `none`, `constant` or `map`.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Environment::None => "none",
            Environment::Constant(_) => "constant",
            Environment::Map { .. } => "map",
        }
    }
}

/// Reads `extras.environment.radiance` from a glTF scene's extras; `Err` describes a malformed value.
pub(crate) fn scene_radiance(extras: &gltf::json::Extras) -> Result<Option<Vec3>, String> {
    let Some(raw) = extras else { return Ok(None) };
    let value: serde_json::Value = serde_json::from_str(raw.get()).map_err(|e| e.to_string())?;
    let Some(rad) = value.get("environment").and_then(|e| e.get("radiance")) else {
        return Ok(None);
    };
    let arr = rad
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or("environment.radiance must be [r, g, b]")?;
    let mut out = [0.0f32; 3];
    for (o, v) in out.iter_mut().zip(arr) {
        let x = v
            .as_f64()
            .ok_or("environment.radiance entries must be numbers")? as f32;
        if !x.is_finite() || x < 0.0 {
            return Err("environment.radiance entries must be finite and non-negative".into());
        }
        *o = x;
    }
    Ok(Some(Vec3::from(out)))
}

/// Equirectangular `(u, v)` in `[0, 1]²` of a unit direction (see module docs).
pub fn direction_to_equirect(d: Vec3) -> Vec2 {
    let u = 0.5 + d.x.atan2(-d.z) / (2.0 * PI);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    Vec2::new(u, v)
}

/// Unit direction of equirectangular `(u, v)` (inverse of [`direction_to_equirect`]).
pub fn equirect_to_direction(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let theta = uv.y * PI;
    let (st, ct) = theta.sin_cos();
    Vec3::new(st * phi.sin(), ct, -st * phi.cos())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equirect_round_trip_and_landmarks() {
        assert!((direction_to_equirect(-Vec3::Z) - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((direction_to_equirect(Vec3::Y).y).abs() < 1e-6);
        assert!((direction_to_equirect(Vec3::X) - Vec2::new(0.75, 0.5)).length() < 1e-6);
        for i in 0..50 {
            let uv = Vec2::new(0.02 + 0.019 * i as f32, 0.03 + 0.018 * i as f32);
            let back = direction_to_equirect(equirect_to_direction(uv));
            assert!((back - uv).length() < 1e-4, "{uv} -> {back}");
        }
    }

    #[test]
    fn resolution_priority() {
        let scene = Some(Vec3::splat(0.5));
        let mut o = EnvOverride::default();
        assert_eq!(
            Environment::resolve(&o, scene),
            Environment::Constant(Vec3::splat(0.5))
        );
        o.scale = 2.0;
        o.radiance = Some([1.0, 2.0, 3.0]);
        assert_eq!(
            Environment::resolve(&o, scene),
            Environment::Constant(Vec3::new(2.0, 4.0, 6.0))
        );
        o.map = Some("sky.exr".into());
        assert!(
            matches!(Environment::resolve(&o, scene), Environment::Map { scale, .. } if scale == 2.0)
        );
        assert_eq!(
            Environment::resolve(&EnvOverride::default(), None),
            Environment::None
        );
    }
}
