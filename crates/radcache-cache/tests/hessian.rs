//! The Hessian error control (`radcache_cache::hessian`, docs/irradiance-cache.md §10) against
//! independent answers:
//! * the edge Hessian against central second differences of an f64 edge term;
//! * the polygon sum against the irradiance of a uniformly emitting parallelogram integrated
//!   numerically (Simpson, f64) and its second differences at displaced points;
//! * the whole record ([`compute_hessian`]) from stratified samples cast at that parallelogram
//!   against the same finite differences;
//! * uniform environments (all sky, a closed room): a zero Hessian and the largest radius.

use glam::{DVec3, Vec3, Vec4};
use radcache_cache::hessian::*;
use radcache_cache::sampling::{stratum_direction_local, stratum_index, stratum_jitter};
use radcache_cache::IC_FAR;

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn f64(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
}

/// The edge term `½ γ n·(a×b)/|a×b|` in f64, `n = +Z`.
fn edge_f64(a: DVec3, b: DVec3) -> f64 {
    let c = a.cross(b);
    let s = c.length();
    if s == 0.0 {
        return 0.0;
    }
    0.5 * s.atan2(a.dot(b)) * c.z / s
}

/// Second differences `(H_tt, H_tb, H_bb)` of `f` at the origin in the tangent plane, step `d`.
fn second_differences(f: impl Fn(DVec3) -> f64, d: f64) -> [f64; 3] {
    let at = |x: f64, y: f64| f(DVec3::new(x * d, y * d, 0.0));
    let c = at(0.0, 0.0);
    let htt = (at(1.0, 0.0) - 2.0 * c + at(-1.0, 0.0)) / (d * d);
    let hbb = (at(0.0, 1.0) - 2.0 * c + at(0.0, -1.0)) / (d * d);
    let htb = (at(1.0, 1.0) - at(1.0, -1.0) - at(-1.0, 1.0) + at(-1.0, -1.0)) / (4.0 * d * d);
    [htt, htb, hbb]
}

fn norm(h: [f64; 3]) -> f64 {
    (h[0] * h[0] + 2.0 * h[1] * h[1] + h[2] * h[2]).sqrt()
}

fn diff(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

fn hess(v: Vec4) -> [f64; 3] {
    [v.y as f64, v.z as f64, v.w as f64]
}

/// A vertex: a point (`w = 1`) or a direction (`w = 0`) in the upper half space.
fn vertex(rng: &mut Rng, dist: f64, finite: bool) -> DVec3 {
    let (ct, phi) = (rng.range(0.05, 1.0), rng.range(-3.1, 3.1));
    let st = (1.0 - ct * ct).sqrt();
    DVec3::new(st * phi.cos(), st * phi.sin(), ct) * if finite { dist } else { 1.0 }
}

#[test]
fn edge_hessian_matches_second_differences() {
    let mut rng = Rng(0x5eed_1234_5678);
    let (mut series, mut closed) = (0, 0);
    for i in 0..400 {
        let (fa, fb) = match i % 5 {
            0 => (true, false),
            1 => (false, true),
            _ => (true, true),
        };
        let dist = rng.range(0.2, 5.0);
        let a = vertex(&mut rng, dist, fa);
        // Neighbouring samples (small angles, the series) and wide edges (the closed forms).
        let spread = if i % 2 == 0 { 0.25 } else { 2.0 };
        let dir = (a.normalize()
            + DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.3) * spread)
            .normalize();
        let dir = DVec3::new(dir.x, dir.y, dir.z.abs().max(0.02)).normalize();
        let b = dir * if fb { rng.range(0.2, 5.0) } else { 1.0 };
        let va = a.as_vec3().extend(f32::from(fa));
        let vb = b.as_vec3().extend(f32::from(fb));
        let got = hessian_edge(va, vb);
        let at = |x: DVec3| {
            let pa = if fa { a - x } else { a };
            let pb = if fb { b - x } else { b };
            edge_f64(pa, pb)
        };
        let near = if fa { a.length() } else { b.length() }.min(if fb { b.length() } else { 1e9 });
        let fd = second_differences(at, 1e-3 * near);
        let c = a.cross(b);
        let tau = c.length_squared() / a.dot(b).powi(2);
        if a.dot(b) > 0.0 && tau < 0.15 {
            series += 1;
        } else {
            closed += 1;
        }
        assert!(
            (got.x as f64 - at(DVec3::ZERO)).abs() < 1e-6,
            "f: {got} {a} {b}"
        );
        let err = diff(hess(got), fd);
        assert!(
            err <= 2e-3 * norm(fd) + 1e-5 / (near * near),
            "{i}: {got} vs {fd:?} ({a}, {b})"
        );
    }
    assert!(
        series > 100 && closed > 100,
        "{series} series, {closed} closed"
    );
    // Two directions: no Hessian.
    let far = hessian_edge(Vec4::new(0.0, 0.6, 0.8, 0.0), Vec4::new(0.6, 0.0, 0.8, 0.0));
    assert!(far.x != 0.0 && far.y == 0.0 && far.z == 0.0 && far.w == 0.0);
}

