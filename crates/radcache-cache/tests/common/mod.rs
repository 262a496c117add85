//! Analytic test scenes for the record/gradient tests (docs/irradiance-cache.md §3.3): uniformly
//! emitting (or black) rectangles under a uniform sky, with
//! * CPU ray casting (ray–rectangle, f64) to produce the per-stratum samples `L_jk`, `r_jk`;
//! * the exact irradiance `E(p, n)` by Lambert's polygon formula (projected solid angle of each
//!   rectangle clipped to the hemisphere of `n`), used as the finite-difference reference.
//!
//! Closed form: `E(p, n) = π·L_sky + Σ_rect (L_rect − L_sky)·Φ(rect)`, valid when no two
//! rectangles overlap as seen from `p` (true for every scene built here), where
//! `Φ = ½ |Σ_edges angle(a_i, a_{i+1}) · n·normalize(a_i × a_{i+1})|`, `a_i = v_i − p`.

#![allow(dead_code)]

use glam::{DVec3, Vec3};
use radcache_cache::record::{compute_record, RecordEstimate};
use radcache_cache::sampling::{
    basis_from_normal, frame_to_world, normalize_or_z, stratum_direction_local, stratum_index,
    stratum_jitter,
};

/// A parallelogram `corner + u·e1 + v·e2`, `u, v ∈ [0, 1]`, emitting `radiance` on both sides.
#[derive(Clone, Copy, Debug)]
pub struct Rect {
    pub corner: DVec3,
    pub e1: DVec3,
    pub e2: DVec3,
    pub radiance: DVec3,
}

impl Rect {
    pub fn new(corner: DVec3, e1: DVec3, e2: DVec3, radiance: DVec3) -> Self {
        Self {
            corner,
            e1,
            e2,
            radiance,
        }
    }

    fn vertices(&self) -> [DVec3; 4] {
        [
            self.corner,
            self.corner + self.e1,
            self.corner + self.e1 + self.e2,
            self.corner + self.e2,
        ]
    }

    /// Ray parameter of the hit, if any (`t > 1e-9`).
    pub fn intersect(&self, o: DVec3, d: DVec3) -> Option<f64> {
        let nrm = self.e1.cross(self.e2);
        let denom = d.dot(nrm);
        if denom.abs() < 1e-300 {
            return None;
        }
        let t = (self.corner - o).dot(nrm) / denom;
        if t <= 1e-9 {
            return None;
        }
        let q = o + d * t - self.corner;
        // Solve q = u e1 + v e2 in the plane (general parallelogram).
        let (a11, a12, a22) = (
            self.e1.dot(self.e1),
            self.e1.dot(self.e2),
            self.e2.dot(self.e2),
        );
        let (b1, b2) = (q.dot(self.e1), q.dot(self.e2));
        let det = a11 * a22 - a12 * a12;
        let u = (b1 * a22 - b2 * a12) / det;
        let v = (a11 * b2 - a12 * b1) / det;
        ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)).then_some(t)
    }
}

/// Rectangles under a uniform sky (radiance `sky` on misses).
#[derive(Clone, Debug)]
pub struct Scene {
    pub rects: Vec<Rect>,
    pub sky: DVec3,
}

impl Scene {
    /// Closest hit: `(radiance, distance)`; a miss returns `(sky, +inf)`.
    pub fn trace(&self, o: DVec3, d: DVec3) -> (DVec3, f64) {
        let mut best = (self.sky, f64::INFINITY);
        for r in &self.rects {
            if let Some(t) = r.intersect(o, d) {
                if t < best.1 {
                    best = (r.radiance, t);
                }
            }
        }
        best
    }

    /// Exact irradiance at `p` with unit normal `n` (Lambert's formula, see the module docs).
    pub fn irradiance(&self, p: DVec3, n: DVec3) -> DVec3 {
        let n = n.normalize();
        let mut e = self.sky * std::f64::consts::PI;
        for r in &self.rects {
            e += (r.radiance - self.sky) * projected_solid_angle(&r.vertices(), p, n);
        }
        e
    }

    /// Samples the `M × N` strata around `(p, n)` with the production direction code and the
    /// deterministic jitter of record `seed`; returns `(L, r)` in `j*N + k` order.
    pub fn sample(&self, p: Vec3, n: Vec3, m: u32, nn: u32, seed: u32) -> (Vec<Vec3>, Vec<f32>) {
        let nrm = normalize_or_z(n);
        let (t, b) = basis_from_normal(nrm);
        let mut ls = vec![Vec3::ZERO; (m * nn) as usize];
        let mut rs = vec![0.0f32; (m * nn) as usize];
        for j in 0..m {
            for k in 0..nn {
                let i = stratum_index(j, k, nn);
                let (xi, psi) = stratum_jitter(seed, i);
                let w = frame_to_world(stratum_direction_local(j, k, m, nn, xi, psi), t, b, nrm);
                let (l, r) = self.trace(p.as_dvec3(), w.as_dvec3().normalize());
                ls[i as usize] = l.as_vec3();
                rs[i as usize] = r as f32;
            }
        }
        (ls, rs)
    }

    /// Samples and reduces one record.
    pub fn record(&self, p: Vec3, n: Vec3, m: u32, nn: u32, seed: u32) -> RecordEstimate {
        let (l, r) = self.sample(p, n, m, nn, seed);
        compute_record(&l, &r, m, nn, n, 1e-6)
    }
}

/// Projected solid angle (irradiance per unit radiance) of a convex polygon seen from `p` with unit
/// normal `n`, after clipping it to the half-space `(x − p)·n >= 0`.
pub fn projected_solid_angle(poly: &[DVec3], p: DVec3, n: DVec3) -> f64 {
    let clipped = clip_to_half_space(poly, p, n);
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..clipped.len() {
        let a = clipped[i] - p;
        let b = clipped[(i + 1) % clipped.len()] - p;
        let c = a.cross(b);
        let len = c.length();
        if len < 1e-300 {
            continue;
        }
        let angle = len.atan2(a.dot(b));
        sum += angle * n.dot(c / len);
    }
    0.5 * sum.abs()
}

/// Sutherland–Hodgman clip of a convex polygon to `(x − p)·n >= 0`.
fn clip_to_half_space(poly: &[DVec3], p: DVec3, n: DVec3) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = ((a - p).dot(n), (b - p).dot(n));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Rotates `v` about the unit `axis` by `angle` (Rodrigues).
pub fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(v) * s + axis * axis.dot(v) * (1.0 - c)
}

/// Channel `c` of a `DVec3`.
pub fn ch(v: DVec3, c: usize) -> f64 {
    v.to_array()[c]
}
