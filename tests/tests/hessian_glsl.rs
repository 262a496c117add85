//! The GLSL twin of `radcache_cache::hessian` (the Hessian error control, in
//! `shaders/common/ircache_math.glsl`) evaluated ON LAVAPIPE against the Rust functions:
//! random edges (points and directions, narrow edges on the series branch and wide ones on the
//! closed forms), vertices, cells with every flag, radii, and whole sample sets through
//! `compute_hessian` (random radiance and distances with misses and invalid samples, the
//! smallest grid, a uniform room, all sky). `shaders/tests/ircache_twin.comp` (modes
//! `HessianTerms`, `HessianRecord`) evaluates one row per invocation.
//!
//! Tolerance: the harness's `|gpu − cpu| <= 1e-5 · max(|cpu|, scale) + 1e-6`, `scale` the size of
//! the terms a result is summed from: for an edge Hessian `1/r²` of its nearer point (the
//! magnitude of each chain-rule term), for a cell the sum of its edges' weighted scales, for a
//! sample set `max Y' · Σ 1/r²` over its points; for `G_S`, `G_SS` on the closed forms the sum of
//! the magnitudes of their terms; a radius `R = (c/|λ|)^{1/4}` inherits a quarter of `|λ|`'s
//! relative tolerance: `scale = R · scale_H / (4|λ|)` (with `|λ|` bounded by `|H_tt| + |H_tb| +
//! |H_bb|`).

use glam::{Vec2, Vec3, Vec4};
use radcache_cache::hessian::*;
use radcache_cache::{luminance_rec709, HESSIAN_SERIES_TAU, IC_FAR};
use radcache_tests::twin::{check_diffs, twin_pipeline, ub, unit, v4, Case, Expect, Row, TwinMode};
use radcache_tests::{context, finish, Rng};

/// A random vertex in the upper half space: a point at distance in `[0.05, 5]` or a direction.
fn vertex(rng: &mut Rng, finite: bool) -> Vec4 {
    let mut d = unit(rng);
    d.z = d.z.abs().max(0.01);
    let d = d.normalize();
    if finite {
        (d * rng.range(0.05, 5.0)).extend(1.0)
    } else {
        d.extend(0.0)
    }
}

/// A vertex near `v` in direction (a neighbouring sample) or anywhere (a wide edge).
fn neighbour(rng: &mut Rng, v: Vec4, narrow: bool, finite: bool) -> Vec4 {
    if !narrow {
        return vertex(rng, finite);
    }
    let d = (v.truncate().normalize() + Vec3::new(rng.range(-0.2, 0.2), rng.range(-0.2, 0.2), 0.0))
        .normalize();
    let d = Vec3::new(d.x, d.y, d.z.abs().max(0.01)).normalize();
    if finite {
        (d * rng.range(0.05, 5.0)).extend(1.0)
    } else {
        d.extend(0.0)
    }
}

/// `1/r²` of a vertex (0 for a direction).
fn inv_r2(v: Vec4) -> f32 {
    if v.w > 0.0 {
        1.0 / v.truncate().length_squared()
    } else {
        0.0
    }
}

fn edge_scale(a: Vec4, b: Vec4) -> f32 {
    inv_r2(a).max(inv_r2(b))
}

/// Scales of `(G, G_S, G_SS)`: the magnitudes of the closed forms' terms (0 on the series).
fn angle_scales(s2: f32, h: f32) -> Vec3 {
    if h > 0.0 && s2 < HESSIAN_SERIES_TAU * h * h {
        return Vec3::ZERO;
    }
    let (q, s) = (s2 + h * h, s2.sqrt());
    let gamma = s.atan2(h);
    let g_s = (h / (2.0 * s2 * q)).abs() + gamma / (2.0 * s2 * s);
    let g_ss = (3.0 * h / (4.0 * s2 * s2 * q)).abs()
        + (h / (2.0 * s2 * q * q)).abs()
        + 3.0 * gamma / (4.0 * s2 * s2 * s);
    Vec3::new(0.0, g_s, g_ss)
}