#[test]
fn angle_terms_are_continuous_at_the_series_threshold() {
    for h in [0.3f32, 1.0, 4.0] {
        let s2 = 0.15 * h * h;
        let below = hessian_angle_terms(s2 * 0.99999, h);
        let above = hessian_angle_terms(s2 * 1.00001, h);
        for c in 0..3 {
            let (x, y) = (below[c], above[c]);
            assert!(
                (x - y).abs() <= 2e-4 * x.abs().max(y.abs()),
                "h {h}: {below} vs {above}"
            );
        }
    }
    assert_eq!(hessian_angle_terms(0.0, -1.0), Vec3::ZERO);
    assert_eq!(hessian_angle_terms(0.0, 0.0), Vec3::ZERO);
}

/// A uniformly emitting parallelogram `p0 + u e1 + v e2` (radiance 1), emitting to both sides.
struct Light {
    p0: DVec3,
    e1: DVec3,
    e2: DVec3,
}

impl Light {
    /// Its irradiance at `x` (normal +Z) by Simpson's rule on a 400 × 400 grid.
    fn irradiance(&self, x: DVec3) -> f64 {
        let n = 400;
        let ne = self.e1.cross(self.e2);
        let area = ne.length();
        let ne = ne / area;
        let w = |i: usize| match i {
            0 => 1.0,
            i if i == n => 1.0,
            i if i % 2 == 1 => 4.0,
            _ => 2.0,
        };
        let mut sum = 0.0;
        for i in 0..=n {
            for j in 0..=n {
                let y = self.p0 + self.e1 * (i as f64 / n as f64) + self.e2 * (j as f64 / n as f64);
                let d = y - x;
                let d2 = d.length_squared();
                let g = d.z.max(0.0) * d.dot(ne).abs() / (d2 * d2);
                sum += w(i) * w(j) * g;
            }
        }
        sum * area / (9.0 * (n * n) as f64)
    }

    fn corners(&self) -> [DVec3; 4] {
        let p = self.p0;
        [p, p + self.e1, p + self.e1 + self.e2, p + self.e2]
    }
}

fn lights() -> [Light; 2] {
    [
        Light {
            p0: DVec3::new(-0.3, -0.5, 1.0),
            e1: DVec3::new(1.2, 0.0, 0.0),
            e2: DVec3::new(0.0, 0.8, 0.0),
        },
        // Tilted and off to the side (a wall-like source).
        Light {
            p0: DVec3::new(0.4, -0.6, 0.1),
            e1: DVec3::new(0.3, 0.0, 0.0),
            e2: DVec3::new(0.2, 0.0, 1.4),
        }
        .oriented(),
    ]
}

impl Light {
    /// The same light with its corners in the order whose edge sum is positive from the origin.
    fn oriented(self) -> Light {
        let c = self.corners();
        let s: f64 = (0..4).map(|i| edge_f64(c[i], c[(i + 1) % 4])).sum();
        if s >= 0.0 {
            self
        } else {
            Light {
                p0: self.p0,
                e1: self.e2,
                e2: self.e1,
            }
        }
    }
}

/// `(E, [H_tt, H_tb, H_bb])` of a light at the origin by numerical integration.
fn reference(light: &Light) -> (f64, [f64; 3]) {
    let e = light.irradiance(DVec3::ZERO);
    (e, second_differences(|x| light.irradiance(x), 0.01))
}

