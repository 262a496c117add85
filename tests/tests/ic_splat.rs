//! The cache's splat, hole-selection, counter and neighbour-clamping passes on lavapipe, against
//! the CPU twins of radcache-cache, on a synthetic G-buffer (every pixel the same surface point),
//! so each expected value is exact; and the splat quads' bound on the Cornell box's own G-buffer.

use glam::Vec3;
use radcache_cache::{extrapolate_irradiance, record_weight, IcParams, WeightKind, WeightRecord};
use radcache_render::{
    passes::gbuffer::GBuffer, passes::holes::HolePass, passes::holes::HoleSelection,
    passes::neighbours::NeighbourJob, passes::neighbours::NeighbourPass, passes::splat::SplatDraw,
    passes::splat::SplatInputs, passes::splat::SplatOutput, passes::splat::SplatPass,
    passes::splat::SplatWeights, state::IcStateDesc, GpuScene, IcState,
};
use radcache_scene::{LoadOptions, Scene};
use radcache_shared::gpu::{DispatchArgs, DrawArgs, GpuRecord, IcCounters};
use radcache_tests::ic_fixture::Gpu;
use radcache_tests::{context, finish, shaders, Rng};
use radcache_vk::{Context, Recorder};

const W: u32 = 32;
const H: u32 = 24;
const P: Vec3 = Vec3::new(0.3, 0.0, 0.3);
const N: Vec3 = Vec3::Y;
const FOOTPRINT: f32 = 1e-3;

fn cornell() -> Scene {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/cornell/cornell.gltf"
    );
    Scene::load(std::path::Path::new(path), &LoadOptions::default())
        .unwrap()
        .0
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// A record at `p` with normal `n`, irradiance `e`, radius `r` (R⁻ = R⁺ = r unless `bounds`).
fn record(p: Vec3, n: Vec3, e: Vec3, r: f32, grad_r: [Vec3; 3]) -> GpuRecord {
    GpuRecord {
        position_radius: v4(p, r),
        normal_rorig: v4(n, r),
        irradiance: v4(e, 1.0),
        bounds: [r, r, FOOTPRINT, r],
        grad_r_red: v4(grad_r[0], 0.0),
        grad_r_green: v4(grad_r[1], 0.0),
        grad_r_blue: v4(grad_r[2], 0.0),
        grad_t_red: [0.0; 4],
        grad_t_green: [0.0; 4],
        grad_t_blue: [0.0; 4],
        info: [0; 4],
    }
}

/// The CPU twin's weight of record `r` at the G-buffer point `(p, n)` of pixel footprint
/// `footprint`, with the in-front tolerance the splat uses.
fn cpu_weight(params: &IcParams, r: &GpuRecord, p: Vec3, n: Vec3, footprint: f32) -> f32 {
    record_weight(
        params.weight_kind,
        p,
        n,
        WeightRecord {
            p: Vec3::from_slice(&r.position_radius[..3]),
            n: Vec3::from_slice(&r.normal_rorig[..3]),
            r: r.position_radius[3],
        },
        params.weight_param(),
        params.front_tolerance_px * footprint,
    )
}

/// Fills every G-buffer pixel with the surface point (P, N).
fn fill_gbuffer(rec: &mut Recorder, g: &GBuffer) {
    let values = [
        v4(P, 1.0),
        v4(N, FOOTPRINT),
        v4(N, 0.0),
        [0.5, 0.5, 0.5, 0.0],
        [0.0; 4],
        [0.0; 4],
    ];
    for (image, value) in g.images().into_iter().zip(values) {
        rec.clear_color(image, value);
    }
}

fn set_state(rec: &mut Recorder, state: &IcState, records: &[GpuRecord], counters: IcCounters) {
    if !records.is_empty() {
        rec.update_buffer(&state.records, 0, records);
    }
    rec.update_buffer(&state.counters, 0, std::slice::from_ref(&counters));
}

