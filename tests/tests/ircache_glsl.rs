//! The GLSL twin of radcache-cache (`shaders/common/ircache_math.glsl`) evaluated ON LAVAPIPE
//! against the Rust functions over tables of inputs (random rows plus edge rows: zero radii,
//! grazing, perpendicular and opposite normals, misses at and beyond `IC_FAR`, zero irradiance,
//! degenerate normals, an overflowing record). `shaders/tests/ircache_twin.comp` evaluates one
//! row per invocation; each family below builds the rows and the expected outputs in the
//! shader's output layout (see the shader for the slots).
//!
//! Tolerance: `|gpu − cpu| <= 1e-5 · max(|cpu|, scale) + 1e-6`, where `scale` is the magnitude of
//! the terms a result is summed from (cancellation: gradients, extrapolation, T&L weights, and
//! the pole row's `stratum_tan_mean`, a difference of two `O(M·θ)` terms through GPU `atan`,
//! which Vulkan allows 4096 ULP), so the bound is relative to what f32 can resolve there.
//! Booleans, hashes, indices and jitters (exact integer arithmetic) must match exactly. A boolean
//! or a step (Ward's threshold, the lifespan's cap) whose CPU margin is within rounding of its
//! threshold (a random row on a tie) is not compared; such ties are counted and must stay rare.

use glam::Vec3;
use radcache_cache::extrapolate::{clamp_extrapolation, extrapolate_irradiance};
use radcache_cache::radiance::*;
use radcache_cache::radius::*;
use radcache_cache::record::*;
use radcache_cache::sampling::*;
use radcache_cache::temporal::*;
use radcache_cache::weight::*;
use radcache_cache::{falloff_strata, luminance_rec709, IC_FAR};
use radcache_tests::twin::{
    check, twin_pipeline, ub, unit, v4, vec, Case, Expect, How, Row, TwinMode,
};
use radcache_tests::{context, finish, Rng};

/// Mode 0: sampling, stratum coefficients and the frame.
fn sampling(rng: &mut Rng) -> Vec<Case> {
    let grazing = Vec3::new(1.0, 0.0, 1e-4);
    let (tiny, far) = (Vec3::X * 1e-16, Vec3::new(3.0, -4.0, 0.0));
    let edge_normals = [Vec3::Z, -Vec3::Z, Vec3::ZERO, tiny, grazing, -Vec3::Y, far];
    let mut cases = Vec::new();
    for i in 0..400u32 {
        let m = if i % 7 == 0 { 1 } else { 1 + rng.below(24) };
        let n = 3 + rng.below(70);
        let (j, k) = match i % 5 {
            0 => (m - 1, n - 1),
            1 => (0, 0),
            _ => (rng.below(m), rng.below(n)),
        };
        let (xi, psi) = match i % 11 {
            0 => (0.0, 0.0),
            1 => (1.0, 1.0),
            2 => (0.999_999_9, 0.5),
            _ => (rng.f32(), rng.f32()),
        };
        let normal = edge_normals.get(i as usize).copied();
        let normal = normal.unwrap_or_else(|| unit(rng) * rng.range(0.5, 2.0));
        let (seed, index, u) = (rng.below(u32::MAX), rng.below(4096), rng.f32());
        let (h, bits) = (rng.below(u32::MAX), rng.below(u32::MAX));
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = [ub(j), ub(k), ub(m), ub(n)];
        row[1] = [xi, psi, ub(seed), ub(index)];
        row[2] = v4(normal, 0.0);
        // Hit distances: a hit, IC_FAR itself (a miss), beyond it, and random ones.
        let r = match i % 4 {
            0 => IC_FAR,
            1 => IC_FAR * 2.0,
            _ => rng.range(0.0, 10.0),
        };
        row[3] = [u, ub(h), ub(bits), r];
        let mut e = Expect::new();
        let d = stratum_direction_local(j, k, m, n, xi, psi);
        e.v(0, d, 1.0);
        let (jx, jy) = stratum_jitter(seed, index);
        let (hash, unit) = (ub(ircache_hash(h)), unit_float_from_bits(bits));
        e.s(1, [jx, jy, hash, unit], 0.0);
        e.how[1] = [How::Exact; 4];
        let (t, b) = basis_from_normal(normal);
        let nn = normalize_or_z(normal);
        e.v(2, t, 1.0);
        e.v(3, b, 1.0);
        e.v(4, nn, 1.0);
        let tan_scale = m as f32 * ((j.min(m - 1) + 1) as f32 / m as f32).sqrt().asin();
        let sa = stratum_projected_solid_angle(m, n);
        e.v(5, rotational_gradient_coeff(j, k, m, n), sa * tan_scale);
        let pw = polar_wall_coeff(j, k, m, n);
        e.v(6, pw, pw.length());
        let aw = azimuthal_wall_coeff(j, k, m, n);
        e.v(7, aw, aw.length());
        e.s(8, [0.0, stratum_tan_centre(j, m), 0.0, sa], 0.0);
        e.f(8, 0, stratum_tan_mean(j, m), tan_scale);
        e.b(8, 2, stratum_elevation_ok(j, m), 0.0, 0.0);
        let (phi_c, phi_s) = (stratum_phi_centre(k, n), stratum_phi_start(k, n));
        e.s(9, [phi_c, phi_s, 0.0, azimuth_from_unit(u)], 0.0);
        e.exact(9, 2, ub(stratum_index(j, k, n)));
        let w = frame_to_world(d, t, b, nn);
        e.v(10, w, 1.0);
        e.v(11, world_to_frame(w, t, b, nn), 1.0);
        e.v(12, horizontal_u(xi * 6.0 - 3.0), 1.0);
        e.v(13, horizontal_v(psi * 6.0 - 3.0), 1.0);
        e.f(0, 3, stratum_solid_angle(j, m, n), 1.0);
        let rs = radiance_sample(normal, r);
        for (slot, c) in [(5, 0), (6, 1), (7, 2)] {
            e.exact(slot, 3, rs[c]);
        }
        let rpw = radiance_polar_wall_coeff(j, k, m, n);
        e.v(14, rpw, rpw.length());
        let raw = radiance_azimuthal_wall_coeff(j, k, m, n);
        e.v(15, raw, raw.length());
        let (fm, fn_) = falloff_strata(1 + h % 1728, 3 + bits % 1726, k % 16);
        e.exact(12, 3, ub(fm));
        e.exact(13, 3, ub(fn_));
        cases.push((row, e));
    }
    cases
}

