//! Shared fixture of the record pass's tests (`tests/tests/ic_records.rs`,
//! `tests/tests/radiance_records.rs`): a G-buffer written point by point
//! (`shaders/tests/gbuffer_fill.comp`; positions and normals computed on the CPU), the cache state,
//! the scene's world triangles for CPU ray casting, and one record dispatch with its sample dump.

use bytemuck::Zeroable;
use glam::Vec3;
use radcache_cache::radius::pixel_footprint;
use radcache_cache::sampling::{
    basis_from_normal, frame_to_world, normalize_or_z, stratum_direction_local, stratum_jitter,
};
use radcache_render::{
    passes::gbuffer::GBuffer, passes::record::record_seed, passes::record::RadianceBlocks,
    passes::record::RecordInputs, passes::record::RecordJob, passes::record::RecordOutputs,
    passes::record::RecordPass, passes::record::WithRadiance, passes::record::R_EPS_REL,
    state::IcStateDesc, GpuScene, IcState,
};
use radcache_scene::Scene;
use radcache_shared::gpu::{DispatchArgs, DrawArgs, GpuRecord, IcCounters};
use radcache_vk::{vk, Buffer, Context, Pipeline, Recorder, ShaderCompiler};

use crate::geometry::intersect;
use crate::ic_fixture::{fill_gbuffer_points, gbuffer_fill_pipeline, GbufferPoint};
use crate::{context, finish, shaders};

pub const W: u32 = 32;
pub const H: u32 = 32;
/// Record slots the tests look at (the pass must leave the others alone).
pub const SLOTS: usize = 16;

pub fn point(x: u32, y: u32, p: Vec3, n: Vec3) -> GbufferPoint {
    let mut q = GbufferPoint::zeroed();
    (q.pixel, q.p, q.n, q.ng, q.footprint) = ([x, y, 0, 0], p, n, n, 0.01);
    q
}

pub fn point_index(q: &GbufferPoint) -> u32 {
    q.pixel[1] * W + q.pixel[0]
}

pub struct Fixture {
    pub ctx: Context,
    pub shaders: ShaderCompiler,
    pub gpu: GpuScene,
    pub gbuffer: GBuffer,
    pub state: IcState,
    pub fill: Pipeline,
    pub tris: Vec<[Vec3; 3]>,
    pub r_eps: f32,
}

impl std::fmt::Debug for Fixture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fixture")
            .field("r_eps", &self.r_eps)
            .finish_non_exhaustive()
    }
}

pub fn fixture(scene: &Scene) -> Fixture {
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, scene, None).unwrap();
    gpu.set_time(scene, 0.0).unwrap();
    gpu.set_view(&scene.camera_at(0.0), W, H, 0, 0).unwrap();
    let mut tris = Vec::new();
    for (inst, m) in scene.instances.iter().zip(scene.instance_transforms(0.0)) {
        let mesh = &scene.meshes[inst.mesh];
        let world = |t| mesh.triangle(t).map(|p| m.transform_point3(p));
        tris.extend((0..mesh.triangle_count()).map(world));
    }
    Fixture {
        fill: gbuffer_fill_pipeline(&ctx, &shaders),
        gbuffer: GBuffer::new(&ctx, W, H).unwrap(),
        state: IcState::new(&ctx, &shaders, &IcStateDesc::new(64, 64)).unwrap(),
        r_eps: R_EPS_REL * gpu.constants().camera_position[3],
        tris,
        gpu,
        shaders,
        ctx,
    }
}

pub fn end(f: Fixture) {
    drop((f.gpu, f.gbuffer, f.state, f.fill));
    finish(f.ctx);
}

/// What one dispatch left behind.
#[derive(Debug)]
pub struct Run {
    pub records: Vec<GpuRecord>,
    /// The radiance buffer after the dispatch (empty without one).
    pub radiance: Vec<[f32; 4]>,
    pub samples: Vec<[f32; 4]>,
    pub counters: IcCounters,
    pub rays: u64,
}

/// A value the pass never writes, in every record slot before a dispatch.
pub fn sentinel() -> GpuRecord {
    bytemuck::cast([0xdead_beef_u32; 44])
}

/// One batch: `requests` over a G-buffer holding `points` (every other pixel is background),
/// with `counters` as given.
#[derive(Debug, Clone, Copy)]
pub struct Batch<'a> {
    /// The G-buffer's points.
    pub points: &'a [GbufferPoint],
    /// The requests (pixel indices).
    pub requests: &'a [u32],
    /// The counters before the dispatch.
    pub counters: IcCounters,
}

impl<'a> Batch<'a> {
    pub fn new(points: &'a [GbufferPoint], requests: &'a [u32], counters: IcCounters) -> Self {
        Batch {
            points,
            requests,
            counters,
        }
    }
}

/// Records created at `level` and `sub_frame` with the pass seed `seed`.
pub fn create(seed: u32, level: u32, sub_frame: u32) -> RecordJob {
    RecordJob::Create {
        level,
        sub_frame,
        seed,
    }
}

/// Runs `job` over `batch` with a pass made with radiance blocks, dumping the strata's samples,
/// the blocks into `radiance`.
pub fn run_with_radiance(
    f: &mut Fixture,
    pass: &RecordPass<WithRadiance>,
    batch: &Batch<'_>,
    job: RecordJob,
    radiance: &Buffer,
) -> Run {
    run_pass(
        f,
        pass,
        batch,
        job,
        Some(radiance),
        |rec, inputs, records, samples| {
            let outputs = RecordOutputs {
                samples: Some(samples),
                ..RecordOutputs::with_radiance(records, radiance)
            };
            pass.record(rec, inputs, &outputs).unwrap();
        },
    )
}