fn counters(records: u32, batch_base: u32) -> IcCounters {
    IcCounters {
        record_count: records,
        requested: 0,
        batch_first: batch_base,
        holes: 0,
        dispatch: DispatchArgs::groups(records - batch_base),
        draw: DrawArgs::quads(records, 0),
        record_capacity: 64,
        request_capacity: 1024,
        dropped_requests: 0,
        rejected_records: 0,
        batch_draw: DrawArgs::quads(records - batch_base, batch_base),
        radii_shrunk: 0,
    }
}

struct Fixture {
    ctx: Context,
    gpu: GpuScene,
    gbuffer: GBuffer,
    splat: SplatPass,
    state: IcState,
}

impl Fixture {
    /// The splat's inputs: the fixture's scene, G-buffer and records.
    fn inputs(&self) -> SplatInputs<'_> {
        SplatInputs {
            scene: &self.gpu,
            gbuffer: &self.gbuffer,
            state: &self.state,
        }
    }
}

fn fixture() -> Fixture {
    let ctx = context();
    let shaders = shaders();
    let scene = cornell();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    gpu.set_time(&scene, 0.0).unwrap();
    gpu.set_view(&scene.camera_at(0.0), W, H, 1, 0).unwrap();
    let gbuffer = GBuffer::new(&ctx, W, H).unwrap();
    let splat = SplatPass::new(&ctx, &shaders, W, H).unwrap();
    let state = IcState::new(&ctx, &shaders, &IcStateDesc::new(64, 1024)).unwrap();
    Fixture {
        ctx,
        gpu,
        gbuffer,
        splat,
        state,
    }
}

fn end(f: Fixture) {
    let Fixture {
        ctx,
        gpu,
        gbuffer,
        splat,
        state,
    } = f;
    drop((gpu, gbuffer, splat, state));
    finish(ctx);
}

#[test]
fn splat_sums_match_the_cpu_weight_and_extrapolation() {
    let f = fixture();
    let params = IcParams::default();
    let weights = SplatWeights::from_params(&params);
    assert_eq!(params.weight_kind, WeightKind::TabellionLamorlette);
    // A record exactly at the pixel's point, and one with a tilted normal and a rotational
    // gradient; both have radii large enough that their splat covers the whole view.
    let tilt = (N + Vec3::new(0.05, 0.0, 0.02)).normalize();
    let grad = [
        Vec3::new(0.0, 0.0, 0.4),
        Vec3::new(0.3, 0.0, 0.0),
        Vec3::ZERO,
    ];
    let r = 1.0e9;
    let recs = [
        record(P, N, Vec3::new(1.0, 2.0, 3.0), r, [Vec3::ZERO; 3]),
        record(
            P + Vec3::new(-0.01, 0.0, 0.0),
            tilt,
            Vec3::new(0.5, 0.25, 0.125),
            r,
            grad,
        ),
    ];
    let mut rec = f.ctx.begin("test.splat").unwrap();
    fill_gbuffer(&mut rec, &f.gbuffer);
    set_state(&mut rec, &f.state, &recs, counters(2, 0));
    f.splat
        .record(&mut rec, &f.inputs(), &SplatDraw::all(&weights))
        .unwrap();
    f.ctx.submit(rec).unwrap().wait().unwrap();
    let sums: Vec<[f32; 4]> = f.ctx.read_image(&f.splat.sum).unwrap();

    let mut expected = [0.0f64; 4];
    for r in &recs {
        let p_i = Vec3::from_slice(&r.position_radius[..3]);
        let n_i = Vec3::from_slice(&r.normal_rorig[..3]);
        let w = cpu_weight(&params, r, P, N, FOOTPRINT);
        assert!(w > 0.0, "the test records must contribute");
        let g = |v: [f32; 4]| Vec3::from_slice(&v[..3]);
        let e = extrapolate_irradiance(
            g(r.irradiance),
            &[g(r.grad_r_red), g(r.grad_r_green), g(r.grad_r_blue)],
            &[Vec3::ZERO; 3],
            P,
            N,
            p_i,
            n_i,
        );
        for c in 0..3 {
            expected[c] += f64::from(w * e[c]);
        }
        expected[3] += f64::from(w);
    }
    for (i, s) in sums.iter().enumerate() {
        for c in 0..4 {
            let got = f64::from(s[c]);
            assert!(
                (got - expected[c]).abs() <= 1e-5 * expected[c].abs().max(1.0),
                "pixel {i} channel {c}: GPU {got}, CPU {}",
                expected[c]
            );
        }
    }
    end(f);
}

