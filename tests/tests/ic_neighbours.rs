//! The neighbour-clamping pass's hash grid on lavapipe against the all-pairs clamp on the CPU
//! (`radcache_cache::neighbour_clamp`), over thousands of records whose R⁺ spans several grid
//! levels, clustered so that many pairs interact; and the count of old records' radii lowered
//! (`IcCounters::radii_shrunk`, which decides whether the cache phase repeats).

use glam::Vec3;
use radcache_cache::radius::neighbour_clamp;
use radcache_render::{
    passes::neighbours::NeighbourJob, passes::neighbours::NeighbourPass, state::IcStateDesc,
    IcState,
};
use radcache_shared::gpu::{DispatchArgs, DrawArgs, GpuRecord, IcCounters};
use radcache_tests::{context, finish, shaders, Rng};
use radcache_vk::Recorder;

const SCENE_SCALE: f32 = 20.0;

fn record(p: Vec3, r_orig: f32, hi: f32) -> GpuRecord {
    GpuRecord {
        position_radius: [p.x, p.y, p.z, r_orig.min(hi)],
        normal_rorig: [0.0, 1.0, 0.0, r_orig],
        irradiance: [1.0, 1.0, 1.0, 1.0],
        bounds: [hi * 0.05, hi, 1.0, r_orig],
        grad_r_red: [0.0; 4],
        grad_r_green: [0.0; 4],
        grad_r_blue: [0.0; 4],
        grad_t_red: [0.0; 4],
        grad_t_green: [0.0; 4],
        grad_t_blue: [0.0; 4],
        info: [0; 4],
    }
}

fn upload(rec: &mut Recorder, state: &IcState, records: &[GpuRecord], counters: IcCounters) {
    // vkCmdUpdateBuffer takes at most 65536 bytes at a time.
    let per = 65536 / std::mem::size_of::<GpuRecord>();
    for (k, chunk) in records.chunks(per).enumerate() {
        let offset = (k * per * std::mem::size_of::<GpuRecord>()) as u64;
        rec.update_buffer(&state.records, offset, chunk);
    }
    rec.update_buffer(&state.counters, 0, std::slice::from_ref(&counters));
}

/// The all-pairs clamp of the batch `[base, n)` against every record, in rounds until nothing
/// changes (`iterate`) or one round from the initial radii (the GPU reads radii that other
/// workgroups may already have lowered, so its result lies between the two).
fn cpu_clamp(records: &[GpuRecord], base: usize, iterate: bool) -> Vec<f32> {
    let p: Vec<Vec3> = records
        .iter()
        .map(|r| Vec3::from_slice(&r.position_radius[..3]))
        .collect();
    // New records start capped at their R⁺.
    let mut r: Vec<f32> = records
        .iter()
        .enumerate()
        .map(|(k, x)| {
            if k >= base {
                x.normal_rorig[3].min(x.bounds[1])
            } else {
                x.normal_rorig[3]
            }
        })
        .collect();
    loop {
        let start = r.clone();
        let mut next = r.clone();
        for i in base..records.len() {
            for j in 0..records.len() {
                if i == j {
                    continue;
                }
                let d = p[i].distance(p[j]);
                next[i] = next[i].min(neighbour_clamp(f32::MAX, start[j], d));
                next[j] = next[j].min(neighbour_clamp(start[j], start[i], d));
            }
        }
        r = next;
        if !iterate || r == start {
            return r;
        }
    }
}

