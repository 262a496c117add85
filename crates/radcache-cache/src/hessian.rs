//! Hessian-based error control for the record radius (Schwarzhaupt, Jensen, Jarosz, *Practical
//! Hessian-Based Error Control for Irradiance Caching*, ACM TOG 31(6) (SIGGRAPH Asia), 2012);
//! docs/irradiance-cache.md §10 has the derivation, cited here as §10.N.
//!
//! All vectors are in the record's local frame `(t, b, n)` (`n = +Z`), relative to the record's
//! point. A *vertex* is a `Vec4`: a hit point `(p, 1)` or, for a miss, a unit direction `(ω, 0)`
//! (a point at infinity).
//!
//! * Environment (§10.1): the hit points of the `M × N` strata plus a ring of *horizon vertices*
//!   (row `M`: row `M − 1`'s hit points moved down to the tangent plane at the same distance)
//!   form a mesh of two triangles per grid cell, `A = (j,k)`, `B = (j+1,k)`, `C = (j+1,k+1)`,
//!   `D = (j,k+1)`, split along `B–D` into `T_lo = (A,B,D)` and `T_hi = (B,C,D)`; the *cap*
//!   inside row 0 is the polygon of row 0. Each triangle (and the cap) carries the normalised
//!   luminance of its farthest vertex (§10.2) `Y' = 0.99·Y/Ȳ + 0.01` (`Y' = 1` if `Ȳ = 0`).
//! * Model irradiance (§10.1): `E' = Σ_t Y'_t · ½ Σ_{edges P→Q of t} γ(P,Q) · n·(P×Q)/|P×Q|`.
//!   An edge shared by two triangles is evaluated once, weighted by the difference of their
//!   luminances; the horizon ring is a boundary.
//! * Edge Hessian (§10.3): for `f = ½ m G(S, h)`, `S = |a×b|²`, `h = a·b`, `m = n·(a×b)`,
//!   `G = γ/√S = atan2(√S, h)/√S`, with `a = P − x`, `b = Q − x` (`db/dx = 0` for a point at
//!   infinity), the chain rule over `(S, h, m)` with
//!   `∇S = 2 c×w`, `∇h = −(α b + β a)`, `∇m = n×w`, `H_S = 2(|w|²I − wwᵀ)`, `H_h = 2αβ I`, `H_m = 0`
//!   (`c = a×b`, `w = α b − β a`, `α, β` = 1 for points, 0 for directions) and
//!   `G_h = −1/Q`, `G_hh = 2h/Q²`, `G_Sh = 1/Q²` (`Q = S + h²`), and, for `τ = S/h² ≥ 0.15` or
//!   `h ≤ 0`, `G_S = h/(2SQ) − γ/(2S√S)`, `G_SS = −3h/(4S²Q) − h/(2SQ²) + 3γ/(4S²√S)`; for
//!   small `τ` (neighbouring samples: `γ` is a stratum wide) `G = φ(τ)/h`, `G_S = φ'(τ)/h³`,
//!   `G_SS = φ''(τ)/h⁵` by the series of `φ(τ) = atan(√τ)/√τ = Σ (−τ)^k/(2k+1)`, which avoids the
//!   cancellation of the closed forms.
//! * Radius (§10.4): `|λ|` the largest eigenvalue magnitude of the 2×2 tangent Hessian divided by
//!   `E'` (a relative Hessian, 1/length²), `s` the pixel footprint:
//!   `R_H = (4·HESSIAN_ERROR·s²/|λ|)^{1/4}` (the smaller ellipse radius; `IC_FAR` when `λ = 0`).
//!
//! The per-cell functions are what the GPU pass evaluates; [`compute_hessian`] is their sum.

use crate::record::is_valid_sample;
use crate::sampling::{stratum_direction_local, stratum_index, stratum_jitter};
use crate::{luminance_rec709, HESSIAN_ERROR, HESSIAN_SERIES_TAU, IC_FAR};
use glam::{Vec2, Vec3, Vec4};

/// Terms of the series of `φ(τ) = atan(√τ)/√τ` used below `HESSIAN_SERIES_TAU` (the last term
/// is below 1e-8 of the first there).
const SERIES_TERMS: u32 = 13;

