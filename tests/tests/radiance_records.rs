//! The record pass's radiance projection (`shaders/passes/record.comp` with
//! `HAS_RADIANCE_CACHE`, docs/radiance-caching.md §6.1, §7) on lavapipe, on a G-buffer written
//! point by point: every record's 16 RGB coefficients and their translational gradients are
//! compared with the CPU twin `radcache_cache::radiance::compute_radiance` applied to the samples
//! the pass dumps, along the directions the CPU twin of the sampling predicts (folding
//! included), in the buffer layout `RECORD_RADIANCE_VEC4S` documents, with the glossy gradient
//! limit (`glossy_gradient_limit`) in the last vec4; slots of records not in
//! the batch stay untouched.
//!
//! Tolerance: `|gpu − cpu| <= 1e-4 · max(|cpu|, scale) + 1e-6`, `scale` the sum of the sizes of
//! the terms (the GPU sums the polar and the azimuthal walls in separate invocations, so its
//! order differs from the CPU's); the gradients, stored as f16 of `g/s` with `s` the record's
//! largest `|g|`, also within one f16 step of `s` (`2⁻¹⁰·s`: the rounding of `packHalf2x16` is the driver's).

use glam::Vec3;
use radcache_cache::radiance::{
    compute_radiance, glossy_gradient_limit, radiance_azimuthal_wall_coeff,
    radiance_polar_wall_coeff, radiance_sample, stratum_solid_angle,
};
use radcache_cache::record::wall_term;
use radcache_cache::sampling::stratum_index;
use radcache_cache::{IcParams, IC_FAR};
use radcache_render::{
    passes::record::RecordPass, passes::record::RecordVariant, passes::record::WithRadiance,
    GlossySpacing, SkyLight,
};
use radcache_shared::consts::{
    RADIANCE_VEC4S, RECORD_FLAG_GLOSSY, RECORD_RADIANCE_VEC4S, SH_COEFFS,
};
use radcache_tests::record_fixture::*;
use radcache_tests::scenes::load;
use radcache_vk::vk;

/// The float at `f` of a record's block of `RECORD_RADIANCE_VEC4S` vec4.
fn float_at(block: &[[f32; 4]], f: usize) -> f32 {
    block[f / 4][f % 4]
}

