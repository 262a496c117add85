//! The irradiance a uniformly emitting polygon sends to a Lambertian receiver, in closed form
//! (docs/materials.md §7): Lambert's formula for the projected solid angle of a polygon, after
//! clipping the polygon to the receiver's upper hemisphere. The direct pass of the cache uses it
//! for the unshadowed light of emissive triangles (the ratio estimator of docs/cache-frame.md
//! §2.2); GLSL twin: `shaders/common/polygon.glsl`.
//!
//! For a polygon with unit vectors `u_i` from the receiver to its vertices (in order),
//! `∫ cos θ dω = ½ |Σ_i θ_i · n·(u_i × u_{i+1}) / |u_i × u_{i+1}||` with
//! `θ_i = atan2(|u_i × u_{i+1}|, u_i·u_{i+1})` the angle of edge i, provided the polygon lies above
//! the receiver's tangent plane (Lambert 1760; Arvo 1995, "Applications of irradiance tensors to
//! the simulation of non-Lambertian phenomena", eq. 9). The part below the plane is cut off first
//! (Sutherland–Hodgman against the plane, at most one more vertex for a triangle).

use glam::Vec3;

/// Vertices of a triangle clipped by a plane: at most 4.
pub const CLIPPED_MAX: usize = 4;

/// `triangle` (world positions) clipped to the half-space `n·(x − p) ≥ 0`, written to `out` as
/// vectors from `p` in the triangle's winding order; returns the vertex count (0, 3 or 4).
pub fn clip_to_hemisphere(
    p: Vec3,
    n: Vec3,
    triangle: [Vec3; 3],
    out: &mut [Vec3; CLIPPED_MAX],
) -> usize {
    // Each corner's side is decided once, so an edge and its neighbour agree on it (at most
    // CLIPPED_MAX vertices come out).
    let d = triangle.map(|v| n.dot(v - p));
    let mut count = 0;
    for i in 0..3 {
        let j = (i + 1) % 3;
        let (a, b) = (triangle[i] - p, triangle[j] - p);
        let (a_in, b_in) = (d[i] >= 0.0, d[j] >= 0.0);
        if a_in && count < CLIPPED_MAX {
            out[count] = a;
            count += 1;
        }
        if a_in != b_in && count < CLIPPED_MAX {
            let t = d[i] / (d[i] - d[j]);
            out[count] = a + (b - a) * t;
            count += 1;
        }
    }
    if count < 3 {
        count = 0;
    }
    count
}

/// The angle of the edge from unit vector `a` to unit vector `b`, divided by `|a × b|`, times
/// `n·(a × b)`: one term of Lambert's sum (0 for coincident vertices).
pub fn edge_term(n: Vec3, a: Vec3, b: Vec3) -> f32 {
    let c = a.cross(b);
    let s = c.length();
    let theta = s.atan2(a.dot(b));
    // θ / sin θ → 1 as the edge shrinks.
    let ratio = if s > 1e-7 { theta / s } else { 1.0 };
    n.dot(c) * ratio
}