/// `(G, G_S, G_SS)` of `G(S, h) = atan2(√S, h)/√S` (§10.3): by the series of `φ` when `h > 0` and
/// `S < HESSIAN_SERIES_TAU·h²`, by the closed forms otherwise; zero when `S + h² = 0` or when
/// `S = 0` and `h <= 0` (the point lies on the edge: singular).
pub fn hessian_angle_terms(s2: f32, h: f32) -> Vec3 {
    let q = s2 + h * h;
    if q <= 0.0 || (s2 <= 0.0 && h <= 0.0) {
        return Vec3::ZERO;
    }
    if h > 0.0 && s2 < HESSIAN_SERIES_TAU * h * h {
        let tau = s2 / (h * h);
        let (mut p0, mut p1, mut p2) = (0.0f32, 0.0f32, 0.0f32);
        for i in 0..SERIES_TERMS {
            let k = (SERIES_TERMS - 1 - i) as f32;
            let sign = if (SERIES_TERMS - 1 - i).is_multiple_of(2) {
                1.0
            } else {
                -1.0
            };
            let c = sign / (2.0 * k + 1.0);
            p0 = p0 * tau + c;
            // φ' and φ'': the coefficients of τ^(k−1) and τ^(k−2).
            if k >= 1.0 {
                p1 = p1 * tau + c * k;
            }
            if k >= 2.0 {
                p2 = p2 * tau + c * k * (k - 1.0);
            }
        }
        let h2 = h * h;
        return Vec3::new(p0 / h, p1 / (h2 * h), p2 / (h2 * h2 * h));
    }
    let s = s2.sqrt();
    let gamma = s.atan2(h);
    let g = gamma / s;
    let g_s = h / (2.0 * s2 * q) - gamma / (2.0 * s2 * s);
    let g_ss =
        -3.0 * h / (4.0 * s2 * s2 * q) - h / (2.0 * s2 * q * q) + 3.0 * gamma / (4.0 * s2 * s2 * s);
    Vec3::new(g, g_s, g_ss)
}

/// Distance of a vertex for the farthest-vertex rule: `|p|` for a point, `IC_FAR` for a direction.
pub fn hessian_vertex_distance(v: Vec4) -> f32 {
    if v.w > 0.0 {
        v.truncate().length().min(IC_FAR)
    } else {
        IC_FAR
    }
}

/// The symmetric `u vᵀ + v uᵀ` of two tangent vectors as `(xx, xy, yy)`.
pub fn hessian_outer(u: Vec2, v: Vec2) -> Vec3 {
    Vec3::new(2.0 * u.x * v.x, u.x * v.y + u.y * v.x, 2.0 * u.y * v.y)
}

/// The edge term `f = ½ γ n·(a×b)/|a×b|` of the directed edge `a → b` and its tangent-plane
/// Hessian with respect to the record's position: `(f, H_tt, H_tb, H_bb)` (§10.3). A point more
/// than 10⁴ times farther than the other is taken as a direction (its contribution is below
/// f32's resolution of the nearer one's). Two directions give `(f, 0, 0, 0)`.
pub fn hessian_edge(a: Vec4, b: Vec4) -> Vec4 {
    let (mut alpha, mut beta) = (f32::from(a.w > 0.0), f32::from(b.w > 0.0));
    let (la, lb) = (a.truncate().length(), b.truncate().length());
    if la <= 0.0 || lb <= 0.0 {
        return Vec4::ZERO;
    }
    if alpha * beta > 0.0 && la > 1.0e4 * lb {
        alpha = 0.0;
    }
    if alpha * beta > 0.0 && lb > 1.0e4 * la {
        beta = 0.0;
    }
    // Points scaled by 1/L (the farther finite one), directions made unit: f is invariant, the
    // Hessian scales by 1/L².
    let scale = (alpha * la).max(beta * lb);
    let inv = if scale > 0.0 { 1.0 / scale } else { 1.0 };
    let av = a.truncate() * if alpha > 0.0 { inv } else { 1.0 / la };
    let bv = b.truncate() * if beta > 0.0 { inv } else { 1.0 / lb };
    let c = av.cross(bv);
    let (s2, h, m) = (c.dot(c), av.dot(bv), c.z);
    let g = hessian_angle_terms(s2, h);
    let f = 0.5 * m * g.x;
    if scale <= 0.0 || (g.x == 0.0 && g.y == 0.0) {
        return Vec4::new(f, 0.0, 0.0, 0.0);
    }
    let q = s2 + h * h;
    let (g_h, g_hh, g_sh) = (-1.0 / q, 2.0 * h / (q * q), 1.0 / (q * q));
    let w = bv * alpha - av * beta;
    let gs = 2.0 * c.cross(w);
    let gs = Vec2::new(gs.x, gs.y);
    let gh = -(bv * alpha + av * beta);
    let gh = Vec2::new(gh.x, gh.y);
    let gm = Vec2::new(-w.y, w.x);
    let w2 = w.dot(w);
    // Symmetric 2×2 as (xx, xy, yy): H_S = 2(|w|²I − wwᵀ), H_h = 2αβI, and the outer products.
    let hs = Vec3::new(
        2.0 * (w2 - w.x * w.x),
        -2.0 * w.x * w.y,
        2.0 * (w2 - w.y * w.y),
    );
    let hh = Vec3::new(1.0, 0.0, 1.0) * (2.0 * alpha * beta);
    let hess = (hs * g.y + hh * g_h) * m
        + hessian_outer(gs, gs) * (0.5 * m * g.z)
        + hessian_outer(gh, gh) * (0.5 * m * g_hh)
        + hessian_outer(gs, gh) * (m * g_sh)
        + hessian_outer(gs, gm) * g.y
        + hessian_outer(gh, gm) * g_h;
    let k = 0.5 * inv * inv;
    Vec4::new(f, hess.x * k, hess.y * k, hess.z * k)
}

