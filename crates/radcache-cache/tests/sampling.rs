//! Tests of the hemisphere sampling (docs/irradiance-cache.md §2.1, §2.2, §7.3): orthonormal basis,
//! stratum directions, coverage of the hemisphere, cosine pdf, deterministic jitter, tan weights.

use glam::Vec3;
use radcache_cache::sampling::*;
use std::f32::consts::{FRAC_PI_2, PI};

fn rand_unit(h: u32) -> f32 {
    unit_float_from_bits(ircache_hash(h))
}

fn rand_dir(i: u32) -> Vec3 {
    let z = 2.0 * rand_unit(3 * i) - 1.0;
    let phi = 2.0 * PI * rand_unit(3 * i + 1);
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

fn assert_frame(n: Vec3, t: Vec3, b: Vec3, tol: f32) {
    assert!((t.length() - 1.0).abs() < tol, "|t| for n = {n}");
    assert!((b.length() - 1.0).abs() < tol, "|b| for n = {n}");
    assert!(
        t.dot(b).abs() < tol && t.dot(n).abs() < tol && b.dot(n).abs() < tol,
        "orthogonality for n = {n}"
    );
    assert!(
        (t.cross(b) - n).length() < tol,
        "right-handed t x b = n for n = {n}"
    );
}

#[test]
fn basis_is_orthonormal_and_right_handed() {
    let mut normals = vec![Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y];
    normals.push(Vec3::new(1e-7, 0.0, -1.0).normalize());
    normals.push(Vec3::new(0.0, 1e-7, -1.0).normalize());
    normals.push(Vec3::new(1.0, 1.0, -1e-6).normalize());
    normals.push(Vec3::new(0.0, 0.0, -0.0) + Vec3::new(0.6, -0.8, 0.0));
    normals.extend((0..20_000).map(rand_dir));
    for n in normals {
        let (t, b) = basis_from_normal(n);
        assert_frame(n, t, b, 2e-5);
    }
}

#[test]
fn basis_normalises_and_falls_back_on_degenerate_normals() {
    let (t, b) = basis_from_normal(Vec3::new(0.0, 0.0, 7.0));
    assert_frame(Vec3::Z, t, b, 1e-6);
    for bad in [
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::INFINITY, 0.0, 0.0),
        Vec3::splat(1e-20),
    ] {
        assert_eq!(normalize_or_z(bad), Vec3::Z);
        let (t, b) = basis_from_normal(bad);
        assert_frame(Vec3::Z, t, b, 1e-6);
    }
}

#[test]
fn stratum_directions_are_unit_and_inside_their_stratum() {
    for (m, n) in [(1, 3), (8, 24), (16, 48), (13, 41)] {
        for j in 0..m {
            for k in 0..n {
                let idx = stratum_index(j, k, n);
                let (xi, psi) = stratum_jitter(12_345, idx);
                for (x, y) in [(xi, psi), (0.0, 0.0), (0.5, 0.5), (0.999_999, 0.999_999)] {
                    let w = stratum_direction_local(j, k, m, n, x, y);
                    assert!((w.length() - 1.0).abs() < 1e-5);
                    assert!(w.z >= 0.0);
                    assert!(
                        stratum_contains(w, j, k, m, n, 1e-5),
                        "({j},{k}) of {m}x{n}, jitter ({x},{y}) -> {w}"
                    );
                }
            }
        }
    }
}

#[test]
fn strata_partition_the_hemisphere() {
    // Projected solid angles add up to π, and every direction of the upper hemisphere maps to
    // exactly one stratum whose (jittered) direction reproduces it (round trip, pbrt-style).
    let (m, n) = STRATA_DEFAULT;
    assert!((stratum_projected_solid_angle(m, n) * (m * n) as f32 - PI).abs() < 1e-5);
    for i in 0..20_000 {
        let mut w = rand_dir(i);
        w.z = w.z.abs();
        let u = (w.x * w.x + w.y * w.y).min(1.0) * m as f32;
        let mut a = w.y.atan2(w.x) / (2.0 * PI);
        if a < 0.0 {
            a += 1.0;
        }
        let v = a * n as f32;
        let (j, k) = ((u as u32).min(m - 1), (v as u32).min(n - 1));
        let hits = (0..m)
            .flat_map(|jj| (0..n).map(move |kk| (jj, kk)))
            .filter(|&(jj, kk)| stratum_contains(w, jj, kk, m, n, 0.0))
            .count();
        assert!(hits >= 1, "direction {w} in no stratum");
        let back = stratum_direction_local(j, k, m, n, u - j as f32, v - k as f32);
        assert!(
            (back - w).length() < 1e-3,
            "round trip {w} -> ({j},{k}) -> {back}"
        );
    }
}

