//! The GLSL twin of radcache-material (`shaders/common/brdf.glsl`) evaluated ON LAVAPIPE against
//! the Rust functions over tables of inputs: random rows plus edge rows (grazing and
//! below-horizon `n·v` and `n·l`, roughness 0 and 1, metallic 0, 0.5 and 1, ior 1 and 1.5,
//! specular factor 0 and 1, random numbers at 0 and just below 1, mirror directions).
//! `shaders/tests/brdf_twin.comp` evaluates one row per invocation; each family below builds the
//! rows and the expected outputs in the shader's output layout (see the shader for the slots).
//!
//! Tolerance: `|gpu − cpu| <= 1e-5 · max(|cpu|, scale) + 1e-6` (the harness's), where `scale` is
//! the magnitude of the terms a result is computed from: for Smith's Λ, `½·root/cosθ`, of which
//! it is a difference. Looser, and why:
//! * Sampled directions (`sample_cosine_hemisphere`, `sample_ggx_vndf`, `brdf_sample.l`) go
//!   through GPU `cos`/`sin`, for which Vulkan allows an absolute error of 2⁻¹¹ on `[−π, π]`
//!   (lavapipe is far better; the figures below are measured): `scale = SINCOS_SCALE`.
//!   Below the horizon (`v.z <= 0`, outside its domain) `sample_ggx_vndf` is not compared.
//! * What is evaluated at a sampled direction (`brdf_sample`'s pdf and weight) inherits that
//!   direction's error `δ` through `D(h)`, whose relative slope is up to `~4|h_xy|/α² ≤ 4/α` near
//!   its peak: `scale = |cpu| · (1 + PDF_DIR_ERROR · 4/α / 1e-5)`, i.e. a relative tolerance
//!   of `1e-5 + 4·PDF_DIR_ERROR/α` (`PDF_DIR_ERROR = 1e-6`: 4·10⁻³ at roughness 0, 1.4·10⁻⁵ at
//!   roughness 1).
//! * The lobe choice `u.z < p` is a step: a row whose `u.z` is within `1e-5` of `p` is a tie
//!   (not compared), as is a weight whose `l.z` is within rounding of `COS_MIN`.
//!
//! The largest differences per function are printed (`--nocapture`).

use glam::Vec3;
use radcache_material::brdf::{
    brdf_eval, brdf_eval_lobes, diffuse_share, schlick_hemispherical_mean, Material, COS_MIN,
};
use radcache_material::fresnel::*;
use radcache_material::ggx::*;
use radcache_material::polygon::*;
use radcache_material::sampling::*;
use radcache_tests::twin::{
    check_diffs, twin_pipeline, unit, v4, vec, BrdfTwinMode, Case, Expect, How, LaneDiff, Row,
};
use radcache_tests::{context, finish, Rng};

/// The scale of sampled unit-vector components (GPU `cos`/`sin`; see the header).
const SINCOS_SCALE: f32 = 10.0;
/// The absolute error allowed in a sampled direction's components: `1e-5 · SINCOS_SCALE`.
const SAMPLED_DIR_ERROR: f32 = 1e-5 * SINCOS_SCALE;
/// The error of a sampled direction assumed where its pdf and weight are compared
/// (see the header).
const PDF_DIR_ERROR: f32 = 1e-6;

/// The largest `f32` below 1: a uniform random number's largest value.
const U_MAX: f32 = 1.0 - f32::EPSILON / 2.0;

fn pick(rng: &mut Rng, edges: &[f32], k: u32, lo: f32, hi: f32) -> f32 {
    edges
        .get(k as usize % (edges.len() * 2))
        .copied()
        .unwrap_or_else(|| rng.range(lo, hi))
}