#[test]
fn the_hash_grid_gives_the_all_pairs_clamp() {
    let ctx = context();
    let shaders = shaders();
    let (n, base) = (3000usize, 2200usize);
    let mut rng = Rng::new(77);
    // Clusters (surfaces seen at different distances): R⁺ from 0.02 to 2.5 (8 levels), radii
    // from well below to well above R⁺.
    let records: Vec<GpuRecord> = (0..n)
        .map(|k| {
            let cluster = (k * 7) % 12;
            let centre = Vec3::new(
                (cluster % 3) as f32 * 4.0 - 4.0,
                (cluster / 3 % 2) as f32 * 3.0,
                (cluster / 6) as f32 * 5.0 - 2.0,
            );
            let hi = 0.02 * 2f32.powf(7.0 * rng.f32());
            let spread = 1.5 * rng.f32() + 0.1;
            let p = centre
                + Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5) * 2.0 * spread;
            // Old records were capped at R⁺ by their own batch.
            let r = hi * (0.1 + 2.0 * rng.f32());
            record(p, if k < base { r.min(hi) } else { r }, hi)
        })
        .collect();
    let state = IcState::new(&ctx, &shaders, &IcStateDesc::new(4096, 1024)).unwrap();
    let pass = NeighbourPass::new(&ctx, &shaders).unwrap();
    let counters = IcCounters {
        record_count: n as u32,
        requested: 0,
        batch_first: base as u32,
        holes: 0,
        dispatch: DispatchArgs::groups((n - base) as u32),
        draw: DrawArgs::quads(n as u32, 0),
        record_capacity: 4096,
        request_capacity: 1024,
        dropped_requests: 0,
        rejected_records: 0,
        batch_draw: DrawArgs::quads((n - base) as u32, base as u32),
        radii_shrunk: 0,
    };
    // The grid built and the batch clamped: the records and the count of old radii lowered.
    let clamp = |records: &[GpuRecord]| -> (Vec<GpuRecord>, u32) {
        let mut rec = ctx.begin("test.grid").unwrap();
        upload(&mut rec, &state, records, counters);
        pass.record(&mut rec, &state, SCENE_SCALE, NeighbourJob::Rebuild)
            .unwrap();
        pass.record(&mut rec, &state, SCENE_SCALE, NeighbourJob::Batch)
            .unwrap();
        ctx.submit(rec).unwrap().wait().unwrap();
        let out = ctx.read_buffer(&state.records, n).unwrap();
        (out, state.read_counters().unwrap().radii_shrunk)
    };
    let (out, shrunk) = clamp(&records);

    // The same batch moved far from every old record: it clamps only itself, and no old
    // record's coverage goes stale.
    let mut apart = records.clone();
    for r in &mut apart[base..] {
        r.position_radius[0] += 1000.0;
    }
    let (apart_out, apart_shrunk) = clamp(&apart);
    drop((pass, state));
    finish(ctx);
    let new_clamped = (base..n)
        .filter(|&k| {
            apart_out[k].normal_rorig[3] < apart[k].normal_rorig[3].min(apart[k].bounds[1])
        })
        .count();
    assert!(new_clamped > 0, "the batch must clamp itself");
    assert_eq!(apart_shrunk, 0, "no old record is near the batch");

    let upper = cpu_clamp(&records, base, false);
    let lower = cpu_clamp(&records, base, true);
    let (mut changed, mut chained, mut old_shrunk) = (0, 0, 0);
    for k in 0..n {
        let got = out[k].normal_rorig[3];
        let hi = records[k].bounds[1];
        let tol = 1e-5 * (1.0 + upper[k]);
        assert!(
            got <= upper[k] + tol && got >= lower[k] - tol,
            "record {k}: {got} outside [{}, {}] (R⁺ {hi})",
            lower[k],
            upper[k]
        );
        // The radius the splat uses agrees with the all-pairs clamp.
        if got.min(hi) < records[k].normal_rorig[3].min(hi) {
            changed += 1;
            // (The lower bound is 0.05 R⁺, below every radius here.)
            old_shrunk += usize::from(k < base);
        }
        if lower[k] < upper[k] {
            chained += 1;
        }
    }
    // Every old record whose used radius went down is counted (once per lowering, so at least
    // once): its coverage splat is stale (crates/radcache-render/src/frame/ic/phases.rs).
    assert!(
        shrunk as usize >= old_shrunk && old_shrunk > 0,
        "radii_shrunk {shrunk}, old records shrunk {old_shrunk}"
    );
    // The data must exercise the clamp: many records shrink, among them old and new ones.
    assert!(changed > n / 10, "only {changed} radii changed");
    assert!(
        chained < n / 10,
        "{chained} chained clamps: the bounds are too loose"
    );
}
