//! The environment map: an equirectangular EXR read into linear RGB texels with an alias table
//! for importance sampling.
//!
//! Convention (shared with `shaders/common/lights.glsl` and `radcache_scene::environment`): +Y is
//! up; texel column u = 0.5 + atan2(x, −z)/2π, row v = acos(y)/π (v = 0 is the zenith, the top row
//! of the file). The map is sampled in proportion to luminance × texel solid angle, so the
//! solid-angle pdf of a direction is pmf(texel) / Ω(texel).

use std::f64::consts::PI;
use std::path::Path;

use radcache_scene::{luminance, AliasTable};
use radcache_shared::gpu::GpuAlias;

use crate::error::{Error, Result};

/// An environment map ready for upload.
#[derive(Debug, Clone)]
pub struct EnvMap {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Linear RGB radiance per texel (before the scale), rows top to bottom; `w` unused.
    pub texels: Vec<[f32; 4]>,
    /// Alias table over texels, weights luminance × solid angle.
    pub alias: Vec<GpuAlias>,
}

/// Solid angle of a texel in row `y` of a `w × h` equirectangular map.
pub fn texel_solid_angle(y: u32, w: u32, h: u32) -> f64 {
    let c0 = (PI * f64::from(y) / f64::from(h)).cos();
    let c1 = (PI * f64::from(y + 1) / f64::from(h)).cos();
    2.0 * PI / f64::from(w) * (c0 - c1).max(0.0)
}

/// Builds the alias table of `table` in the GPU layout.
pub fn gpu_alias(table: &AliasTable) -> Vec<GpuAlias> {
    (0..table.len())
        .map(|i| GpuAlias {
            prob: table.prob[i],
            alias: table.alias[i],
            pmf: table.pmf[i],
            pad: 0,
        })
        .collect()
}

impl EnvMap {
    /// Reads `path` (an RGB or RGBA EXR). Non-finite or negative texels are an error naming the
    /// first one: an environment must not inject NaN/Inf into the image.
    pub fn load(path: &Path) -> Result<EnvMap> {
        let (image, _) = radcache_image::read_exr(path)?;
        EnvMap::from_rgb(
            path,
            image.width(),
            image.height(),
            image.pixels().collect(),
        )
    }

    /// Builds the map from linear RGB texels (rows top to bottom); `path` names it in errors.
    pub fn from_rgb(path: &Path, width: u32, height: u32, rgb: Vec<[f32; 3]>) -> Result<EnvMap> {
        let bad = |message: String| Error::EnvMap {
            path: path.to_path_buf(),
            message,
        };
        if width == 0 || height == 0 {
            return Err(bad("the map is empty".into()));
        }
        if let Some(i) = rgb
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite() || *c < 0.0))
        {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(bad(format!(
                "texel ({x}, {y}) is {:?}: radiance must be finite and non-negative",
                rgb[i]
            )));
        }
        let weights: Vec<f32> = rgb
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let y = i as u32 / width;
                (f64::from(luminance((*p).into())) * texel_solid_angle(y, width, height)) as f32
            })
            .collect();
        let table = AliasTable::new(&weights);
        Ok(EnvMap {
            width,
            height,
            texels: rgb.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect(),
            alias: gpu_alias(&table),
        })
    }

    /// Radiance integrated over the sphere divided by 4π (the mean radiance), for reports.
    pub fn mean_radiance(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for (i, t) in self.texels.iter().enumerate() {
            let omega = texel_solid_angle(i as u32 / self.width, self.width, self.height);
            for c in 0..3 {
                sum[c] += f64::from(t[c]) * omega;
            }
        }
        sum.map(|s| s / (4.0 * PI))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angles_cover_the_sphere() {
        let (w, h) = (16, 8);
        let total: f64 = (0..h)
            .map(|y| texel_solid_angle(y, w, h) * f64::from(w))
            .sum();
        assert!((total - 4.0 * PI).abs() < 1e-9, "{total}");
    }

    #[test]
    fn non_finite_texels_are_refused() {
        let mut rgb = vec![[1.0f32; 3]; 8];
        rgb[5][1] = f32::NAN;
        let e = EnvMap::from_rgb(Path::new("sky.exr"), 4, 2, rgb).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("sky.exr") && text.contains("(1, 1)"),
            "{text}"
        );
    }

    #[test]
    fn constant_map_has_unit_mean_and_solid_angle_pmf() {
        let map = EnvMap::from_rgb(Path::new("c.exr"), 8, 4, vec![[2.0; 3]; 32]).unwrap();
        let mean = map.mean_radiance();
        assert!((mean[0] - 2.0).abs() < 1e-9);
        // pmf ∝ solid angle for a constant map.
        let pmf0 = f64::from(map.alias[0].pmf);
        let expected = texel_solid_angle(0, 8, 4) / (4.0 * PI);
        assert!((pmf0 - expected).abs() < 1e-6, "{pmf0} {expected}");
    }
}