#[test]
fn strata_sample_the_cosine_pdf() {
    // Under p(ω) = cosθ/π: E[cosθ] = 2/3, E[cos²θ] = 1/2, E[sinθ cosφ] = 0.
    let (m, n) = (64, 192);
    let (mut c1, mut c2, mut sx) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..m {
        for k in 0..n {
            let (xi, psi) = stratum_jitter(7, stratum_index(j, k, n));
            let w = stratum_direction_local(j, k, m, n, xi, psi);
            c1 += w.z as f64;
            c2 += (w.z * w.z) as f64;
            sx += w.x as f64;
        }
    }
    let cnt = (m * n) as f64;
    assert!(
        (c1 / cnt - 2.0 / 3.0).abs() < 1e-3,
        "mean cos = {}",
        c1 / cnt
    );
    assert!((c2 / cnt - 0.5).abs() < 1e-3, "mean cos² = {}", c2 / cnt);
    assert!((sx / cnt).abs() < 1e-3);
}

#[test]
fn jitter_is_deterministic_and_uniform() {
    assert_eq!(stratum_jitter(5, 77), stratum_jitter(5, 77));
    assert_ne!(stratum_jitter(5, 77), stratum_jitter(6, 77));
    let (mut sum, mut lo, mut hi) = (0.0f64, 1.0f32, 0.0f32);
    for i in 0..100_000 {
        let (x, y) = stratum_jitter(i / 768, i % 768);
        for v in [x, y] {
            assert!((0.0..1.0).contains(&v));
            sum += v as f64;
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    assert!((sum / 200_000.0 - 0.5).abs() < 5e-3);
    assert!(lo < 1e-3 && hi > 0.999);
}

#[test]
fn azimuths_are_wrapped_to_minus_pi_pi() {
    for k in 0..48 {
        for phi in [stratum_phi_centre(k, 48), stratum_phi_start(k, 48)] {
            assert!((-PI..=PI).contains(&phi));
        }
        let u = horizontal_u(stratum_phi_centre(k, 48));
        let v = horizontal_v(stratum_phi_centre(k, 48));
        assert!(
            u.dot(v).abs() < 1e-6 && (u.cross(v) - Vec3::Z).length() < 1e-6,
            "u x v = n"
        );
    }
}

#[test]
fn tan_weights() {
    // Row mean of tanθ: matches a fine numerical integral, is finite on the horizon row, and sums
    // to M·∫₀¹ sqrt(u/(1−u)) du = M·π/2.
    for m in [1u32, 2, 8, 16, 64] {
        let mut total = 0.0f64;
        for j in 0..m {
            let mean = stratum_tan_mean(j, m);
            assert!(mean.is_finite() && mean > 0.0);
            let steps = 200_000;
            let (a, b) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
            let num: f64 = (0..steps)
                .map(|s| {
                    let u = a + (b - a) * (s as f64 + 0.5) / steps as f64;
                    (u / (1.0 - u)).sqrt()
                })
                .sum::<f64>()
                / steps as f64;
            let tol = if j + 1 == m { 2e-2 } else { 1e-4 }; // midpoint rule is poor at the singularity
            assert!(
                ((mean as f64) - num).abs() <= tol * num,
                "M={m} j={j}: {mean} vs {num}"
            );
            if j + 1 == m && m >= 16 {
                // §3.1's centre value underestimates the horizon row by ≈ 1/√2 (the bias the
                // row mean removes, see record.rs).
                let ratio = stratum_tan_centre(j, m) / mean;
                assert!(
                    (ratio - std::f32::consts::FRAC_1_SQRT_2).abs() < 0.01,
                    "M={m}: {ratio}"
                );
            }
            total += mean as f64;
        }
        assert!(
            (total / m as f64 - FRAC_PI_2 as f64).abs() < 1e-5,
            "M={m}: {}",
            total / m as f64
        );
    }
}