/// Mode HessianTerms: the per-edge, per-vertex and per-cell functions and the radius.
fn terms(rng: &mut Rng) -> Vec<Case> {
    let mut cases = Vec::new();
    for i in 0..400u32 {
        let narrow = i % 3 != 0;
        let a = vertex(rng, i % 7 != 0);
        let b = neighbour(rng, a, narrow, i % 5 != 0);
        let c = neighbour(rng, b, narrow, i % 11 != 0);
        let d = neighbour(rng, a, narrow, true);
        let bl = neighbour(rng, b, narrow, i % 13 != 0);
        let au = neighbour(rng, d, narrow, true);
        let ab = a.truncate().cross(b.truncate());
        let (s2, h) = (ab.length_squared(), a.truncate().dot(b.truncate()));
        let (m, n) = (1 + rng.below(24), 3 + rng.below(70));
        let (j, k, seed) = (rng.below(m), rng.below(n), rng.below(u32::MAX));
        let r = match i % 6 {
            0 => IC_FAR,
            1 => 1e-6,
            _ => rng.range(0.01, 10.0),
        };
        let (r_eps, mean_y) = (1e-4, if i % 9 == 0 { 0.0 } else { rng.range(0.1, 3.0) });
        let y = Vec4::new(rng.f32(), rng.f32(), rng.f32(), rng.f32()) * 2.0;
        let (y_bl, y_au, y_cap) = (rng.f32() * 2.0, rng.f32() * 2.0, rng.f32() * 2.0);
        let flags = i % 4;
        let hsum = Vec4::new(
            rng.range(0.5, 3.5),
            rng.range(-9.0, 9.0),
            rng.range(-9.0, 9.0),
            rng.range(-9.0, 9.0),
        );
        let hsum = if i % 17 == 0 {
            Vec4::new(3.0, 0.0, 0.0, 0.0)
        } else {
            hsum
        };
        let footprint = rng.range(1e-4, 0.05);
        let (u, v) = (
            Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)),
            Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)),
        );
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = a.to_array();
        row[1] = b.to_array();
        row[2] = [s2, h, footprint, 0.0];
        row[3] = [ub(j), ub(k), ub(m), ub(n)];
        row[4] = [ub(seed), r, r_eps, mean_y];
        row[5] = c.to_array();
        row[6] = d.to_array();
        row[7] = bl.to_array();
        row[8] = au.to_array();
        row[9] = y.to_array();
        row[10] = [y_bl, y_au, y_cap, ub(flags)];
        row[11] = hsum.to_array();
        row[12] = [u.x, u.y, v.x, v.y];
        let mut e = Expect::new();
        let edge = hessian_edge(a, b);
        e.f(0, 0, edge.x, 1.0);
        let es = edge_scale(a, b);
        for lane in 1..4 {
            e.f(0, lane, edge[lane], es);
        }
        let g = hessian_angle_terms(s2, h);
        let gs = angle_scales(s2, h);
        for lane in 0..3 {
            e.f(1, lane, g[lane], gs[lane]);
        }
        e.f(1, 3, hessian_vertex_distance(a), 0.0);
        let vtx = hessian_vertex(j, k, m, n, seed, r, r_eps);
        let reach = if vtx.w > 0.0 { r } else { 1.0 };
        e.s(2, vtx.to_array(), reach);
        e.s(
            3,
            hessian_horizon_vertex(a).to_array(),
            a.truncate().length(),
        );
        e.f(4, 0, hessian_luminance(r, mean_y), 0.0);
        e.exact(4, 1, hessian_farthest(a, y.x, b, y.y, c, y.z));
        // |λ| is a sum of magnitudes here (no cancellation): relative rounding only.
        e.f(4, 2, hessian_radius(hsum, footprint), 0.0);
        let cell = hessian_cell(&HessianCell {
            a,
            b,
            c,
            d,
            bl,
            au,
            y,
            y_bl,
            y_au,
            y_cap,
            first: flags & 1 != 0,
            last: flags & 2 != 0,
        });
        let cs = 2.0 * (edge_scale(b, d) + edge_scale(a, b) + edge_scale(a, d) + edge_scale(b, c));
        e.f(5, 0, cell.x, 8.0);
        for lane in 1..4 {
            e.f(5, lane, cell[lane], cs);
        }
        e.v(6, hessian_outer(u, v), 18.0);
        cases.push((row, e));
    }
    cases
}