/// The projected solid angle `∫ cos θ dω` of `triangle` seen from `p` with unit normal `n`,
/// over the part above the tangent plane: the irradiance per unit radiance of a uniformly
/// emitting triangle whose emitting face is towards `p` (the caller decides sidedness). In
/// `[0, π]`; 0 for a triangle wholly below the plane or degenerate.
pub fn triangle_projected_solid_angle(p: Vec3, n: Vec3, triangle: [Vec3; 3]) -> f32 {
    let mut q = [Vec3::ZERO; CLIPPED_MAX];
    let count = clip_to_hemisphere(p, n, triangle, &mut q);
    let mut sum = 0.0;
    for i in 0..count {
        let (a, b) = (q[i], q[(i + 1) % count]);
        let (la, lb) = (a.length(), b.length());
        if la > 0.0 && lb > 0.0 {
            sum += edge_term(n, a / la, b / lb);
        }
    }
    (0.5 * sum.abs()).min(std::f32::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The projected solid angle by quadrature over the triangle's area: ∫ cos θ_r cos θ_e / r²
    /// dA with the receiver's cosine clamped at 0 (midpoint rule on a fine barycentric grid).
    fn quadrature(p: Vec3, n: Vec3, t: [Vec3; 3]) -> f64 {
        let (p, n) = (p.as_dvec3(), n.as_dvec3());
        let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
        let ng = (b - a).cross(c - a);
        let area = 0.5 * ng.length();
        let ng = ng.normalize();
        let k = 400;
        let mut sum = 0.0;
        let cell = area / (k * k) as f64;
        for i in 0..k {
            for j in 0..k - i {
                // Two sub-triangles per cell (up and down), each with its centroid.
                for (di, dj, w) in [(1.0 / 3.0, 1.0 / 3.0, 1.0), (2.0 / 3.0, 2.0 / 3.0, 1.0)] {
                    let (u, v) = ((i as f64 + di) / k as f64, (j as f64 + dj) / k as f64);
                    if u + v > 1.0 {
                        continue;
                    }
                    let x = a + (b - a) * u + (c - a) * v;
                    let d = x - p;
                    let r2 = d.length_squared();
                    let dir = d / r2.sqrt();
                    let cos_r = n.dot(dir).max(0.0);
                    let cos_e = ng.dot(dir).abs();
                    sum += w * cos_r * cos_e / r2 * cell;
                }
            }
        }
        sum
    }

    struct Lcg(u64);
    impl Lcg {
        fn f(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
        fn v(&mut self, s: f32) -> Vec3 {
            Vec3::new(self.f() - 0.5, self.f() - 0.5, self.f() - 0.5) * 2.0 * s
        }
    }

    #[test]
    fn a_small_triangle_overhead_is_its_area_over_the_distance_squared() {
        let e = 1e-3;
        let t = [Vec3::Z, Vec3::new(e, 0.0, 1.0), Vec3::new(0.0, e, 1.0)];
        let got = triangle_projected_solid_angle(Vec3::ZERO, Vec3::Z, t);
        let want = 0.5 * e * e;
        assert!((got - want).abs() <= 1e-3 * want, "{got} vs {want}");
    }

    #[test]
    fn a_hemisphere_filling_polygon_gives_pi() {
        // A huge triangle just above the receiver covers nearly the whole hemisphere.
        let s = 1e4;
        let t = [
            Vec3::new(-s, -s, 1e-3),
            Vec3::new(3.0 * s, -s, 1e-3),
            Vec3::new(-s, 3.0 * s, 1e-3),
        ];
        let got = triangle_projected_solid_angle(Vec3::ZERO, Vec3::Z, t);
        assert!((f64::from(got) - PI).abs() < 1e-3, "{got}");
    }

    #[test]
    fn below_the_horizon_or_degenerate_gives_zero() {
        let t = [
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 1.0, -2.0),
        ];
        assert_eq!(triangle_projected_solid_angle(Vec3::ZERO, Vec3::Z, t), 0.0);
        let line = [Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.0)];
        assert!(triangle_projected_solid_angle(Vec3::ZERO, Vec3::Z, line).abs() < 1e-6);
        // In the receiver's own plane: no cosine, no light.
        let flat = [Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        assert!(triangle_projected_solid_angle(Vec3::ZERO, Vec3::Z, flat) < 1e-6);
    }

    #[test]
    fn lambert_matches_quadrature_for_random_triangles_crossing_the_horizon() {
        let mut rng = Lcg(2026);
        let mut crossing = 0;
        for _ in 0..60 {
            let p = rng.v(0.5);
            let n = rng.v(1.0).normalize();
            let centre = p + n * 0.6 + rng.v(0.8);
            let t = [
                centre + rng.v(0.5),
                centre + rng.v(0.5),
                centre + rng.v(0.5),
            ];
            let above = t.iter().filter(|v| n.dot(**v - p) >= 0.0).count();
            crossing += usize::from(above == 1 || above == 2);
            let got = f64::from(triangle_projected_solid_angle(p, n, t));
            let want = quadrature(p, n, t);
            assert!(
                (got - want).abs() <= 2e-3 * want.max(1e-2),
                "p {p} n {n} t {t:?}: Lambert {got}, quadrature {want}"
            );
            // The winding does not matter.
            let back = f64::from(triangle_projected_solid_angle(p, n, [t[0], t[2], t[1]]));
            assert!(
                (back - got).abs() <= 1e-4 * got.max(1e-2),
                "{back} vs {got}"
            );
        }
        assert!(
            crossing >= 10,
            "only {crossing} triangles crossed the horizon"
        );
    }
}