/// The splat quad bounds a record's zone by two square frusta on its tangent plane
/// (`splat.vert`), tighter than the ball's box on surfaces seen at an angle: on the Cornell box's
/// G-buffer (floor, ceiling and side walls seen obliquely, corners where zones reach another
/// surface), Σw of records at random pixels, with random radii and normals tilted up to ~25°,
/// equals the CPU's sum over every record at every pixel. A quad that missed a pixel of its
/// zone would lose that record's weight there. The coverage splat (`SPLAT_COVERAGE`, what hole
/// selection reads) gives the same Σw and no colour.
#[test]
fn splat_quads_cover_every_pixel_of_each_zone() {
    let scene = cornell();
    let (w, h) = (96, 72);
    let gpu = Gpu::with_gbuffer(&scene, None, (w, h), Some(false));
    let splat = SplatPass::new(&gpu.ctx, &gpu.shaders, w, h).unwrap();
    let state = IcState::new(&gpu.ctx, &gpu.shaders, &IcStateDesc::new(64, 1024)).unwrap();
    gpu.render([0.0, 0.0], None);
    let g = gpu.read_gbuffer();
    let params = IcParams::default();
    let weights = SplatWeights::from_params(&params);
    let surface: Vec<usize> = (0..g.position.len())
        .filter(|&i| g.position[i][3] > 0.0)
        .collect();
    let mut rng = Rng::new(17);
    let at = |v: [f32; 4]| Vec3::from_slice(&v[..3]);
    let recs: Vec<GpuRecord> = (0..48)
        .map(|_| {
            let i = surface[rng.below(surface.len() as u32) as usize];
            let tilt = Vec3::new(
                rng.range(-0.2, 0.2),
                rng.range(-0.2, 0.2),
                rng.range(-0.2, 0.2),
            );
            let n = (at(g.normal[i]) + tilt).normalize();
            // Zones of about 2 to 30 pixels.
            let r = g.normal[i][3] * rng.range(2.0, 30.0);
            record(
                at(g.position[i]),
                n,
                Vec3::new(1.0, 0.5, 0.25),
                r,
                [Vec3::ZERO; 3],
            )
        })
        .collect();
    // Every record splatted into the sum target with `output`; its read-back.
    let splat_all = |output: SplatOutput| -> Vec<[f32; 4]> {
        let mut rec = gpu.ctx.begin("test.splat_bounds").unwrap();
        set_state(&mut rec, &state, &recs, counters(recs.len() as u32, 0));
        let inputs = SplatInputs {
            scene: &gpu.scene,
            gbuffer: &gpu.gbuffer,
            state: &state,
        };
        let draw = SplatDraw {
            output,
            ..SplatDraw::all(&weights)
        };
        splat.record(&mut rec, &inputs, &draw).unwrap();
        gpu.ctx.submit(rec).unwrap().wait().unwrap();
        gpu.ctx.read_image(&splat.sum).unwrap()
    };
    let sums = splat_all(SplatOutput::IrradianceAndCount);
    // The cache phase's coverage splat: the same Σw, no colour.
    let coverage = splat_all(SplatOutput::Coverage);
    for (i, (c, s)) in coverage.iter().zip(&sums).enumerate() {
        assert_eq!(
            c[..3],
            [0.0; 3],
            "pixel {i}: the coverage splat wrote colour"
        );
        assert!(
            (c[3] - s[3]).abs() <= 1e-6 * s[3].max(1.0),
            "pixel {i}: coverage Σw {}, splat Σw {}",
            c[3],
            s[3]
        );
    }
    let (mut reached, mut oblique) = (0, 0);
    for &i in &surface {
        let (p, n) = (at(g.position[i]), at(g.normal[i]));
        let expected: f32 = recs
            .iter()
            .map(|r| {
                let w = cpu_weight(&params, r, p, n, g.normal[i][3]);
                // Records whose plane the view sees at an angle (the camera looks along the z
                // axis), where the frusta's rectangle is much smaller than the ball's box.
                if w > 0.0 && r.normal_rorig[2].abs() < 0.5 {
                    oblique += 1;
                }
                w
            })
            .sum();
        reached += usize::from(expected > 0.0);
        let got = sums[i][3];
        assert!(
            (got - expected).abs() <= 1e-4 * expected.max(1.0),
            "pixel {i}: GPU Σw {got}, CPU {expected}"
        );
    }
    eprintln!(
        "{reached} of {} pixels reached; {oblique} oblique weights",
        surface.len()
    );
    assert!(
        reached > surface.len() / 10,
        "{reached} of {} pixels reached",
        surface.len()
    );
    assert!(oblique > 100, "{oblique} oblique weights");
    drop((splat, state));
    gpu.end();
}