/// Mode 1: weights and their tests.
fn weights(rng: &mut Rng) -> Vec<Case> {
    let (y, o) = (Vec3::Y, Vec3::ZERO);
    let behind = Vec3::new(0.3, -0.5, 0.2);
    let tilted = Vec3::new(1.0, 1e-3, 0.0).normalize();
    // (p, n, p_i, n_i, r_i, a, κ, tol): edge rows first.
    let mut rows = vec![
        (Vec3::ONE, y, Vec3::ONE, y, 0.5, 0.2, 1.0, 0.01), // p = p_i, n = n_i: Ward's cap
        (o, -y, o, y, 1.0, 0.2, 1.0, 0.0),                 // opposite normals
        (o, Vec3::X, o, y, 1.0, 0.2, 1.0, 0.0),            // perpendicular (n·n_i = 0)
        (Vec3::X * 0.1, y, o, y, 0.0, 0.2, 1.0, 0.0),      // zero radius
        (Vec3::X * 0.1, y, o, y, 1.0, 0.0, 0.0, 0.0),      // a = κ = 0
        (behind, y, o, y, 2.0, 0.5, 1.0, 0.5),             // in front, exactly at the tolerance
        (behind, y, o, y, 2.0, 0.5, 1.0, -0.4),            // behind, negative tolerance
        (Vec3::X * 0.1, tilted, o, y, 1.0, 0.3, 1.0, 0.0), // grazing normal
        (Vec3::X * 1e3, y, o, y, IC_FAR, 0.2, 1.0, 0.0),   // radius IC_FAR
    ];
    for _ in 0..500 {
        let (n_i, r_i, p_i) = (unit(rng), rng.range(0.01, 2.0), vec(rng, 5.0));
        let p = p_i + vec(rng, 1.0).normalize_or_zero() * r_i * rng.range(0.0, 1.5);
        let tilt = rng.range(0.0, 1.2);
        let n = (n_i + vec(rng, tilt)).normalize_or(n_i);
        let (a, kappa) = (rng.range(0.05, 0.5), rng.range(0.5, 2.0));
        let tol = rng.range(0.0, 0.05);
        rows.push((p, n, p_i, n_i, r_i, a, kappa, tol));
    }
    let (ward, tl) = (WeightKind::Ward, WeightKind::TabellionLamorlette);
    let mut cases = Vec::new();
    for (p, n, p_i, n_i, r_i, a, kappa, tol) in rows {
        let mut row: Row = [[0.0; 4]; 16];
        row[..4].copy_from_slice(&[v4(p, 0.0), v4(n, 0.0), v4(p_i, 0.0), v4(n_i, 0.0)]);
        row[4] = [r_i, a, kappa, tol];
        row[5] = [0.05, 0.5, 0.0, 0.0];
        let mut e = Expect::new();
        let eps = position_error(p, p_i, n_i, r_i) + normal_error(n, n_i);
        let front = (p - p_i).dot(n_i) + tol.max(0.0);
        let facing = n.dot(n_i);
        e.f(0, 0, ward_weight(p, n, p_i, n_i, r_i, a, tol), 0.0);
        e.f(0, 1, tl_weight(p, n, p_i, n_i, r_i, kappa, tol), 1.0);
        let record = WeightRecord {
            p: p_i,
            n: n_i,
            r: r_i,
        };
        e.f(0, 2, record_weight(ward, p, n, record, a, tol), 0.0);
        let w_tl = record_weight(tl, p, n, record, kappa, tol);
        e.f(0, 3, w_tl, 1.0);
        // Ward's weight steps at ε = a and wherever a test flips: ties are not compared.
        let ward_tie = (eps - a).abs() <= 1e-5 * a || front.abs() <= 1e-5 || facing.abs() <= 1e-6;
        if ward_tie && front != 0.0 && facing != 0.0 {
            e.how[0][0] = How::Tie;
            e.how[0][2] = How::Tie;
        }
        e.b(1, 0, normal_test(n, n_i), facing, 1e-6);
        e.b(1, 1, in_front_test(p, p_i, n_i, tol), front, 1e-5);
        e.f(1, 2, normal_error(n, n_i), 1.0);
        e.f(1, 3, position_error(p, p_i, n_i, r_i), 0.0);
        let sw = splat_radius(ward, r_i, a, 0.05);
        let st = splat_radius(tl, r_i, kappa, 0.05);
        let (vw, vt) = (validity_scale(ward, a), validity_scale(tl, kappa));
        e.s(2, [vw, vt, sw, st], 0.0);
        let cw = coverage_threshold(ward, a, 0.5);
        let ct = coverage_threshold(tl, kappa, 0.5);
        let (uw, ut) = (weight_unit(ward, a), weight_unit(tl, kappa));
        e.s(3, [uw, ut, cw, ct], 0.0);
        cases.push((row, e));
    }
    cases
}