/// IEEE binary16 to f32 (what GLSL's `unpackHalf2x16` gives for each half).
fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let mant = f32::from(h & 0x3ff);
    sign * match exp {
        0 => mant * 2f32.powi(-24),
        31 => f32::INFINITY,
        _ => (1.0 + mant / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// Gradient float `f` (`3i + c`) of axis `a`: the f16 of word `24a + f/2` times the scale.
fn gradient_at(block: &[[f32; 4]], a: usize, f: usize) -> f32 {
    let v = RADIANCE_VEC4S as usize;
    let scale = block[v][0];
    let word = 24 * a + f / 2;
    let bits = block[v + 1 + word / 4][word % 4].to_bits();
    let half = if f.is_multiple_of(2) {
        bits & 0xffff
    } else {
        bits >> 16
    };
    half_to_f32(half as u16) * scale
}

/// The sizes of the terms of coefficient and gradient sums (with `|Y| <= 1` for bands 0–3).
fn scales(l: &[Vec3], r: &[f32], m: u32, n: u32, r_eps: f32) -> (f32, f32) {
    let (mut value, mut grad) = (0.0f32, 0.0f32);
    let s = |i: usize| radiance_sample(l[i], r[i]);
    for j in 0..m {
        for k in 0..n {
            let i = stratum_index(j, k, n) as usize;
            value += stratum_solid_angle(j, m, n) * s(i).max_element();
            let wall = |p: usize| wall_term(s(i), s(p), r[i], r[p], r_eps).abs().max_element();
            let kp = stratum_index(j, if k == 0 { n - 1 } else { k - 1 }, n) as usize;
            grad += radiance_azimuthal_wall_coeff(j, k, m, n).length() * wall(kp);
            if j > 0 {
                let jp = stratum_index(j - 1, k, n) as usize;
                grad += radiance_polar_wall_coeff(j, k, m, n).length() * wall(jp);
            }
        }
    }
    (value, grad)
}

fn close(what: &str, gpu: f32, cpu: f32, scale: f32) {
    let tol = 1e-4 * cpu.abs().max(scale) + 1e-6;
    assert!(
        (gpu - cpu).abs() <= tol,
        "{what}: GPU {gpu:e}, CPU {cpu:e} (tolerance {tol:e})"
    );
}

#[test]
fn radiance_coefficients_and_gradients_match_the_cpu_twin() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load(&root.join("../assets/cornell/cornell.gltf"));
    let mut f = fixture(&scene);
    let pixels = [(16, 26), (3, 16), (28, 16), (16, 6), (9, 29)];
    let mut points: Vec<_> = pixels
        .into_iter()
        .map(|(x, y)| surface_at_pixel(&f, &scene, x, y))
        .collect();
    // A shading normal tilted off the geometric one: some directions are folded.
    let mut tilted = points[0];
    tilted.pixel = [5, 5, 0, 0];
    tilted.n = (tilted.ng + Vec3::new(0.8, 0.0, 0.3)).normalize();
    points.push(tilted);
    let requests: Vec<u32> = points.iter().map(point_index).collect();
    let k = points.len() as u32;
    let params = IcParams::draft();
    let pass = RecordPass::new(&f.ctx, &f.shaders, &f.gpu, &radiance_variant(params)).unwrap();
    let stride = RECORD_RADIANCE_VEC4S as usize;
    let slots = 16usize;
    let sentinel = vec![[-7.0f32; 4]; slots * stride];
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let radiance = f
        .ctx
        .create_buffer_init("test.radiance", storage, &sentinel)
        .unwrap();
    let (base, seed) = (2u32, 23u32);
    let c = counters(base, k, k, 64);
    let batch = Batch::new(&points, &requests, c);
    let out = run_with_radiance(&mut f, &pass, &batch, create(seed, 1, 0), &radiance);
    let (m, n) = (params.strata_m, params.strata_n);
    let count = (m * n) as usize;
    let mut folded_any = false;
    for (i, q) in points.iter().enumerate() {
        let s = &out.samples[i * count..(i + 1) * count];
        let l: Vec<Vec3> = s.iter().map(|v| Vec3::new(v[0], v[1], v[2])).collect();
        let r: Vec<f32> = s.iter().map(|v| v[3]).collect();
        let dirs: Vec<Vec3> = (0..count as u32)
            .map(|si| {
                let (d, folded) = direction(q, m, n, seed, si);
                folded_any |= folded;
                d
            })
            .collect();
        let est = compute_radiance(&l, &r, &dirs, m, n, q.n, f.r_eps);
        let (value_scale, grad_scale) = scales(&l, &r, m, n, f.r_eps);
        let slot = base as usize + i;
        let block = &out.radiance[slot * stride..(slot + 1) * stride];
        // The gradients are f16 of g/s, s the largest |g|: one f16 step of s.
        let largest = est.grad.iter().flatten().flat_map(|v| v.to_array());
        let largest = largest.fold(0.0f32, |m, x| m.max(x.abs()));
        close(
            "gradient scale",
            float_at(block, 4 * RADIANCE_VEC4S as usize),
            largest,
            0.0,
        );
        for ci in 0..SH_COEFFS as usize {
            for ch in 0..3 {
                let fl = 3 * ci + ch;
                let what = format!("record {i} coefficient {ci} channel {ch}");
                close(&what, float_at(block, fl), est.coeffs[ci][ch], value_scale);
                for a in 0..3 {
                    let gpu = gradient_at(block, a, fl);
                    let what = format!("record {i} gradient {a} of coefficient {ci} channel {ch}");
                    let cpu = est.grad[a][ci][ch];
                    let tol = 1e-4 * cpu.abs().max(grad_scale) + largest * 2f32.powi(-10);
                    assert!((gpu - cpu).abs() <= tol, "{what}: GPU {gpu:e}, CPU {cpu:e}");
                }
            }
        }
        // The glossy gradient limit in lane 0 of the last vec4 (docs/radiance-caching.md §9):
        // from the f32 sums, so only their rounding separates it from the CPU twin's.
        let limit = glossy_gradient_limit(&est);
        let gpu = float_at(block, 4 * (stride - 1));
        assert!(
            limit < IC_FAR && (gpu - limit).abs() <= 2e-3 * limit,
            "record {i}: glossy limit GPU {gpu:e}, CPU {limit:e}"
        );
        assert_eq!(block[stride - 1][1..], [0.0; 3], "record {i}");
        // The walls light every point: band 0 is positive and some gradient is not zero.
        assert!(est.coeffs[0].min_element() > 0.0, "{:?}", est.coeffs[0]);
        let g: f32 = est.grad.iter().flatten().map(|v| v.length()).sum();
        assert!(g > 0.0, "record {i}: no gradient");
    }
    assert!(folded_any, "the tilted point folds no direction");
    for slot in (0..base as usize).chain(base as usize + points.len()..slots) {
        let block = &out.radiance[slot * stride..(slot + 1) * stride];
        assert!(
            block.iter().flatten().all(|&x| x == -7.0),
            "slot {slot} was written"
        );
    }
    drop((pass, radiance));
    end(f);
}

/// `gbuffer_pack_metallic_roughness` (shaders/common/gbuffer_pack.glsl): 10 bits each.
fn pack_metallic_roughness(metallic: f32, roughness: f32) -> f32 {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 1023.0 + 0.5).floor();
    q(metallic) * 1024.0 + q(roughness)
}

