//! CPU estimates the direct-light tests hold the cache's direct pass against
//! (`tests/tests/ic_direct.rs`, `tests/tests/ic_emitter_shadows.rs`): the emitters' light by
//! uniform area sampling with CPU visibility, and agreement of two per-pixel estimates within
//! their standard error.

use std::f64::consts::PI;

use glam::DVec3;
use radcache_scene::Scene;

use crate::ic_fixture::{cast, world_triangles, xyz, GRead, Tri};
use crate::scenes::mean_se;
use crate::Rng;

/// ρ/π × the irradiance from emissive triangles at the G-buffer's points: `m` uniform area
/// samples of the emitters per pixel with CPU visibility (no MIS: independent of the GPU's).
pub fn cpu_direct(scene: &Scene, g: &GRead, m: usize) -> Vec<DVec3> {
    let tris = world_triangles(scene);
    let emission = |t: &Tri| scene.material_emission[t.material as usize].as_dvec3();
    let lights: Vec<&Tri> = tris
        .iter()
        .filter(|t| emission(t).max_element() > 0.0)
        .collect();
    let area = |t: &Tri| 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length() as f64;
    let total: f64 = lights.iter().map(|t| area(t)).sum();
    let mut rng = Rng::new(5);
    let mut next = || f64::from(rng.f32());
    let mut out = vec![DVec3::ZERO; g.position.len()];
    for (i, value) in out
        .iter_mut()
        .enumerate()
        .filter(|(i, _)| g.position[*i][3] > 0.0)
    {
        let (p, n) = (xyz(g.position[i]), xyz(g.geometric[i]));
        let mut sum = DVec3::ZERO;
        for _ in 0..m {
            let mut pick = next() * total;
            let t = lights.iter().find(|t| {
                pick -= area(t);
                pick < 0.0
            });
            let t = t.unwrap_or(&lights[lights.len() - 1]);
            let (mut a, mut b) = (next(), next());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let [p0, p1, p2] = t.p.map(|v| v.as_dvec3());
            let to = p0 * (1.0 - a - b) + p1 * a + p2 * b - p;
            let dist = to.length();
            let dir = to / dist;
            let cos_l = -t.front.dot(dir);
            let cos_l = if scene.materials[t.material as usize].double_sided {
                cos_l.abs()
            } else {
                cos_l
            };
            let cos_s = n.dot(dir);
            if cos_s > 0.0
                && cos_l > 0.0
                && cast(&tris, p + n * 1e-5, dir, dist * (1.0 - 1e-4)).is_none()
            {
                sum += emission(t) * cos_s * cos_l / (dist * dist) * total;
            }
        }
        *value = xyz(g.albedo[i]) / PI * sum / m as f64;
    }
    out
}

/// |mean(a − b)| over `pixels` within 5 standard errors, per channel.
pub fn agree(what: &str, a: &[DVec3], b: &[DVec3], pixels: &[usize]) {
    for c in 0..3 {
        let d: Vec<f64> = pixels.iter().map(|&i| a[i][c] - b[i][c]).collect();
        let m = mean_se(&d);
        let scale = pixels.iter().map(|&i| b[i][c]).sum::<f64>() / pixels.len() as f64;
        eprintln!(
            "{what} channel {c}: mean difference {:.3e} ± {:.3e} (mean {scale:.4})",
            m.mean, m.se
        );
        assert!(
            m.mean.abs() <= 5.0 * m.se + 1e-5 * scale,
            "{what} channel {c}: {m:?}"
        );
    }
}
