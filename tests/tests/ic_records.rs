//! The record pass (`shaders/passes/record.comp`) on lavapipe, on a G-buffer written point by
//! point (`shaders/tests/gbuffer_fill.comp`; positions and normals computed on the CPU), so it
//! does not depend on the raster G-buffer pass.
//!
//! Every record is checked field by field against the CPU twins applied to the samples the pass
//! dumps (`compute_record`, `finalize_radius`, `radius_bounds`), every gather distance against a
//! CPU ray cast along the direction the CPU twin of the sampling predicts (seed, jitter, frame,
//! folding), and the irradiance against an analytic value (furnace) or an independent estimate
//! (Cornell box), within 5 standard errors taken from the per-stratum spread (treating the strata
//! as independent samples, which overestimates the error of a stratified estimate).

use glam::Vec3;
use radcache_cache::radius::finalize_radius;
use radcache_cache::record::*;
use radcache_cache::sampling::*;
use radcache_cache::{IcParams, IC_FAR, R_FLOOR};
use radcache_render::{passes::record::RecordPass, passes::record::RecordVariant, SkyLight};
use radcache_render::{
    passes::record::RECORD_FLAGS_MASK, passes::record::RECORD_FLAG_INVALID_IRRADIANCE,
    passes::record::RECORD_FLAG_NO_SURFACE,
};
use radcache_render::{
    passes::record::RECORD_FLAG_CLAMPED_DOWN, passes::record::RECORD_FLAG_CLAMPED_UP,
    passes::record::RECORD_FLAG_FOLDED,
};
use radcache_scene::Scene;
use radcache_shared::gpu::{GpuRecord, IcCounters};
use radcache_tests::geometry::intersect;
use radcache_tests::ic_fixture::GbufferPoint;
use radcache_tests::record_fixture::*;
use radcache_tests::scenes::{load, temp_dir};
use std::f32::consts::PI;