/// Mode 2: extrapolation with gradients and its clamp.
fn extrapolation(rng: &mut Rng) -> Vec<Case> {
    let mut cases = Vec::new();
    for i in 0..300 {
        let e_i = match i {
            0 => Vec3::ZERO,
            1 => Vec3::new(0.0, 1.0, 2.0),
            _ => vec(rng, 5.0).abs(),
        };
        let g: Vec<Vec3> = (0..6).map(|_| vec(rng, 8.0) * f32::from(i != 2)).collect();
        let (gr, gt) = ([g[0], g[1], g[2]], [g[3], g[4], g[5]]);
        let (p_i, n_i) = (vec(rng, 3.0), unit(rng));
        let n = (n_i + vec(rng, 0.4)).normalize_or(n_i);
        let n = if i == 3 { -n_i } else { n };
        let (p, x) = (p_i + vec(rng, 0.5), vec(rng, 25.0));
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = v4(e_i, 0.0);
        for (slot, v) in g.iter().enumerate() {
            row[1 + slot] = v4(*v, 0.0);
        }
        row[7..12].copy_from_slice(&[p, n, p_i, n_i, x].map(|v| v4(v, 0.0)));
        let mut e = Expect::new();
        // The sum's terms: E + |n_i × n|·|∇_r| + |Δp|·|∇_t| (largest channel).
        let terms = (0..3)
            .map(|c| n_i.cross(n).length() * gr[c].length() + (p - p_i).length() * gt[c].length())
            .fold(e_i.max_element(), f32::max);
        let x_e = extrapolate_irradiance(e_i, &gr, &gt, p, n, p_i, n_i);
        e.v(0, x_e, terms);
        e.v(1, clamp_extrapolation(x, e_i), 0.0);
        cases.push((row, e));
    }
    cases
}