/// The vertex of stratum `(j, k)` (§10.1): its jittered direction (seed `seed`, as the gather)
/// times `r` for a valid hit, the direction alone for a miss (`r >= IC_FAR`) or an invalid
/// sample (`r <= r_eps`).
pub fn hessian_vertex(j: u32, k: u32, m: u32, n: u32, seed: u32, r: f32, r_eps: f32) -> Vec4 {
    let (xi, psi) = stratum_jitter(seed, stratum_index(j, k, n));
    let d = stratum_direction_local(j, k, m, n, xi, psi);
    if is_valid_sample(r, r_eps) && r < IC_FAR {
        (d * r).extend(1.0)
    } else {
        d.extend(0.0)
    }
}

/// The horizon vertex below `v` (§10.1): `v` moved down to the tangent plane along its azimuth,
/// keeping its distance (a direction stays a direction); `+t` for a vertex at the pole.
pub fn hessian_horizon_vertex(v: Vec4) -> Vec4 {
    let xy = Vec2::new(v.x, v.y);
    let len = xy.length();
    let dir = if len > 0.0 { xy / len } else { Vec2::X };
    let dist = if v.w > 0.0 {
        v.truncate().length()
    } else {
        1.0
    };
    (dir * dist).extend(0.0).extend(v.w)
}

/// Normalised luminance (§10.2): `0.99·y/mean_y + 0.01`, or 1 when `mean_y <= 0`.
pub fn hessian_luminance(y: f32, mean_y: f32) -> f32 {
    if mean_y > 0.0 {
        0.99 * y.max(0.0) / mean_y + 0.01
    } else {
        1.0
    }
}

/// The luminance of a triangle: that of its farthest vertex (the first of equals) (§10.2).
pub fn hessian_farthest(a: Vec4, y_a: f32, b: Vec4, y_b: f32, c: Vec4, y_c: f32) -> f32 {
    let (da, db, dc) = (
        hessian_vertex_distance(a),
        hessian_vertex_distance(b),
        hessian_vertex_distance(c),
    );
    if da >= db && da >= dc {
        y_a
    } else if db >= dc {
        y_b
    } else {
        y_c
    }
}

/// One cell of the hemisphere's mesh for [`hessian_cell`] (the GLSL twin's arguments, in order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HessianCell {
    /// Vertex `A = (j, k)`.
    pub a: Vec4,
    /// Vertex `B = (j+1, k)`.
    pub b: Vec4,
    /// Vertex `C = (j+1, k+1)`.
    pub c: Vec4,
    /// Vertex `D = (j, k+1)`.
    pub d: Vec4,
    /// Vertex `(j+1, k−1)`.
    pub bl: Vec4,
    /// Vertex `(j−1, k+1)` (unused when `first`).
    pub au: Vec4,
    /// The luminances of `A, B, C, D`.
    pub y: Vec4,
    /// The luminance at `bl`.
    pub y_bl: f32,
    /// The luminance at `au`.
    pub y_au: f32,
    /// The cap's luminance (for the first row).
    pub y_cap: f32,
    /// The cell is on the first row.
    pub first: bool,
    /// The cell is on the last row.
    pub last: bool,
}