/// A direction with a given `z` (`z` in `[−1, 1]`), random azimuth.
fn with_z(z: f32, rng: &mut Rng) -> Vec3 {
    let phi = rng.range(0.0, std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
}

/// Mode 0: Fresnel, GGX and Smith terms.
fn terms(rng: &mut Rng) -> Vec<Case> {
    let mut cases = Vec::new();
    for i in 0..600u32 {
        let f0 = Vec3::new(rng.f32(), rng.f32(), rng.f32());
        let f90 = if i % 3 == 0 { 1.0 } else { rng.f32() };
        let cos_theta = pick(rng, &[0.0, 1.0, 1e-6, -0.5, 1.5, 1e-3], i, 0.0, 1.0);
        let ior = pick(rng, &[1.0, 1.5, 0.5, 2.5], i / 2, 1.0, 3.0);
        let alpha = pick(rng, &[ALPHA_MIN, 1.0, 0.5, 0.01], i / 3, ALPHA_MIN, 1.0);
        let roughness = pick(rng, &[0.0, 1.0, -0.1, 1.2, 0.5], i / 5, 0.0, 1.0);
        let cos_edges = [0.0, 1e-6, 1e-4, 1.0, -0.3];
        let n_dot_l = pick(rng, &cos_edges, i / 7, 0.0, 1.0);
        let n_dot_v = pick(rng, &cos_edges, i / 11, 0.0, 1.0);
        let spec = match i % 4 {
            0 => Vec3::ZERO,
            1 => Vec3::ONE,
            _ => Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0,
        };
        let m = match i % 13 {
            0 => Vec3::Z,
            1 => -Vec3::Z,
            2 => Vec3::new(1.0, 0.0, 1e-4).normalize(),
            3 => with_z(1.0 - 1e-6, rng),
            _ => with_z(rng.range(-0.2, 1.0), rng),
        };
        let c = Vec3::new(
            rng.range(-1.0, 2.0),
            rng.range(-1.0, 2.0),
            rng.range(-1.0, 2.0),
        );
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = v4(f0, f90);
        row[1] = [cos_theta, ior, alpha, n_dot_l];
        row[2] = v4(spec, n_dot_v);
        row[3] = v4(m, roughness);
        row[4] = v4(c, 0.0);
        let mut e = Expect::new();
        e.v(0, fresnel_schlick(f0, f90, cos_theta), 1.0);
        e.f(0, 3, schlick_weight(cos_theta), 1.0);
        e.v(1, dielectric_f0(ior, spec), 0.0);
        e.f(1, 3, f0_from_ior(ior), 0.0);
        e.f(2, 0, ggx_d(alpha, m), 0.0);
        let lambda = smith_lambda(alpha, cos_theta);
        let lambda_terms = if cos_theta > 0.0 {
            0.5 * (alpha * alpha + (1.0 - alpha * alpha) * cos_theta * cos_theta).sqrt() / cos_theta
        } else {
            0.0
        };
        e.f(2, 1, lambda, lambda_terms);
        e.f(2, 2, smith_g1(alpha, cos_theta), 0.0);
        e.f(2, 3, smith_v_correlated(alpha, n_dot_l, n_dot_v), 0.0);
        e.f(3, 0, alpha_from_roughness(roughness), 0.0);
        e.f(3, 1, max_component(c), 0.0);
        e.f(3, 2, mean_component(c), 2.0);
        e.f(3, 3, schlick_hemispherical_mean(n_dot_v), 0.0);
        cases.push((row, e));
    }
    cases
}

/// A random or edge material for row `i`.
fn material(rng: &mut Rng, i: u32) -> Material {
    let base = match i % 9 {
        0 => Vec3::ONE,
        1 => Vec3::ZERO,
        2 => Vec3::new(1.5, -0.2, 0.5),
        _ => Vec3::new(rng.f32(), rng.f32(), rng.f32()),
    };
    Material {
        base_colour: base,
        metallic: pick(rng, &[0.0, 0.5, 1.0], i / 2, 0.0, 1.0),
        roughness: pick(rng, &[0.0, 1.0, 0.05], i / 3, 0.0, 1.0),
        ior: pick(rng, &[1.0, 1.5], i / 5, 1.0, 2.5),
        specular_factor: pick(rng, &[0.0, 1.0], i / 7, 0.0, 1.0),
        specular_colour: if i.is_multiple_of(4) {
            Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 1.5
        } else {
            Vec3::ONE
        },
    }
}

/// Mode 1: evaluation, diffuse share, sampling and pdfs.
fn brdf(rng: &mut Rng) -> Vec<Case> {
    let mut cases = Vec::new();
    let z_edges = [COS_MIN, 1e-5, 1e-3, 0.0, -0.2, 1.0, 0.05];
    for i in 0..1500u32 {
        let m = material(rng, i);
        let v = with_z(pick(rng, &z_edges, i / 11, 0.0, 1.0), rng);
        let alpha = alpha_from_roughness(m.roughness);
        let mirror = Vec3::new(-v.x, -v.y, v.z);
        let l = match i % 6 {
            0 => mirror,
            1 => (mirror + unit(rng) * alpha * 0.5).normalize(),
            _ => with_z(pick(rng, &z_edges, i / 13, -0.3, 1.0), rng),
        };
        let u_edges = [0.0, U_MAX, 0.5];
        let u = Vec3::new(
            pick(rng, &u_edges, i / 17, 0.0, 1.0),
            pick(rng, &u_edges, i / 19, 0.0, 1.0),
            pick(rng, &u_edges, i / 23, 0.0, 1.0),
        );
        let mf = if i % 2 == 0 {
            sample_ggx_vndf(alpha, v, rng.f32(), rng.f32())
        } else {
            unit(rng)
        };
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = v4(m.base_colour, m.metallic);
        row[1] = [m.roughness, m.ior, m.specular_factor, 0.0];
        row[2] = v4(m.specular_colour, 0.0);
        row[3] = v4(v, 0.0);
        row[4] = v4(l, 0.0);
        row[5] = v4(u, 0.0);
        row[6] = v4(mf, alpha);
        let mut e = Expect::new();
        let lobes = brdf_eval_lobes(&m, v, l);
        e.v(0, lobes.diffuse, 0.0);
        e.f(0, 3, diffuse_share(&m, v.z), 1.0);
        e.v(1, lobes.specular, 0.0);
        let p = specular_lobe_probability(&m, v.z);
        e.f(1, 3, p, 1.0);
        e.v(2, brdf_eval(&m, v, l), 0.0);
        e.f(2, 3, brdf_pdf(&m, v, l), 0.0);
        // The visible-normal sampler is defined for `v.z > 0` (its doc): below the horizon
        // `h_s = c + v_s` cancels (`v_s.z → −1` for small α) and the rows are not compared.
        if v.z > 0.0 {
            e.v(3, sample_ggx_vndf(alpha, v, u.x, u.y), SINCOS_SCALE);
        }
        e.f(3, 3, ggx_vndf_pdf(alpha, v, mf), 0.0);
        e.v(4, reflect(v, mf), 2.0);
        e.f(4, 3, ggx_reflection_pdf(alpha, v, l), 0.0);
        e.v(5, sample_cosine_hemisphere(u.x, u.y), SINCOS_SCALE);
        e.f(5, 3, cosine_hemisphere_pdf(l), 0.0);
        let s = brdf_sample(&m, v, u);
        e.v(6, s.l, SINCOS_SCALE);
        let sampled = |x: f32| x.abs() * (1.0 + PDF_DIR_ERROR * 4.0 / alpha / 1e-5);
        e.f(6, 3, s.pdf, sampled(s.pdf));
        for c in 0..3 {
            e.f(7, c, s.weight[c], sampled(s.weight[c]));
        }
        // The lobe choice and the horizon test are steps: rows on them are ties.
        let lobe_tie = v.z >= COS_MIN && (u.z - p).abs() <= 1e-5;
        let horizon_tie = (s.l.z - COS_MIN).abs() <= SAMPLED_DIR_ERROR;
        if lobe_tie {
            e.how[6] = [How::Tie; 4];
        }
        if lobe_tie || horizon_tie {
            e.how[7] = [How::Tie; 4];
        }
        cases.push((row, e));
    }
    // The rows hold what they are for: both lobes sampled, weights above and below the horizon.
    let sampled_specular = cases.iter().filter(|c| c.0[5][2] < c.1.v[1][3]).count();
    assert!(
        sampled_specular > 100,
        "{sampled_specular} specular samples"
    );
    let below = cases.iter().filter(|c| c.1.v[6][2] < 0.0).count();
    assert!(below > 10, "{below} samples below the horizon");
    let lit = cases.iter().filter(|c| c.1.v[7][0] > 0.0).count();
    assert!(lit > 500, "{lit} non-zero weights");
    cases
}

/// Output lanes of each function: (slot, first lane, lanes, name).
type Lanes = [(usize, usize, usize, &'static str)];

const TERM_LANES: &Lanes = &[
    (0, 0, 3, "fresnel_schlick"),
    (0, 3, 1, "schlick_weight"),
    (1, 0, 3, "dielectric_f0"),
    (1, 3, 1, "f0_from_ior"),
    (2, 0, 1, "ggx_d"),
    (2, 1, 1, "smith_lambda"),
    (2, 2, 1, "smith_g1"),
    (2, 3, 1, "smith_v_correlated"),
    (3, 0, 1, "alpha_from_roughness"),
    (3, 1, 1, "max_component"),
    (3, 2, 1, "mean_component"),
    (3, 3, 1, "schlick_hemispherical_mean"),
];

const BRDF_LANES: &Lanes = &[
    (0, 0, 3, "brdf_eval_lobes.diffuse"),
    (0, 3, 1, "diffuse_share"),
    (1, 0, 3, "brdf_eval_lobes.specular"),
    (1, 3, 1, "specular_lobe_probability"),
    (2, 0, 3, "brdf_eval"),
    (2, 3, 1, "brdf_pdf"),
    (3, 0, 3, "sample_ggx_vndf"),
    (3, 3, 1, "ggx_vndf_pdf"),
    (4, 0, 3, "reflect"),
    (4, 3, 1, "ggx_reflection_pdf"),
    (5, 0, 3, "sample_cosine_hemisphere"),
    (5, 3, 1, "cosine_hemisphere_pdf"),
    (6, 0, 3, "brdf_sample.l"),
    (6, 3, 1, "brdf_sample.pdf"),
    (7, 0, 3, "brdf_sample.weight"),
];

const POLYGON_LANES: &Lanes = &[
    (0, 0, 1, "triangle_projected_solid_angle"),
    (0, 2, 1, "edge_term"),
    (1, 0, 3, "clip_to_hemisphere"),
];

/// Prints the largest differences of each function's lanes.
fn report(names: &Lanes, diffs: &[[LaneDiff; 4]; 16]) {
    for &(slot, first, lanes, name) in names {
        let (mut abs, mut rel, mut tol) = (0.0f32, 0.0f32, 0.0f32);
        for d in &diffs[slot][first..first + lanes] {
            abs = abs.max(d.abs);
            rel = rel.max(d.rel);
            tol = tol.max(d.of_tolerance);
        }
        eprintln!(
            "{name:<28} max |gpu - cpu| {abs:.2e}, relative {rel:.2e}, of tolerance {tol:.3}"
        );
    }
}

/// Mode 2: the projected solid angle of triangles around a receiver, many crossing its horizon
/// (the clipping), some wholly below, one degenerate.
fn polygons(rng: &mut Rng) -> Vec<Case> {
    let mut cases = Vec::new();
    for i in 0..400u32 {
        let p = vec(rng, 1.0);
        let n = unit(rng);
        let centre = p + n * rng.range(-0.3, 1.0) + vec(rng, 0.8);
        let mut t = [
            centre + vec(rng, 0.6),
            centre + vec(rng, 0.6),
            centre + vec(rng, 0.6),
        ];
        if i % 37 == 0 {
            t[2] = t[0] + (t[1] - t[0]) * 0.5;
        }
        let a = unit(rng);
        let b = if i % 11 == 0 { a } else { unit(rng) };
        let mut row: Row = [[0.0; 4]; 16];
        row[0] = v4(p, 0.0);
        row[1] = v4(n, 0.0);
        for (k, v) in t.iter().enumerate() {
            row[2 + k] = v4(*v, 0.0);
        }
        row[5] = v4(a, 0.0);
        row[6] = v4(b, 0.0);
        let mut q = [Vec3::ZERO; CLIPPED_MAX];
        let count = clip_to_hemisphere(p, n, t, &mut q);
        let mut e = Expect::new();
        // The sum of up to four terms of magnitude up to π: their scale.
        e.f(0, 0, triangle_projected_solid_angle(p, n, t), 4.0);
        e.exact(0, 1, count as f32);
        e.f(0, 2, edge_term(n, a, b), 1.0);
        let scale = t.iter().map(|v| (*v - p).length()).fold(0.0, f32::max);
        for (k, v) in q.iter().take(count).enumerate() {
            e.v(1 + k, *v, scale);
        }
        cases.push((row, e));
    }
    cases
}

#[test]
fn brdf_glsl_twin_matches_the_rust_brdf_on_the_gpu() {
    let ctx = context();
    let pipeline = twin_pipeline(&ctx, "brdf_twin.comp", "brdf_twin");
    let mut rng = Rng::new(0xb2df_2026);
    let d = check_diffs(&ctx, &pipeline, BrdfTwinMode::Terms, &terms(&mut rng), &[]);
    report(TERM_LANES, &d);
    let bc = brdf(&mut rng);
    let d = check_diffs(&ctx, &pipeline, BrdfTwinMode::Brdf, &bc, &[]);
    report(BRDF_LANES, &d);
    let d = check_diffs(
        &ctx,
        &pipeline,
        BrdfTwinMode::Polygon,
        &polygons(&mut rng),
        &[],
    );
    report(POLYGON_LANES, &d);
    drop(pipeline);
    finish(ctx);
}
