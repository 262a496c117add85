//! Finite-difference checks of the radiance records' coefficient gradients
//! (`radcache_cache::radiance`, docs/radiance-caching.md §7) on the analytic rectangle scenes of
//! tests/common: samples come from ray casting each stratum direction (the production direction
//! code and jitter); the reference is the central difference `(c(x+δ) − c(x−δ))/2δ` along the
//! record's tangents `t` and `b` of coefficients projected from a dense 512×1536 gather (the same
//! projection, 786k rays, its jitter the same at both points).
//!
//! The error is the Frobenius norm over the 16 coefficients × 3 channels × 2 tangents,
//! `‖G − G_fd‖/‖G_fd‖`. Like the irradiance's translational gradient (tests/gradients.rs) the
//! estimator is first order in the stratum size `h(M, N) = max(asin(1/√M), 2π/N)`, and the same
//! bounds hold: mean over 8 jitter seeds `<= 1.6·h`, each seed `<= 2.4·h`; the 64×192 mean must
//! be below the 16×48 one.

mod common;

use common::{Rect, Scene};
use glam::{DVec3, Vec3};
use radcache_cache::radiance::{compute_radiance, RadianceEstimate};
use radcache_cache::sampling::{
    basis_from_normal, frame_to_world, normalize_or_z, stratum_direction_local, stratum_index,
    stratum_jitter,
};

const SEEDS: u32 = 8;

fn h_max(m: u32, n: u32) -> f64 {
    (1.0 / (m as f64).sqrt())
        .asin()
        .max(std::f64::consts::TAU / n as f64)
}

/// Closed room `[−2, 2]² × [0, 3]` with walls of six different radiances (so every band of the
/// incoming radiance varies across the room).
fn coloured_room() -> Scene {
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let e = [
        DVec3::new(1.0, 0.6, 0.3),
        DVec3::new(0.1, 0.5, 0.2),
        DVec3::new(0.3, 0.3, 0.9),
        DVec3::new(0.6, 0.6, 0.6),
        DVec3::new(2.0, 2.0, 1.5),
        DVec3::new(0.05, 0.05, 0.05),
    ];
    let rects = vec![
        Rect::new(DVec3::new(2.0, -2.0, 0.0), y * 4.0, z * 3.0, e[0]),
        Rect::new(DVec3::new(-2.0, -2.0, 0.0), y * 4.0, z * 3.0, e[1]),
        Rect::new(DVec3::new(-2.0, 2.0, 0.0), x * 4.0, z * 3.0, e[2]),
        Rect::new(DVec3::new(-2.0, -2.0, 0.0), x * 4.0, z * 3.0, e[3]),
        Rect::new(DVec3::new(-2.0, -2.0, 3.0), x * 4.0, y * 4.0, e[4]),
        Rect::new(DVec3::new(-2.0, -2.0, 0.0), x * 4.0, y * 4.0, e[5]),
    ];
    Scene {
        rects,
        sky: DVec3::ZERO,
    }
}

/// The coloured room with a small bright panel hanging in it (a sharp radiance edge close by).
fn room_with_panel() -> Scene {
    let mut s = coloured_room();
    s.rects.push(Rect::new(
        DVec3::new(0.2, -0.5, 0.8),
        DVec3::Y * 0.8,
        DVec3::new(0.3, 0.0, 0.4),
        DVec3::new(4.0, 3.0, 1.0),
    ));
    s
}

/// The record of `M × N` strata at `(p, n)` with jitter `seed`.
fn radiance(scene: &Scene, p: DVec3, n: Vec3, m: u32, nn: u32, seed: u32) -> RadianceEstimate {
    let nrm = normalize_or_z(n);
    let (t, b) = basis_from_normal(nrm);
    let count = (m * nn) as usize;
    let (mut l, mut r, mut dirs) = (vec![Vec3::ZERO; count], vec![0.0; count], vec![]);
    dirs.resize(count, Vec3::ZERO);
    for j in 0..m {
        for k in 0..nn {
            let i = stratum_index(j, k, nn);
            let (xi, psi) = stratum_jitter(seed, i);
            let w = frame_to_world(stratum_direction_local(j, k, m, nn, xi, psi), t, b, nrm);
            let (li, ri) = scene.trace(p, w.as_dvec3().normalize());
            let i = i as usize;
            l[i] = li.as_vec3();
            r[i] = ri as f32;
            dirs[i] = w;
        }
    }
    compute_radiance(&l, &r, &dirs, m, nn, n, 1e-6)
}