/// Mode 3: radius post-processing, bounds, neighbour clamps and footprints.
fn radius(rng: &mut Rng) -> Vec<Case> {
    let pick = |rng: &mut Rng, k: u32| match k {
        0 => 0.0,
        1 => IC_FAR,
        2 => 2.0 * IC_FAR,
        3 => -1.0,
        4 => 1e-6,
        _ => rng.range(1e-3, 10.0),
    };
    let mut cases = Vec::new();
    for i in 0..300u32 {
        let (r, r_nb) = (pick(rng, i % 9), pick(rng, (i / 9) % 9));
        let (r_lo, r_hi) = (pick(rng, (i / 3) % 11), pick(rng, (i / 5) % 13));
        let e_i = vec(rng, 4.0).abs() * f32::from(i % 4 != 0);
        let gt = [0; 3].map(|_| vec(rng, 3.0) * f32::from(i % 6 != 0));
        let fp = rng.range(1e-4, 0.1) * f32::from(i % 10 != 0);
        let (px, v_scale) = ([rng.range(0.5, 4.0), rng.range(4.0, 40.0)], rng.f32());
        let bounds = [fp, px[0], px[1], v_scale];
        let (r_j, d_ij) = (pick(rng, i % 7), rng.range(0.0, 3.0));
        let cos_view = rng.range(-1.0, 1.0) * f32::from(i % 8 != 0);
        let (depth, tan) = (rng.range(0.1, 50.0), rng.range(0.1, 2.0));
        let pinhole = [depth, tan, 64.0 + i as f32, cos_view];
        let (dpdx, dpdy) = (vec(rng, 0.01), vec(rng, 0.01));
        let (p_i, p_j) = (vec(rng, 2.0), vec(rng, 2.0));
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = [r, r_nb, r_lo, r_hi];
        row[1] = v4(e_i, 0.0);
        row[2..5].copy_from_slice(&gt.map(|g| v4(g, 0.0)));
        row[5] = bounds;
        row[6] = [r_j, d_ij, 0.0, 0.0];
        row[7] = pinhole;
        row[8..12].copy_from_slice(&[dpdx, dpdy, p_i, p_j].map(|v| v4(v, 0.0)));
        let mut e = Expect::new();
        let fin = finalize_radius(r, e_i, &gt, r_nb, r_lo, r_hi);
        e.s(0, [fin.r_orig, fin.r_used, fin.r_lo, fin.r_hi], 0.0);
        let (clamped, limited) = (
            clamp_radius(r, r_lo, r_hi),
            gradient_limit_radius(r, e_i, &gt),
        );
        let att = gradient_attenuation(r, r_lo);
        e.s(1, [fin.grad_t_scale, clamped, limited, att], 0.0);
        let (lo, hi) = radius_bounds(fp, px[0], px[1], v_scale);
        let (sane, nb) = (sanitize_radius(r), neighbour_clamp(r, r_j, d_ij));
        e.s(2, [lo, hi, sane, nb], 0.0);
        let s_pin = pixel_footprint(depth, tan, 64.0 + i as f32, cos_view);
        let s_diff = pixel_footprint_from_differentials(dpdx, dpdy);
        let (ri, rj) = neighbour_clamp_pair(r, p_i, r_j, p_j);
        e.s(3, [s_pin, s_diff, ri, rj], 0.0);
        let glossy = glossy_gradient_limit_from_sums(e_i, gt[0]);
        e.s(4, [glossy, 0.0, 0.0, 0.0], 0.0);
        cases.push((row, e));
    }
    cases
}