/// Mode HessianRecord: whole sample sets; returns the cases and the samples buffer.
fn records(rng: &mut Rng) -> (Vec<Case>, Vec<[f32; 4]>) {
    let r_eps = 1e-4;
    // (m, n, L kind, r kind): random L, r with misses and invalid samples; all sky; the
    // smallest grid; uniform L in a room; the default grid; a dark half.
    let sets = [
        (4, 12, 0, 0),
        (4, 12, 0, 1),
        (1, 3, 0, 0),
        (8, 24, 1, 2),
        (16, 48, 0, 0),
        (8, 24, 2, 2),
    ];
    let (mut cases, mut samples) = (Vec::new(), Vec::new());
    for (set, (m, n, l_kind, r_kind)) in sets.into_iter().enumerate() {
        let seed = rng.below(u32::MAX);
        let (mut l, mut r) = (Vec::new(), Vec::new());
        for s in 0..m * n {
            l.push(match l_kind {
                0 => Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0,
                1 => Vec3::splat(0.75),
                _ => Vec3::splat(if s % n < n / 2 { 1.0 } else { 0.0 }),
            });
            r.push(match (r_kind, s % 10) {
                (1, _) | (0, 3) => IC_FAR,
                (0, 7) if s < 10 => r_eps * 0.5,
                (2, _) => 0.6 + 0.3 * ((s * 7919) % 13) as f32 / 13.0,
                _ => rng.range(0.05, 3.0),
            });
        }
        let footprint = 0.01 * (1 + set) as f32;
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = [footprint, r_eps, 0.0, 0.0];
        row[1] = [ub(m), ub(n), ub(samples.len() as u32), ub(seed)];
        samples.extend(l.iter().zip(&r).map(|(l, r)| v4(*l, *r)));
        let h = compute_hessian(&l, &r, m, n, seed, r_eps);
        let mean_y = l.iter().map(|&c| luminance_rec709(c)).sum::<f32>() / (m * n) as f32;
        let y_max = l
            .iter()
            .map(|&c| hessian_luminance(luminance_rec709(c), mean_y))
            .fold(0.0, f32::max);
        let sum_inv: f32 = r
            .iter()
            .filter(|&&x| x > r_eps && x < IC_FAR)
            .map(|x| 1.0 / (x * x))
            .sum();
        let scale = y_max * sum_inv;
        let mut e = Expect::new();
        e.f(0, 0, h.x, 4.0 * y_max);
        for lane in 1..4 {
            e.f(0, lane, h[lane], scale);
        }
        let rad = hessian_radius(h, footprint);
        let lambda = h.y.abs() + h.z.abs() + h.w.abs();
        let rad_scale = if rad < IC_FAR {
            rad * scale / (4.0 * lambda)
        } else {
            0.0
        };
        e.f(1, 0, rad, rad_scale);
        assert_eq!(r_kind == 1, rad == IC_FAR, "set {set}: {h} {rad}");
        cases.push((row, e));
    }
    (cases, samples)
}

#[test]
fn hessian_twin_matches_the_rust_formulas_on_the_gpu() {
    let ctx = context();
    let pipeline = twin_pipeline(&ctx, "ircache_twin.comp", "ircache_twin");
    let mut rng = Rng::new(0x4e55_1a2b);
    let report = |name: &str, d: [[radcache_tests::twin::LaneDiff; 4]; 16], slots: usize| {
        for (s, lanes) in d.iter().take(slots).enumerate() {
            let worst = lanes.iter().map(|l| l.of_tolerance).fold(0.0, f32::max);
            eprintln!("{name} slot {s}: largest share of the tolerance {worst:.3}");
        }
    };
    let cases = terms(&mut rng);
    let d = check_diffs(&ctx, &pipeline, TwinMode::HessianTerms, &cases, &[]);
    report("terms", d, 7);
    let (cases, samples) = records(&mut rng);
    let d = check_diffs(&ctx, &pipeline, TwinMode::HessianRecord, &cases, &samples);
    report("records", d, 2);
    drop(pipeline);
    finish(ctx);
}
