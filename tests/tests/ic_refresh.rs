//! Refreshing records in place (temporal caching, docs/temporal.md §3.5 and
//! docs/irradiance-cache.md §2.3) on lavapipe: a record computed again at its own point with its
//! own seeds reproduces its irradiance and gradients bit for bit under unchanged lighting; with
//! another frame seed it draws other samples (the comparison can fail) and stays within noise.

use radcache_cache::IcParams;
use radcache_render::{
    passes::gbuffer::GBuffer, passes::record::RecordInputs, passes::record::RecordJob,
    passes::record::RecordOutputs, passes::record::RecordPass, passes::record::RecordVariant,
    GpuScene, IcRenderer, IcSettings, PathGridMode, SplatMode,
};
use radcache_shared::gpu::{DispatchArgs, GpuRecord, IcCounters};
use radcache_tests::scenes::load;
use radcache_tests::{context, finish, shaders};
use radcache_vk::Context;

const SIZE: u32 = 48;
const SEED: u32 = 5;

fn refresh(
    ctx: &Context,
    pass: &RecordPass,
    gpu: &GpuScene,
    gbuffer: &GBuffer,
    r: &IcRenderer,
    which: &[u32],
    seed: u32,
) -> Vec<GpuRecord> {
    let state = r.state();
    let mut c: IcCounters = state.read_counters().unwrap();
    let count = c.record_count as usize;
    c.requested = which.len() as u32;
    c.dispatch = DispatchArgs::groups(which.len() as u32);
    let mut rec = ctx.begin("test.refresh").unwrap();
    rec.update_buffer(&state.requests, 0, which);
    rec.update_buffer(&state.counters, 0, std::slice::from_ref(&c));
    let inputs = RecordInputs {
        scene: gpu,
        gbuffer,
        requests: &state.requests,
        counters: &state.counters,
        job: RecordJob::Refresh { frame_seed: seed },
    };
    pass.record(&mut rec, &inputs, &RecordOutputs::records(&state.records))
        .unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    ctx.read_buffer(&state.records, count).unwrap()
}

fn values(r: &GpuRecord) -> Vec<[f32; 4]> {
    vec![
        r.irradiance,
        r.grad_r_red,
        r.grad_r_green,
        r.grad_r_blue,
        r.grad_t_red,
        r.grad_t_green,
        r.grad_t_blue,
    ]
}

#[test]
fn a_refreshed_record_reproduces_its_value() {
    let scene = load(&std::path::PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/cornell/cornell.gltf"
    )));
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let settings = IcSettings {
        width: SIZE,
        height: SIZE,
        params: IcParams::draft(),
        sub_frames: 2,
        direct_samples: 2,
        seed: SEED,
        // Holes filled at both sub-frames' jitters, so that records carry either seed.
        splat: SplatMode::PerSubFrame,
        // Full gather paths (`--set path_grid=off`): with the radiance grid a record's value also
        // depends on the cells other paths filled, and a refresh reproduces it only to within
        // their noise (docs/temporal.md §3.5, §3.8; tests/ic_path_grid_frames.rs).
        path_grid: PathGridMode::Off,
        ..IcSettings::default()
    };
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &settings).unwrap();
    let (_, stats) = r
        .render(&ctx, &scene, &mut gpu, &settings, &mut |_| {})
        .unwrap();
    let before: Vec<GpuRecord> = ctx
        .read_buffer(&r.state().records, stats.records as usize)
        .unwrap();
    // Records of both sub-frames and several levels.
    let which: Vec<u32> = (0..stats.records as u32).step_by(5).collect();
    assert!(which.len() > 20);
    assert!(
        which.iter().any(|&i| before[i as usize].info[2] == 1),
        "no sub-frame 1 record"
    );
    let pass = RecordPass::new(
        &ctx,
        &shaders,
        &gpu,
        &RecordVariant::new(settings.params, settings.sky),
    )
    .unwrap();
    let gbuffer = GBuffer::new(&ctx, SIZE, SIZE).unwrap();

    let same = refresh(&ctx, &pass, &gpu, &gbuffer, &r, &which, SEED);
    for (k, (a, b)) in before.iter().zip(&same).enumerate() {
        assert_eq!(values(a), values(b), "record {k}");
        assert_eq!(a.position_radius[..3], b.position_radius[..3]);
        assert_eq!(a.normal_rorig[..3], b.normal_rorig[..3]);
        assert_eq!(a.info, b.info);
    }

    // Another frame seed: other samples, the same expectation.
    let other = refresh(&ctx, &pass, &gpu, &gbuffer, &r, &which, SEED + 1);
    let (mut changed, mut sum_a, mut sum_b) = (0, 0.0f64, 0.0f64);
    for &i in &which {
        let (a, b) = (&same[i as usize], &other[i as usize]);
        if a.irradiance != b.irradiance {
            changed += 1;
        }
        sum_a += f64::from(a.irradiance[1]);
        sum_b += f64::from(b.irradiance[1]);
    }
    assert!(
        changed * 10 >= which.len() * 9,
        "{changed} of {} changed",
        which.len()
    );
    assert!(
        (sum_a - sum_b).abs() <= 0.05 * sum_a,
        "mean irradiance {sum_a} vs {sum_b}"
    );
    drop((pass, gbuffer, r, gpu));
    finish(ctx);
}