/// Largest gradient-term sums of a sample set (rotational, translational): the scale of the
/// cancellation in the gradient sums.
fn gradient_scales(l: &[Vec3], r: &[f32], m: u32, n: u32, r_eps: f32) -> (f32, f32) {
    let (mut rot, mut trans) = (0.0f32, 0.0f32);
    for j in 0..m {
        let tan_scale = m as f32 * ((j + 1) as f32 / m as f32).sqrt().asin();
        for k in 0..n {
            let i = stratum_index(j, k, n) as usize;
            rot += stratum_projected_solid_angle(m, n) * tan_scale * l[i].max_element();
            let wall = |p: usize| wall_term(l[i], l[p], r[i], r[p], r_eps).abs().max_element();
            let kp = stratum_index(j, if k == 0 { n - 1 } else { k - 1 }, n) as usize;
            trans += azimuthal_wall_coeff(j, k, m, n).length() * wall(kp);
            if j > 0 {
                let jp = stratum_index(j - 1, k, n) as usize;
                trans += polar_wall_coeff(j, k, m, n).length() * wall(jp);
            }
        }
    }
    (rot, trans)
}

/// Mode 4: compute_record over sample sets; returns the cases and the samples buffer.
fn records(rng: &mut Rng) -> (Vec<Case>, Vec<[f32; 4]>) {
    let r_eps = 1e-4;
    // (m, n, normal, L kind, r kind)
    let sets = [
        (4, 12, Vec3::new(0.3, 0.8, -0.5), 0, 0), // random L, r with misses and invalid samples
        (4, 12, Vec3::Y, 0, 1),                   // every ray misses
        (4, 12, Vec3::X, 1, 0),                   // E = 0
        (4, 12, -Vec3::Z, 0, 0),                  // the basis's other branch
        (8, 24, Vec3::new(1.0, 0.01, 0.0), 0, 0), // near-grazing normal, bigger set
        (1, 3, Vec3::Z, 0, 0),                    // smallest set
        (4, 12, Vec3::ZERO, 2, 0),                // degenerate normal (+Z), constant L
        (4, 12, Vec3::new(-0.2, 0.1, 0.9), 0, 2), // huge hits and misses beyond IC_FAR
        (4, 12, Vec3::Y, 3, 0),                   // the sum overflows: E not storable
    ];
    let (mut cases, mut samples) = (Vec::new(), Vec::new());
    for (m, n, normal, l_kind, r_kind) in sets {
        let (mut l, mut r) = (Vec::new(), Vec::new());
        for s in 0..m * n {
            l.push(match l_kind {
                0 => vec(rng, 1.0) + Vec3::ONE,
                1 => Vec3::ZERO,
                2 => Vec3::splat(0.75),
                _ => Vec3::splat(1e37),
            });
            r.push(match (r_kind, s % 10) {
                (1, _) | (0, 3) => IC_FAR,
                (0, 7) if s < 10 => r_eps * 0.5,
                (0, 8) if s < 10 => 0.0,
                (2, 2) => 2.0 * IC_FAR,
                (2, 5) => 1e29,
                _ => rng.range(0.05, 3.0),
            });
        }
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = v4(normal, r_eps);
        row[1] = [ub(m), ub(n), ub(samples.len() as u32), 0.0];
        samples.extend(l.iter().zip(&r).map(|(l, r)| v4(*l, *r)));
        let est = compute_record(&l, &r, m, n, normal, r_eps);
        let (rot, trans) = gradient_scales(&l, &r, m, n, r_eps);
        let mut e = Expect::new();
        e.v(0, est.e, 0.0);
        for c in 0..3 {
            e.v(1 + c, est.grad_r[c], rot);
            e.v(4 + c, est.grad_t[c], trans);
        }
        let radii = [est.r_harmonic, est.r_min, est.r_min_restricted, 0.0];
        e.s(7, radii, 0.0);
        e.exact(7, 3, ub(est.valid_samples));
        e.b(8, 0, irradiance_is_valid(est.e), 0.0, 0.0);
        if est.e.is_finite() {
            e.f(8, 1, luminance_rec709(est.e), 0.0);
        }
        // The edge sets do what they are for.
        assert_eq!(irradiance_is_valid(est.e), l_kind != 3);
        assert_eq!(est.r_harmonic == IC_FAR, r_kind == 1);
        assert_eq!(est.valid_samples < m * n, r_kind == 0 && m * n >= 10);
        cases.push((row, e));
    }
    (cases, samples)
}