/// Records made for glossy lobes keep the preset's full strata at the fine levels, where other
/// records take the fine strata (`IcParams::strata_at`; docs/irradiance-cache.md §2.8): on
/// `glossy_room`, one surface point requested at the default preset's first fine level gathers
/// 12×36 samples and is flagged glossy where its G-buffer says metal of roughness 0.8, and 8×24
/// unflagged where it says roughness 0.3 (below the records' threshold, so its lobe's light is
/// path traced per pixel).
#[test]
fn records_for_glossy_lobes_keep_the_full_strata_at_fine_levels() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load(&root.join("../assets/glossy_room/glossy_room.gltf"));
    let mut f = fixture(&scene);
    let params = IcParams::default();
    let level = params.fine_level();
    assert!(level < params.levels, "the default preset has fine levels");
    assert_eq!(params.strata_at(level, true), (12, 36));
    assert_eq!(params.strata_at(level, false), (8, 24));
    let metal = scene
        .materials
        .iter()
        .position(|m| m.metallic > 0.5)
        .expect("glossy_room has a metal");
    let mut rough = surface_at_pixel(&f, &scene, 16, 26);
    rough.material = metal as f32;
    rough.metallic_roughness = pack_metallic_roughness(1.0, 0.8);
    let mut sharp = rough;
    sharp.pixel = [5, 5, 0, 0];
    sharp.metallic_roughness = pack_metallic_roughness(1.0, 0.3);
    let points = [rough, sharp];
    let requests: Vec<u32> = points.iter().map(point_index).collect();
    let pass = RecordPass::new(&f.ctx, &f.shaders, &f.gpu, &radiance_variant(params)).unwrap();
    let zeros = vec![[0.0f32; 4]; SLOTS * RECORD_RADIANCE_VEC4S as usize];
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let radiance = f
        .ctx
        .create_buffer_init("test.radiance", storage, &zeros)
        .unwrap();
    let c = counters(0, 2, 2, 64);
    let batch = Batch::new(&points, &requests, c);
    let out = run_with_radiance(&mut f, &pass, &batch, create(5, level, 0), &radiance);
    let per = params.sample_count() as usize;
    // A stratum the pass traced has a positive distance (the room is closed); the others keep
    // the dump's zeros.
    let traced = |i: usize| {
        out.samples[i * per..(i + 1) * per]
            .iter()
            .filter(|s| s[3] > 0.0)
            .count()
    };
    let glossy = |i: usize| out.records[i].info[3] & RECORD_FLAG_GLOSSY != 0;
    assert_eq!((traced(0), glossy(0)), (12 * 36, true), "roughness 0.8");
    assert_eq!((traced(1), glossy(1)), (8 * 24, false), "roughness 0.3");
    drop((pass, radiance));
    end(f);
}

/// Records with radiance coefficients, for `params`.
fn radiance_variant(params: IcParams) -> RecordVariant<WithRadiance> {
    RecordVariant::new(params, SkyLight::Records).with(WithRadiance {
        glossy_spacing: GlossySpacing::Lobe,
    })
}