#[test]
fn polygon_edge_sum_matches_the_integrated_irradiance() {
    for light in lights() {
        let (e, h) = reference(&light);
        let c = light.corners();
        let mut sum = Vec4::ZERO;
        for i in 0..4 {
            let v = |p: DVec3| p.as_vec3().extend(1.0);
            sum += hessian_edge(v(c[i]), v(c[(i + 1) % 4]));
        }
        eprintln!("E {e} vs {}; H {h:?} vs {sum}", sum.x);
        assert!((sum.x as f64 - e).abs() <= 1e-5 * e, "{} vs {e}", sum.x);
        assert!(diff(hess(sum), h) <= 2e-3 * norm(h), "{sum} vs {h:?}");
        assert!(norm(h) > 0.1 * e, "a configuration with curvature");
    }
}

/// The samples of an `m × n` record at the origin (normal +Z) looking at `light`: radiance 1 on
/// a hit, 0 and a miss elsewhere.
fn samples(light: &Light, m: u32, n: u32, seed: u32) -> (Vec<Vec3>, Vec<f32>) {
    let (mut l, mut r) = (Vec::new(), Vec::new());
    let ne = light.e1.cross(light.e2);
    for j in 0..m {
        for k in 0..n {
            let (xi, psi) = stratum_jitter(seed, stratum_index(j, k, n));
            let d = stratum_direction_local(j, k, m, n, xi, psi).as_dvec3();
            let t = (light.p0.dot(ne)) / d.dot(ne);
            let y = d * t - light.p0;
            // Coordinates of the hit in (e1, e2).
            let (g11, g12, g22) = (
                light.e1.dot(light.e1),
                light.e1.dot(light.e2),
                light.e2.dot(light.e2),
            );
            let (b1, b2) = (y.dot(light.e1), y.dot(light.e2));
            let det = g11 * g22 - g12 * g12;
            let (u, v) = ((b1 * g22 - b2 * g12) / det, (b2 * g11 - b1 * g12) / det);
            let hit = t > 0.0 && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v);
            l.push(if hit { Vec3::ONE } else { Vec3::ZERO });
            r.push(if hit { t as f32 } else { IC_FAR });
        }
    }
    (l, r)
}

#[test]
fn record_hessian_from_samples_matches_the_reference() {
    for light in lights() {
        let (e, h) = reference(&light);
        let rel = h.map(|x| x / e);
        let mut errors = Vec::new();
        for (m, n) in [(16, 48), (32, 96)] {
            let mut mean = [0.0f64; 3];
            let seeds = 8;
            for seed in 0..seeds {
                let (l, r) = samples(&light, m, n, seed);
                let got = compute_hessian(&l, &r, m, n, seed, 1e-6);
                // The model irradiance is normalised to π, less the light's outline that the
                // farthest-vertex rule gives to the background (a stratum wide).
                let pi = std::f32::consts::PI;
                assert!(got.x > 0.2 * pi && got.x < 1.001 * pi, "E' {}", got.x);
                for (acc, h) in mean.iter_mut().zip(hess(got)) {
                    *acc += h / got.x as f64 / seeds as f64;
                }
            }
            let err = diff(mean, rel) / norm(rel);
            eprintln!("{m}x{n}: relative H {mean:?} vs {rel:?}: error {err:.3}");
            errors.push(err);
        }
        // The sample mesh approximates the light's outline to a stratum: the error shrinks
        // with the strata.
        assert!(errors[1] < 0.15 && errors[1] < errors[0], "{errors:?}");
    }
}