#[test]
fn holes_request_one_record_per_block_and_vanish_when_covered() {
    let f = fixture();
    let shaders = shaders();
    let holes = HolePass::new(&f.ctx, &shaders).unwrap();
    let weights = SplatWeights::from_params(&IcParams::default());
    let spacing = 4;
    // No records: every pixel is a hole, one request per 4×4 block.
    let mut rec = f.ctx.begin("test.holes").unwrap();
    fill_gbuffer(&mut rec, &f.gbuffer);
    set_state(&mut rec, &f.state, &[], counters(0, 0));
    f.splat
        .record(&mut rec, &f.inputs(), &SplatDraw::all(&weights))
        .unwrap();
    holes
        .record(
            &mut rec,
            &f.gbuffer,
            &f.splat,
            &f.state,
            HoleSelection::Request {
                spacing,
                threshold: 0.5,
                seed: 7,
            },
        )
        .unwrap();
    f.state.record_begin_batch(&mut rec).unwrap();
    f.ctx.submit(rec).unwrap().wait().unwrap();
    let c = f.state.read_counters().unwrap();
    assert_eq!(c.holes, W * H, "hole pixels");
    let blocks = W.div_ceil(spacing) * H.div_ceil(spacing);
    assert_eq!(c.requested, blocks, "one request per block");
    assert_eq!(c.dispatch.x, blocks, "record pass dispatch");
    let requests: Vec<u32> = f
        .ctx
        .read_buffer(&f.state.requests, blocks as usize)
        .unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for &r in &requests {
        let (x, y) = (r % W, r / W);
        assert!(r < W * H);
        assert!(
            seen.insert((x / spacing, y / spacing)),
            "two requests in block of {r}"
        );
    }

    // One record covering everything: no holes left.
    let mut rec = f.ctx.begin("test.covered").unwrap();
    let cover = record(P, N, Vec3::ONE, 1.0e9, [Vec3::ZERO; 3]);
    set_state(&mut rec, &f.state, &[cover], counters(1, 0));
    f.state.record_begin_level(&mut rec).unwrap();
    f.splat
        .record(&mut rec, &f.inputs(), &SplatDraw::all(&weights))
        .unwrap();
    holes
        .record(
            &mut rec,
            &f.gbuffer,
            &f.splat,
            &f.state,
            HoleSelection::Request {
                spacing,
                threshold: 0.5,
                seed: 7,
            },
        )
        .unwrap();
    f.ctx.submit(rec).unwrap().wait().unwrap();
    let c = f.state.read_counters().unwrap();
    assert_eq!((c.requested, c.holes), (0, 0), "{c:?}");
    drop(holes);
    end(f);
}