/// [`run_with_radiance`] for a pass without radiance coefficients.
pub fn run(f: &mut Fixture, pass: &RecordPass, batch: &Batch<'_>, job: RecordJob) -> Run {
    run_pass(
        f,
        pass,
        batch,
        job,
        None,
        |rec, inputs, records, samples| {
            let outputs = RecordOutputs {
                samples: Some(samples),
                ..RecordOutputs::records(records)
            };
            pass.record(rec, inputs, &outputs).unwrap();
        },
    )
}

/// Runs `job` over `batch`: `record` records `pass` with the inputs into the records and the
/// sample dump; `radiance` is read back.
fn run_pass<R: RadianceBlocks>(
    f: &mut Fixture,
    pass: &RecordPass<R>,
    batch: &Batch<'_>,
    job: RecordJob,
    radiance: Option<&Buffer>,
    record: impl FnOnce(&mut Recorder, &RecordInputs<'_>, &Buffer, &Buffer),
) -> Run {
    let Batch {
        points,
        requests,
        counters,
    } = *batch;
    let per = pass.params().sample_count() as usize;
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let zeros = vec![[0.0f32; 4]; requests.len() * per];
    let samples = f.ctx.create_buffer_init("test.samples", storage, &zeros);
    let texels = f.ctx.create_buffer_init("test.texels", storage, points);
    let (samples, texels) = (samples.unwrap(), texels.unwrap());
    let (g, st) = (&f.gbuffer, &f.state);
    let mut rec = f.ctx.begin("test.records").unwrap();
    f.gpu.record_update(&f.ctx, &mut rec).unwrap();
    fill_gbuffer_points(&mut rec, &f.fill, g, &texels, points.len() as u32);
    rec.update_buffer(&st.requests, 0, requests);
    rec.update_buffer(&st.counters, 0, &[counters]);
    rec.update_buffer(&st.records, 0, &[sentinel(); SLOTS]);
    let inputs = RecordInputs {
        scene: &f.gpu,
        gbuffer: g,
        requests: &st.requests,
        counters: &st.counters,
        job,
    };
    record(&mut rec, &inputs, &st.records, &samples);
    let timings = f.ctx.submit(rec).unwrap().wait().unwrap();
    assert!(timings.iter().any(|t| t.name == "records"), "no scope");
    Run {
        records: f.ctx.read_buffer(&st.records, SLOTS).unwrap(),
        samples: f.ctx.read_buffer(&samples, zeros.len()).unwrap(),
        counters: st.read_counters().unwrap(),
        rays: pass.rays().unwrap(),
        radiance: radiance.map(|b| read_all(&f.ctx, b)).unwrap_or_default(),
    }
}

/// Every vec4 of `buffer`.
fn read_all(ctx: &Context, buffer: &Buffer) -> Vec<[f32; 4]> {
    ctx.read_buffer(buffer, (buffer.size() / 16) as usize)
        .unwrap()
}

pub fn counters(base: u32, requests: u32, groups: u32, capacity: u32) -> IcCounters {
    IcCounters {
        record_count: base,
        requested: requests,
        batch_first: base,
        dispatch: DispatchArgs::groups(groups),
        draw: DrawArgs::quads(base, 0),
        ..IcCounters::reset(capacity, 64)
    }
}

/// The first surface hit through the centre of pixel `(x, y)`, computed on the CPU.
pub fn surface_at_pixel(f: &Fixture, scene: &Scene, x: u32, y: u32) -> GbufferPoint {
    let view = scene.camera_at(0.0);
    let tan_half = (view.perspective.yfov * 0.5).tan();
    let sx = ((x as f32 + 0.5) / W as f32 * 2.0 - 1.0) * tan_half * W as f32 / H as f32;
    let sy = (1.0 - (y as f32 + 0.5) / H as f32 * 2.0) * tan_half;
    let d = (view.forward + view.right * sx + view.up * sy).normalize();
    let o = view.position;
    let hits = f.tris.iter().filter_map(|tri| {
        let hit = intersect(o.as_dvec3(), d.as_dvec3(), *tri, 0.0);
        hit.filter(|h| h.t > 0.0).map(|h| (h.t, tri))
    });
    let (t, tri) = hits.min_by(|a, b| a.0.total_cmp(&b.0)).expect("a surface");
    let ng = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
    let ng = if ng.dot(d) > 0.0 { -ng } else { ng };
    let p = (o.as_dvec3() + d.as_dvec3() * t).as_vec3();
    let mut q = point(x, y, p, ng);
    let depth = t as f32 * d.dot(view.forward);
    q.footprint = pixel_footprint(depth, tan_half, H as f32, ng.dot(-d));
    q
}

/// The gather direction of stratum `i` as the pass must generate it, and whether it was folded.
pub fn direction(q: &GbufferPoint, m: u32, n: u32, seed: u32, i: u32) -> (Vec3, bool) {
    let nn = normalize_or_z(q.n);
    let (t, b) = basis_from_normal(nn);
    let (xi, psi) = stratum_jitter(record_seed(point_index(q), seed), i);
    let local = stratum_direction_local(i / n, i % n, m, n, xi, psi);
    let d = frame_to_world(local, t, b, nn);
    let below = d.dot(q.ng);
    let folded = (d - 2.0 * below * q.ng).normalize();
    (if below <= 0.0 { folded } else { d }, below <= 0.0)
}