#[test]
fn uniform_environments_give_a_zero_hessian_and_the_largest_radius() {
    let (m, n) = (16, 48);
    let l = vec![Vec3::splat(0.7); (m * n) as usize];
    // All sky: every vertex is a direction.
    let sky = compute_hessian(&l, &vec![IC_FAR; (m * n) as usize], m, n, 3, 1e-6);
    assert!((sky.x - std::f32::consts::PI).abs() < 1e-3, "{sky}");
    assert_eq!((sky.y, sky.z, sky.w), (0.0, 0.0, 0.0));
    assert_eq!(hessian_radius(sky, 0.01), IC_FAR);
    // A closed box around the point (1 × 1.2 × 0.8 high, off centre), uniformly bright.
    let (lo, hi) = (DVec3::new(-0.3, -0.7, 0.0), DVec3::new(0.7, 0.5, 0.8));
    let mut r = Vec::new();
    for j in 0..m {
        for k in 0..n {
            let (xi, psi) = stratum_jitter(3, stratum_index(j, k, n));
            let d = stratum_direction_local(j, k, m, n, xi, psi).as_dvec3();
            let t = (0..3)
                .map(|a| {
                    let bound = if d[a] > 0.0 { hi[a] } else { lo[a] };
                    if d[a] == 0.0 {
                        f64::INFINITY
                    } else {
                        bound / d[a]
                    }
                })
                .fold(f64::INFINITY, f64::min);
            r.push(t as f32);
        }
    }
    let room = compute_hessian(&l, &r, m, n, 3, 1e-6);
    // The same room with its far half dark has curvature of order 1/distance².
    let half: Vec<Vec3> = (0..(m * n) as usize)
        .map(|i| {
            if i % n as usize >= (n / 2) as usize {
                Vec3::ZERO
            } else {
                l[i]
            }
        })
        .collect();
    let lit = compute_hessian(&half, &r, m, n, 3, 1e-6);
    let lambda = |h: Vec4| (h.y.abs() + h.w.abs() + 2.0 * h.z.abs()) / h.x;
    eprintln!(
        "room {room} ({}), half {lit} ({})",
        lambda(room),
        lambda(lit)
    );
    assert!((room.x - std::f32::consts::PI).abs() < 1e-3, "{room}");
    assert!(
        lambda(room) < 1e-4 * lambda(lit) && lambda(lit) > 0.5,
        "{room} vs {lit}"
    );
    assert!(hessian_radius(room, 0.01) > 10.0 * hessian_radius(lit, 0.01));
}

#[test]
fn radius_follows_the_eigenvalue_and_the_footprint() {
    let h = Vec4::new(3.0, 2.0, -0.5, 0.5);
    let base = hessian_radius(h, 0.01);
    // λ_max of [[2, −0.5], [−0.5, 0.5]] = 1.25 + sqrt(0.5625 + 0.25).
    let lambda = 1.25 + (0.5625f32 + 0.25).sqrt();
    let want = (4.0 * radcache_cache::HESSIAN_ERROR * 1e-4 * 3.0 / lambda).powf(0.25);
    assert!((base - want).abs() <= 1e-5 * want, "{base} vs {want}");
    // R ∝ |λ|^{-1/4} and ∝ √s; a negative-definite Hessian counts by its magnitude.
    let steeper = Vec4::new(3.0, 32.0, -8.0, 8.0);
    assert!((hessian_radius(steeper, 0.01) - base / 2.0).abs() <= 1e-5 * base);
    assert!((hessian_radius(h, 0.04) - 2.0 * base).abs() <= 1e-5 * base);
    let neg = Vec4::new(3.0, -2.0, 0.5, -0.5);
    assert_eq!(hessian_radius(neg, 0.01), base);
    assert_eq!(hessian_radius(Vec4::new(0.0, 1.0, 0.0, 1.0), 0.01), IC_FAR);
}

#[test]
fn vertices_luminances_and_the_farthest_rule() {
    let v = hessian_vertex(3, 5, 8, 24, 77, 2.0, 1e-4);
    let (xi, psi) = stratum_jitter(77, stratum_index(3, 5, 24));
    let d = stratum_direction_local(3, 5, 8, 24, xi, psi);
    assert_eq!(v, (d * 2.0).extend(1.0));
    assert_eq!(hessian_vertex(3, 5, 8, 24, 77, IC_FAR, 1e-4), d.extend(0.0));
    assert_eq!(hessian_vertex(3, 5, 8, 24, 77, 1e-5, 1e-4), d.extend(0.0));
    let hz = hessian_horizon_vertex(v);
    assert!(hz.z == 0.0 && (hz.truncate().length() - 2.0).abs() < 1e-6 && hz.w == 1.0);
    assert!((hz.x * v.y - hz.y * v.x).abs() < 1e-6, "same azimuth");
    assert_eq!(hessian_luminance(2.0, 1.0), 1.99);
    assert_eq!(hessian_luminance(0.0, 0.0), 1.0);
    let (near, far, sky) = (
        Vec4::new(0.0, 0.0, 1.0, 1.0),
        Vec4::new(0.0, 3.0, 0.0, 1.0),
        Vec4::Z,
    );
    assert_eq!(hessian_farthest(near, 1.0, far, 2.0, near, 3.0), 2.0);
    assert_eq!(hessian_farthest(near, 1.0, far, 2.0, sky, 3.0), 3.0);
    assert_eq!(hessian_vertex_distance(sky), IC_FAR);
}