fn xyz(v: [f32; 4]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

fn close(what: &str, gpu: f32, cpu: f32, scale: f32) {
    let tol = 1e-5 * cpu.abs().max(scale) + 1e-6;
    let msg = format!("{what}: GPU {gpu:e}, CPU {cpu:e} (tolerance {tol:e})");
    assert!((gpu - cpu).abs() <= tol, "{msg}");
}

/// A record's samples (radiance, distance), checked finite, non-negative and in range.
fn split(samples: &[[f32; 4]]) -> (Vec<Vec3>, Vec<f32>) {
    for s in samples {
        assert!(
            s.iter().all(|c| c.is_finite() && *c >= 0.0) && s[3] <= IC_FAR,
            "{s:?}"
        );
    }
    (
        samples.iter().map(|s| xyz(*s)).collect(),
        samples.iter().map(|s| s[3]).collect(),
    )
}

/// Standard error of E per channel, from the spread of the strata's radiance.
fn standard_error(l: &[Vec3]) -> Vec3 {
    let n = l.len() as f32;
    let mean = l.iter().sum::<Vec3>() / n;
    let var = l.iter().map(|v| (*v - mean) * (*v - mean)).sum::<Vec3>() / (n - 1.0);
    (var / n).powf(0.5) * PI
}

/// Sums of the gradient terms' sizes (rotational, translational): the scale of the cancellation
/// in the gradient sums. The pole row's tan-mean is a difference of O(M·θ) terms computed with
/// GPU `atan` (see ircache_glsl.rs), hence `M·θ_j⁺`.
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

/// Checks one record against the CPU twins applied to its samples; returns the CPU estimate.
fn check_record(
    f: &Fixture,
    params: &IcParams,
    q: &GbufferPoint,
    rec: &GpuRecord,
    samples: &[[f32; 4]],
    level: u32,
    sub_frame: u32,
) -> RecordEstimate {
    // The strata of the record's level (the fine strata from `fine_level`; no glossy lobe here).
    let (m, n) = params.strata_at(level, false);
    let samples = &samples[..(m * n) as usize];
    let (l, r) = split(samples);
    let est = compute_record(&l, &r, m, n, q.n, f.r_eps);
    let e = xyz(rec.irradiance);
    let (rot, trans) = gradient_scales(&l, &r, m, n, f.r_eps);
    let gr = [rec.grad_r_red, rec.grad_r_green, rec.grad_r_blue].map(xyz);
    let gt = [rec.grad_t_red, rec.grad_t_green, rec.grad_t_blue].map(xyz);
    for c in 0..3 {
        close("E", e[c], est.e[c], 0.0);
        for a in 0..3 {
            close("grad_r", gr[c][a], est.grad_r[c][a], rot);
            close("grad_t", gt[c][a], est.grad_t[c][a], trans);
        }
    }
    assert_eq!(xyz(rec.position_radius), q.p);
    let normal_error = xyz(rec.normal_rorig).distance(normalize_or_z(q.n));
    close("normal", normal_error, 0.0, 0.0);
    close("R_harm", rec.bounds[3], est.r_harmonic, 0.0);
    let (lo, hi) = params.radius_bounds(q.footprint);
    close("R-", rec.bounds[0], lo, 0.0);
    close("R+", rec.bounds[1], hi, 0.0);
    assert_eq!(rec.bounds[2], q.footprint);
    // finalize_radius (twin-tested) wired with the record's own E and gradients.
    let fin = finalize_radius(est.radius(), e, &gt, IC_FAR, lo, hi);
    let (r_used, r_orig) = (rec.position_radius[3], rec.normal_rorig[3]);
    let att = rec.irradiance[3];
    close("R_orig", r_orig, fin.r_orig, 0.0);
    close("R_used", r_used, fin.r_used, 0.0);
    close("attenuation", att, fin.grad_t_scale, 0.0);
    let (lo, hi) = (rec.bounds[0], rec.bounds[1]);
    assert!(lo <= r_used && r_used <= hi, "{rec:?}");
    assert!(r_used == r_orig.clamp(lo, hi) && r_orig <= est.radius());
    let (up, down) = (r_orig < lo, r_orig > hi);
    assert!((up && r_used > r_orig && att < 1.0) || (!up && att == 1.0));
    assert!(!down || r_orig > r_used);
    let up_flag = if up { RECORD_FLAG_CLAMPED_UP } else { 0 };
    let flags = up_flag | if down { RECORD_FLAG_CLAMPED_DOWN } else { 0 };
    let own_flags = rec.info[3] & RECORD_FLAGS_MASK & !RECORD_FLAG_FOLDED;
    assert_eq!(own_flags, flags, "{rec:?}");
    assert_eq!(rec.info[..3], [point_index(q), level, sub_frame]);
    est
}

/// Compares every gather distance with a CPU ray cast; returns (mismatches, folded directions).
fn check_distances(
    f: &Fixture,
    q: &GbufferPoint,
    p: &IcParams,
    seed: u32,
    s: &[[f32; 4]],
) -> [usize; 2] {
    let (m, n) = (p.strata_m, p.strata_n);
    let (mut bad, mut folded) = (0, 0);
    for (i, s) in s.iter().enumerate() {
        let (d, fold) = direction(q, m, n, seed, i as u32);
        folded += usize::from(fold);
        let (o, d) = (q.p.as_dvec3(), d.as_dvec3());
        let hits = f.tris.iter().filter_map(|tri| intersect(o, d, *tri, 0.0));
        let t = hits.map(|h| h.t).filter(|t| *t > 1e-4).fold(1e30, f64::min);
        let r = (t as f32).min(IC_FAR);
        if !((s[3] >= IC_FAR && r >= IC_FAR) || (s[3] - r).abs() <= 2e-4 + 1e-4 * r) {
            bad += 1;
            eprintln!("stratum {i} of {q:?}: GPU r = {}, CPU r = {r}", s[3]);
        }
    }
    [bad, folded]
}

fn furnace_scene(le: f32) -> Scene {
    let dir = temp_dir(&format!("records-furnace-{le}"));
    load(&radcache_scene::assets::write_furnace(&dir, 0.5, le).unwrap())
}

/// The record pass for `f`'s scene with `params`, the sky through the records.
fn record_pass(f: &Fixture, params: IcParams) -> RecordPass {
    RecordPass::new(
        &f.ctx,
        &f.shaders,
        &f.gpu,
        &RecordVariant::new(params, SkyLight::Records),
    )
    .unwrap()
}

#[test]
fn furnace_records_match_the_analytic_irradiance() {
    let (albedo, le) = (0.5f32, 1.0f32);
    let mut f = fixture(&furnace_scene(le));
    let params = IcParams::draft();
    let pass = record_pass(&f, params);
    let (m, n) = (params.strata_m, params.strata_n);
    // Shading normal tilted off the geometric one: some directions must be folded.
    let tilted = Vec3::new(0.6, 1.0, 0.0).normalize();
    let mut tilted = point(15, 15, Vec3::new(0.2, -1.0, 0.3), tilted);
    tilted.ng = Vec3::Y;
    let points = [
        point(3, 4, Vec3::new(0.0, -1.0, 0.0), Vec3::Y),
        point(20, 7, Vec3::new(1.0, 0.3, -0.2), -Vec3::X),
        point(9, 25, Vec3::new(-0.95, -1.0, -0.95), Vec3::Y),
        point(28, 30, Vec3::new(0.5, 1.0, 0.5), -Vec3::Y),
        tilted,
    ];
    let requests: Vec<u32> = points.iter().map(point_index).collect();
    let (base, seed, level, sub_frame) = (3u32, 17u32, 2u32, 1u32);
    let c = counters(base, 5, 5, 64);
    let out = run(
        &mut f,
        &pass,
        &Batch::new(&points, &requests, c),
        create(seed, level, sub_frame),
    );
    // Radiance leaving every wall is Le/(1−ρ); the direct pass counts the emission Le arriving
    // directly, so a gather ray returns ρ·Le/(1−ρ) and E_ind = π·ρ·Le/(1−ρ).
    let expected = PI * albedo * le / (1.0 - albedo);
    let count = (m * n) as usize;
    for (i, q) in points.iter().enumerate() {
        let rec = &out.records[base as usize + i];
        let s = &out.samples[i * count..(i + 1) * count];
        let est = check_record(&f, &params, q, rec, s, level, sub_frame);
        let (l, r) = split(s);
        let se = standard_error(&l);
        let dev = (est.e - Vec3::splat(expected)) / se;
        eprintln!("furnace point {i}: E {} ({dev} SE from {expected})", est.e);
        assert!(dev.abs().max_element() < 5.0 && se.max_element() < 0.1 * expected);
        // A constant field: the gradients are noise. Their expected size follows from the
        // per-stratum variance and the (linear) coefficients of each L_jk.
        let sigma = se / PI * (count as f32).sqrt();
        let (mut rot2, mut trans2) = (0.0f32, 0.0f32);
        for idx in 0..count {
            let mut impulse = vec![Vec3::ZERO; count];
            impulse[idx] = Vec3::X;
            let g = compute_record(&impulse, &r, m, n, q.n, f.r_eps);
            rot2 += g.grad_r[0].length_squared();
            trans2 += g.grad_t[0].length_squared();
        }
        for c in 0..3 {
            let (gr, gt) = (est.grad_r[c].length(), est.grad_t[c].length());
            let noise = 5.0 * sigma[c] * Vec3::new(rot2.sqrt(), trans2.sqrt(), 0.0);
            assert!(gr <= noise.x && gt <= noise.y, "{gr} {gt} {noise}");
        }
        let [bad, folded] = check_distances(&f, q, &params, seed, s);
        assert!(bad == 0 && (folded > 0) == (i == 4), "{bad} {folded}");
        assert_eq!(rec.info[3] & RECORD_FLAG_FOLDED != 0, folded > 0);
    }
    for slot in (0..base as usize).chain(base as usize + 5..SLOTS) {
        assert_eq!(out.records[slot], sentinel(), "slot {slot} was written");
    }
    assert_eq!(out.counters, c, "the pass changes no counter here");
    assert!(out.rays > 5 * u64::from(m * n), "{} rays", out.rays);
    drop(pass);
    end(f);
}

#[test]
fn invalid_irradiance_background_and_overflow_are_guarded() {
    // Le = 1e36: every sample is finite (≈ 1e36) but their sum over the 12×36 strata overflows.
    let mut f = fixture(&furnace_scene(1e36));
    let params = IcParams::default();
    let pass = record_pass(&f, params);
    let q = point(5, 5, Vec3::new(0.0, -1.0, 0.0), Vec3::Y);
    // Surface (overflows), background pixel, pixel past the image, and one request past the
    // capacity (base 2 + 3 records); one workgroup more than there are requests.
    let requests = [point_index(&q), 10 * W + 10, W * H + 7, point_index(&q)];
    let c = counters(2, 4, 5, 5);
    let out = run(
        &mut f,
        &pass,
        &Batch::new(&[q], &requests, c),
        create(5, 0, 3),
    );
    let (l, r) = split(&out.samples[..params.sample_count() as usize]);
    let est = compute_record(&l, &r, params.strata_m, params.strata_n, q.n, f.r_eps);
    assert!(!irradiance_is_valid(est.e), "the CPU twin rejects it too");
    let no_surface = RECORD_FLAG_NO_SURFACE;
    let flags = [RECORD_FLAG_INVALID_IRRADIANCE, no_surface, no_surface];
    for (i, flag) in flags.into_iter().enumerate() {
        let rec = out.records[2 + i];
        let all: [f32; 44] = bytemuck::cast(rec);
        assert!(all[..40].iter().all(|v| v.is_finite()), "{rec:?}");
        assert_eq!(rec.info, [requests[i], 0, 3, flag]);
        assert_eq!(xyz(rec.irradiance), Vec3::ZERO);
        // A zero normal fails every weight's normal test: it never weighs anything.
        assert_eq!(xyz(rec.normal_rorig), Vec3::ZERO);
        let radii = (rec.normal_rorig[3], rec.bounds[0], rec.bounds[1]);
        assert_eq!(radii, (IC_FAR, R_FLOOR, R_FLOOR));
        assert_eq!(all[16..40], [0.0; 24], "gradients of record {i}");
    }
    assert_eq!(out.records[5], sentinel(), "dropped, yet written");
    let expected = IcCounters {
        dropped_requests: 1,
        rejected_records: 3,
        ..c
    };
    assert_eq!(out.counters, expected, "dropped 1, rejected 3");
    drop(pass);
    end(f);
}

#[test]
fn cornell_records_agree_with_an_independent_estimate() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load(&root.join("../assets/cornell/cornell.gltf"));
    let mut f = fixture(&scene);
    let pixels = [(16, 26), (3, 16), (28, 16), (16, 6), (9, 29), (23, 21)];
    let at = |(x, y)| surface_at_pixel(&f, &scene, x, y);
    let mut points: Vec<GbufferPoint> = pixels.into_iter().map(at).collect();
    // A tiny footprint puts R⁺ below the record's radius: it must be clamped down.
    points[1].footprint = 1e-4;
    let requests: Vec<u32> = points.iter().map(point_index).collect();
    let k = points.len() as u32;
    let (draft, fine) = (IcParams::draft(), IcParams::default());
    let pass_a = record_pass(&f, draft);
    let pass_b = record_pass(&f, fine);
    let c = counters(0, k, k, 64);
    let batch = Batch::new(&points, &requests, c);
    let a = run(&mut f, &pass_a, &batch, create(11, 1, 0));
    let again = run(&mut f, &pass_a, &batch, create(11, 1, 0));
    let b = run(&mut f, &pass_b, &batch, create(12, 3, 2));
    // The default's coarse levels gather 12×36 strata, its first fine one (spacing ≤ R⁻) 8×24,
    // each finer one half the rays (IcParams::strata_falloff): 4×12 two levels on.
    let coarse = run(&mut f, &pass_b, &batch, create(13, 2, 2));
    let finest = run(&mut f, &pass_b, &batch, create(14, 5, 2));
    assert_eq!(fine.fine_level(), 3);
    assert_eq!(fine.strata_at(2, false), (12, 36));
    assert_eq!(fine.strata_at(3, false), (8, 24));
    assert_eq!(fine.strata_at(5, false), (4, 12));
    assert_eq!(a.records, again.records, "not deterministic");
    // The test hook's stride is the larger strata's count.
    let (ca, cb) = (draft.sample_count() as usize, fine.sample_count() as usize);
    let mut bad = 0;
    for (i, q) in points.iter().enumerate() {
        let sa = &a.samples[i * ca..(i + 1) * ca];
        let sb = &b.samples[i * cb..(i + 1) * cb];
        let ea = check_record(&f, &draft, q, &a.records[i], sa, 1, 0);
        let eb = check_record(&f, &fine, q, &b.records[i], sb, 3, 2);
        let sc = &coarse.samples[i * cb..(i + 1) * cb];
        check_record(&f, &fine, q, &coarse.records[i], sc, 2, 2);
        let sd = &finest.samples[i * cb..(i + 1) * cb];
        check_record(&f, &fine, q, &finest.records[i], sd, 5, 2);
        // The first fine level's strata are the draft's: the same count of samples.
        assert_eq!(fine.strata_at(3, false), draft.strata_at(1, false));
        let sb = &sb[..ca];
        let (sea, seb) = (standard_error(&split(sa).0), standard_error(&split(sb).0));
        let r = &a.records[i];
        let dev = (ea.e - eb.e) / (sea * sea + seb * seb).powf(0.5);
        eprintln!(
            "point {i}: E {} ± {sea} vs {} ± {seb}: {dev} SE",
            ea.e, eb.e
        );
        let radii = [r.bounds[3], r.normal_rorig[3], r.position_radius[3]];
        eprintln!("  R_harm, R_orig, R: {radii:?} in {:?}", &r.bounds[..2]);
        // The walls light every point indirectly.
        assert!(ea.e.min_element() > 0.0 && dev.abs().max_element() <= 5.0);
        bad += check_distances(&f, q, &draft, 11, sa)[0];
    }
    let flags: Vec<u32> = a.records[..k as usize].iter().map(|r| r.info[3]).collect();
    for flag in [RECORD_FLAG_CLAMPED_UP, RECORD_FLAG_CLAMPED_DOWN] {
        assert!(flags.iter().any(|f| f & flag != 0), "{flags:?}");
    }
    // A ray through a crack between two triangles may legitimately differ.
    assert!(bad * 200 <= points.len() * ca, "{bad} distances differ");
    assert!(a.rays > u64::from(k) * ca as u64 && b.rays > u64::from(k) * ca as u64);
    assert!(coarse.rays > u64::from(k) * cb as u64);
    // 48 gather rays and their paths a record, against the 192 of the first fine level's.
    assert!(finest.rays > u64::from(k) * 48 && finest.rays * 2 < b.rays);
    assert_eq!(
        (a.counters.dropped_requests, a.counters.rejected_records),
        (0, 0)
    );
    drop((pass_a, pass_b));
    end(f);
}