/// `G[tangent][coefficient][channel]` as one flat vector.
fn flat(g: impl Fn(usize, usize, usize) -> f64) -> Vec<f64> {
    let mut out = Vec::new();
    for a in 0..2 {
        for i in 0..16 {
            for c in 0..3 {
                out.push(g(a, i, c));
            }
        }
    }
    out
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// (mean, max) relative error over the seeds of the gradients at `(p, n)`.
fn gradient_errors(scene: &Scene, p: Vec3, n: Vec3, m: u32, nn: u32, fd: &[f64]) -> (f64, f64) {
    let (t, b) = basis_from_normal(normalize_or_z(n));
    let (mut mean, mut max) = (0.0, 0.0f64);
    for seed in 0..SEEDS {
        let rec = radiance(scene, p.as_dvec3(), n, m, nn, seed);
        let est = flat(|a, i, c| {
            let axis = if a == 0 { t } else { b };
            let g = Vec3::new(rec.grad[0][i][c], rec.grad[1][i][c], rec.grad[2][i][c]);
            f64::from(g.dot(axis))
        });
        let diff: Vec<f64> = est.iter().zip(fd).map(|(e, f)| e - f).collect();
        let e = norm(&diff) / norm(fd);
        mean += e / f64::from(SEEDS);
        max = max.max(e);
    }
    (mean, max)
}

fn check(name: &str, scene: &Scene, p: Vec3, n: Vec3) {
    let (t, b) = basis_from_normal(normalize_or_z(n));
    let d = 0.01;
    let (dm, dn, seed) = (512, 1536, 7);
    let at =
        |axis: Vec3, s: f64| radiance(scene, p.as_dvec3() + axis.as_dvec3() * s, n, dm, dn, seed);
    let (tp, tm, bp, bm) = (at(t, d), at(t, -d), at(b, d), at(b, -d));
    let fd = flat(|a, i, c| {
        let (plus, minus) = if a == 0 { (&tp, &tm) } else { (&bp, &bm) };
        f64::from(plus.coeffs[i][c] - minus.coeffs[i][c]) / (2.0 * d)
    });
    assert!(
        norm(&fd) > 1e-2,
        "{name}: the scene must have non-trivial gradients"
    );
    let mut means = Vec::new();
    for (m, nn) in [(16, 48), (32, 96), (64, 192)] {
        let h = h_max(m, nn);
        let (mean, max) = gradient_errors(scene, p, n, m, nn, &fd);
        println!("{name:<28} {m:>2}x{nn:<3} h={h:.3}  mean {mean:.3} max {max:.3}");
        assert!(
            mean <= 1.6 * h && max <= 2.4 * h,
            "{name} {m}x{nn}: coefficient gradients err by {mean:.3} (mean), {max:.3} (max)"
        );
        means.push(mean);
    }
    assert!(means[2] < means[0], "{name}: errors must shrink with M×N");
}

#[test]
fn floor_record_in_a_coloured_room() {
    check(
        "floor, coloured room",
        &coloured_room(),
        Vec3::new(-0.7, 0.4, 0.0),
        Vec3::Z,
    );
}

#[test]
fn floor_record_near_a_wall() {
    check(
        "floor near the +x wall",
        &coloured_room(),
        Vec3::new(1.5, 0.3, 0.0),
        Vec3::Z,
    );
}

#[test]
fn tilted_record_under_a_bright_panel() {
    let n = Vec3::new(0.35, -0.3, 1.0).normalize();
    check(
        "tilted, under a panel",
        &room_with_panel(),
        Vec3::new(0.3, 0.1, 0.2),
        n,
    );
}

#[test]
fn wall_record_facing_the_room() {
    check(
        "on the +x wall",
        &room_with_panel(),
        Vec3::new(2.0, 0.3, 1.0),
        -Vec3::X,
    );
}