/// The edges cell `(j, k)` owns, weighted (§10.1): the diagonal `B → D` by `Y_lo − Y_hi`, the
/// polar edge `A → B` by `Y_lo − Y_left` (the `T_hi` of cell `(j, k−1)`), the azimuthal edge
/// `A → D` by `Y_above − Y_lo` (`T_hi` of cell `(j−1, k)`, or the cap), and on the last row the
/// horizon edge `B → C` by `Y_hi`. `bl` is vertex `(j+1, k−1)` and `au` vertex `(j−1, k+1)`
/// (unused when `first`); `y` holds the luminances of `A, B, C, D`. Returns the weighted sum of
/// [`hessian_edge`]'s `(f, H_tt, H_tb, H_bb)`.
pub fn hessian_cell(cell: &HessianCell) -> Vec4 {
    let HessianCell {
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
        first,
        last,
    } = *cell;
    let y_lo = hessian_farthest(a, y.x, b, y.y, d, y.w);
    let y_hi = hessian_farthest(b, y.y, c, y.z, d, y.w);
    let y_left = hessian_farthest(bl, y_bl, b, y.y, a, y.x);
    let y_above = if first {
        y_cap
    } else {
        hessian_farthest(a, y.x, d, y.w, au, y_au)
    };
    let mut sum = hessian_edge(b, d) * (y_lo - y_hi)
        + hessian_edge(a, b) * (y_lo - y_left)
        + hessian_edge(a, d) * (y_above - y_lo);
    if last {
        sum += hessian_edge(b, c) * y_hi;
    }
    sum
}

/// The record radius from the summed `(E', H_tt, H_tb, H_bb)` and the pixel footprint (§10.4):
/// `(4·HESSIAN_ERROR·s²/|λ|)^{1/4}` with `|λ| = (|H_tt + H_bb|/2 + sqrt(((H_tt − H_bb)/2)² +
/// H_tb²)) / E'`; `IC_FAR` when `λ = 0` or `E' <= 0`. In `[0, IC_FAR]`.
pub fn hessian_radius(h: Vec4, footprint: f32) -> f32 {
    let mean = 0.5 * (h.y + h.w);
    let half = 0.5 * (h.y - h.w);
    let lambda = mean.abs() + (half * half + h.z * h.z).sqrt();
    // NaN fails both tests too.
    let usable = h.x > 0.0 && lambda > 0.0;
    if !usable {
        return IC_FAR;
    }
    let rel = lambda / h.x;
    let r = (2.0 * footprint.max(0.0) * (HESSIAN_ERROR / rel).sqrt()).sqrt();
    r.min(IC_FAR)
}

/// Sums [`hessian_cell`] over the `M × N` strata (`l[j*N + k]`, `r[j*N + k]`, directions from the
/// jitter of `seed`, local frame): `(E', H_tt, H_tb, H_bb)` (§10.1–§10.3).
///
/// # Panics
/// If `l` or `r` does not hold exactly `m * n` entries (a programming error).
pub fn compute_hessian(l: &[Vec3], r: &[f32], m: u32, n: u32, seed: u32, r_eps: f32) -> Vec4 {
    let count = m as usize * n as usize;
    assert_eq!(l.len(), count, "radiance slice must hold M*N strata");
    assert_eq!(r.len(), count, "distance slice must hold M*N strata");
    if count == 0 {
        return Vec4::ZERO;
    }
    let mean_y = l.iter().map(|&c| luminance_rec709(c)).sum::<f32>() / count as f32;
    // Vertex and luminance of grid point (j, k), j in 0..=M (row M: the horizon), k wrapping.
    let vert = |j: u32, k: u32| {
        let k = k % n;
        let js = j.min(m - 1);
        let i = stratum_index(js, k, n) as usize;
        let v = hessian_vertex(js, k, m, n, seed, r[i], r_eps);
        let y = hessian_luminance(luminance_rec709(l[i]), mean_y);
        (if j >= m { hessian_horizon_vertex(v) } else { v }, y)
    };
    let (mut cap_d, mut y_cap) = (-1.0f32, 1.0f32);
    for k in 0..n {
        let (v, y) = vert(0, k);
        let d = hessian_vertex_distance(v);
        if d > cap_d {
            (cap_d, y_cap) = (d, y);
        }
    }
    let mut sum = Vec4::ZERO;
    for j in 0..m {
        for k in 0..n {
            let (a, ya) = vert(j, k);
            let (b, yb) = vert(j + 1, k);
            let (c, yc) = vert(j + 1, k + 1);
            let (d, yd) = vert(j, k + 1);
            let (bl, y_bl) = vert(j + 1, k + n - 1);
            let (au, y_au) = if j > 0 {
                vert(j - 1, k + 1)
            } else {
                (Vec4::ZERO, 0.0)
            };
            let y = Vec4::new(ya, yb, yc, yd);
            sum += hessian_cell(&HessianCell {
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
                first: j == 0,
                last: j + 1 == m,
            });
        }
    }
    sum
}