/// Mode 5: the temporal formulas (lifespan, validity, extrapolation) and the moving cover.
fn temporal(rng: &mut Rng) -> Vec<Case> {
    let mut cases = Vec::new();
    for k in 0..160 {
        let e0 = match k % 8 {
            0 => Vec3::ZERO,
            _ => vec(rng, 1.0) + Vec3::splat(1.2),
        };
        let e1 = match k % 8 {
            1 => e0,
            2 => Vec3::ZERO,
            _ => e0 + vec(rng, 0.3),
        };
        let (a_t, max_age) = (rng.range(0.01, 0.2), rng.range(1.0, 60.0));
        let (age, lifespan) = (rng.range(-2.0, 40.0), rng.range(0.0, 40.0));
        let de = vec(rng, 0.2);
        let (p, n) = (vec(rng, 2.0), unit(rng));
        // Spheres around p: inside, above, across and below its horizon, of radius 0.
        let dir = unit(rng);
        let d = rng.range(0.05, 3.0);
        let r = match k % 5 {
            0 => d * rng.range(1.05, 2.0),
            1 => 0.0,
            _ => d * rng.range(0.01, 0.9),
        };
        let sphere = (p + dir * d).extend(r);
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = v4(e0, 0.0);
        row[1] = v4(e1, 0.0);
        row[2] = [a_t, max_age, age, lifespan];
        row[3] = v4(de, 0.0);
        row[4] = v4(p, 0.0);
        row[5] = v4(n, 0.0);
        row[6] = sphere.to_array();
        let mut e = Expect::new();
        // The lifespan's cap is a step: a row within rounding of it is a tie.
        let (y0, y1) = (luminance_rec709(e0).max(0.0), luminance_rec709(e1).max(0.0));
        let cap_margin = a_t * y0 - max_age * (y1 - y0).abs();
        e.f(0, 0, temporal_lifespan(e0, e1, a_t, max_age), max_age);
        if cap_margin != 0.0 && cap_margin.abs() <= 1e-5 * (a_t * y0).max(1e-6) {
            e.how[0][0] = How::Tie;
        }
        e.b(
            0,
            1,
            temporal_is_valid(age, lifespan),
            age - lifespan,
            1e-6 * 40.0,
        );
        // The cover is continuous except where p is on the sphere (d = r).
        let cover = moving_cover(p, n, sphere);
        e.f(0, 2, cover, 1.0);
        if r > 0.0 && (d - r).abs() <= 1e-5 * d {
            e.how[0][2] = How::Tie;
        }
        e.v(
            1,
            temporal_gradient(e0, e1),
            e0.max_element().max(e1.max_element()),
        );
        e.v(
            2,
            temporal_extrapolate(e0, de, age),
            e0.max_element() + 40.0 * 0.2,
        );
        cases.push((row, e));
    }
    // The kinds of cover the rows hold.
    let covers: Vec<f32> = cases.iter().map(|c| c.1.v[0][2]).collect();
    assert!(covers.contains(&1.0) && covers.contains(&0.0));
    assert!(covers.iter().filter(|&&c| c > 0.0 && c < 1.0).count() > 40);
    cases
}

#[test]
fn glsl_twin_matches_the_rust_formulas_on_the_gpu() {
    let ctx = context();
    let pipeline = twin_pipeline(&ctx, "ircache_twin.comp", "ircache_twin");
    let mut rng = Rng::new(0x1c_2024);
    check(
        &ctx,
        &pipeline,
        TwinMode::Sampling,
        &sampling(&mut rng),
        &[],
    );
    check(&ctx, &pipeline, TwinMode::Weight, &weights(&mut rng), &[]);
    check(
        &ctx,
        &pipeline,
        TwinMode::Extrapolate,
        &extrapolation(&mut rng),
        &[],
    );
    check(&ctx, &pipeline, TwinMode::Radius, &radius(&mut rng), &[]);
    let (cases, samples) = records(&mut rng);
    check(&ctx, &pipeline, TwinMode::Record, &cases, &samples);
    check(
        &ctx,
        &pipeline,
        TwinMode::Temporal,
        &temporal(&mut rng),
        &[],
    );
    drop(pipeline);
    finish(ctx);
}