#[test]
fn counters_turn_requests_into_dispatches_within_capacity() {
    let f = fixture();
    let mut rec = f.ctx.begin("test.counters").unwrap();
    f.state.record_reset(&mut rec).unwrap();
    f.ctx.submit(rec).unwrap().wait().unwrap();
    let c = f.state.read_counters().unwrap();
    let counts = [c.record_count, c.requested, c.batch_first, c.holes];
    assert_eq!(counts, [0; 4]);
    assert_eq!([c.record_capacity, c.request_capacity], [64, 1024]);

    // 60 records exist, 10 are requested, room for 4.
    let mut rec = f.ctx.begin("test.batch").unwrap();
    let mut start = counters(60, 60);
    start.requested = 10;
    set_state(&mut rec, &f.state, &[], start);
    f.state.record_begin_batch(&mut rec).unwrap();
    f.state.record_end_batch(&mut rec).unwrap();
    f.ctx.submit(rec).unwrap().wait().unwrap();
    let c = f.state.read_counters().unwrap();
    assert_eq!(c.dispatch.x, 4);
    assert_eq!(c.batch_first, 60, "batch base");
    assert_eq!(c.record_count, 64, "record count");
    assert_eq!(c.draw, DrawArgs::quads(64, 0));
    assert_eq!(c.batch_draw, DrawArgs::quads(4, 60), "the batch's own draw");
    assert_eq!(c.dropped_requests, 6, "dropped requests");
    end(f);
}

#[test]
fn neighbour_clamping_shrinks_radii_to_neighbour_plus_distance() {
    let f = fixture();
    let shaders = shaders();
    let pass = NeighbourPass::new(&f.ctx, &shaders).unwrap();
    // Old record 0 (R 10) far from everything; new records 1 (R 1) and 2 (R 8) two units apart,
    // record 3 (old, R 5) one unit from record 1.
    let recs = [
        record(
            Vec3::new(100.0, 0.0, 0.0),
            N,
            Vec3::ONE,
            10.0,
            [Vec3::ZERO; 3],
        ),
        record(Vec3::ZERO, N, Vec3::ONE, 1.0, [Vec3::ZERO; 3]),
        record(Vec3::new(2.0, 0.0, 0.0), N, Vec3::ONE, 8.0, [Vec3::ZERO; 3]),
        record(Vec3::new(0.0, 1.0, 0.0), N, Vec3::ONE, 5.0, [Vec3::ZERO; 3]),
    ];
    let mut c = counters(4, 1);
    c.dispatch.x = 2; // records 1 and 2 are the new batch
    let mut rec = f.ctx.begin("test.neighbours").unwrap();
    set_state(&mut rec, &f.state, &recs, c);
    pass.record(&mut rec, &f.state, 200.0, NeighbourJob::Rebuild)
        .unwrap();
    pass.record(&mut rec, &f.state, 200.0, NeighbourJob::Batch)
        .unwrap();
    f.ctx.submit(rec).unwrap().wait().unwrap();
    let out: Vec<GpuRecord> = f.ctx.read_buffer(&f.state.records, 4).unwrap();
    let r: Vec<f32> = out.iter().map(|r| r.normal_rorig[3]).collect();
    // Record 0: 10 ≤ 1 + ~100, unchanged. Record 2: min(8, 1 + 2) = 3. Record 3: min(5, 1 + 1) = 2.
    let expected = [10.0, 1.0, 3.0, 2.0];
    for (got, want) in r.iter().zip(expected) {
        assert!(
            (got - want).abs() < 1e-5,
            "radii {r:?}, expected {expected:?}"
        );
    }
    drop(pass);
    end(f);
}
