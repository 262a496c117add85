//! `cargo xtask bench rays`: the device's raw ray-query throughput, the figure later passes are
//! judged against.
//!
//! Scene: a ~100k-triangle sphere BLAS in 4 instances inside a 12-triangle room. Workloads, each
//! `--rays N` rays (default 2M): (a) coherent pinhole-camera rays, closest hit; (b) incoherent
//! cosine-distributed hemisphere rays from random surface points, closest hit. Rays are read from a
//! buffer; one warm-up dispatch, then the median GPU time of 3 timed dispatches. Also reported:
//! BLAS build (+ compaction) and TLAS build times.

use anyhow::{Context as _, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use radcache_tests::geometry::{room, uv_sphere, Mesh};
use radcache_tests::Rng;
use radcache_vk::{
    vk, BindingKind, BindingLayout, BlasGeometry, Buffer, BufferDesc, Context, MemoryLocation,
    Pipeline, Resource, ShaderCompiler, Tlas, TlasInstance, TlasUpdate,
};

use super::harness::{Bench, Figure};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct GpuRay {
    pub(super) origin: [f32; 3],
    pub(super) tmin: f32,
    pub(super) dir: [f32; 3],
    pub(super) tmax: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    count: u32,
    flags: u32,
    row_width: u32,
    pad: u32,
}

/// Invocations per row of the 2-D dispatch (1024 groups of 64).
const ROW: u32 = 65536;

fn rows(m: Mat4) -> [f32; 12] {
    let t = m.transpose().to_cols_array();
    let mut out = [0.0; 12];
    out.copy_from_slice(&t[..12]);
    out
}

struct Scene {
    sphere: Mesh,
    room: Mesh,
    transforms: Vec<Mat4>,
}

fn scene() -> Scene {
    // 2·256·196 = 100,352 triangles.
    let sphere = uv_sphere(1.0, 197, 256);
    let transforms = [(-1.5, -1.5), (1.5, -1.5), (-1.5, 1.5), (1.5, 1.5)]
        .iter()
        .map(|&(x, z)| Mat4::from_translation(Vec3::new(x, 0.0, z)))
        .collect();
    Scene {
        sphere,
        room: room(Vec3::splat(-4.0), Vec3::splat(4.0)),
        transforms,
    }
}

fn camera_rays(n: usize) -> Vec<GpuRay> {
    let width = (n as f64 * 16.0 / 9.0).sqrt().round() as usize;
    let height = n.div_ceil(width);
    let eye = Vec3::new(0.0, 2.5, 3.9);
    let forward = (Vec3::ZERO - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan = (35f32.to_radians()).tan();
    (0..n)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let u =
                ((x as f32 + 0.5) / width as f32 * 2.0 - 1.0) * tan * width as f32 / height as f32;
            let v = (1.0 - (y as f32 + 0.5) / height as f32 * 2.0) * tan;
            let d = (forward + right * u + up * v).normalize();
            GpuRay {
                origin: eye.to_array(),
                tmin: 0.0,
                dir: d.to_array(),
                tmax: 1e30,
            }
        })
        .collect()
}

fn hemisphere_rays(s: &Scene, n: usize) -> Vec<GpuRay> {
    let mut rng = Rng::new(1);
    let sphere_tris = s.sphere.triangle_count() as u32;
    let total = sphere_tris * s.transforms.len() as u32 + s.room.triangle_count() as u32;
    (0..n)
        .map(|_| {
            let k = rng.below(total);
            let tri = if k < sphere_tris * 4 {
                let m = s.transforms[(k / sphere_tris) as usize];
                s.sphere
                    .triangle((k % sphere_tris) as usize)
                    .map(|p| m.transform_point3(p))
            } else {
                s.room.triangle((k - sphere_tris * 4) as usize)
            };
            let (mut a, mut b) = (rng.f32(), rng.f32());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let p = tri[0] + (tri[1] - tri[0]) * a + (tri[2] - tri[0]) * b;
            let nrm = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
            // Cosine-distributed direction about the normal (Malley's method).
            let (r, phi) = (rng.f32().sqrt(), 2.0 * std::f32::consts::PI * rng.f32());
            let (t, bt) = nrm.any_orthonormal_pair();
            let d = (t * r * phi.cos() + bt * r * phi.sin() + nrm * (1.0 - r * r).max(0.0).sqrt())
                .normalize();
            GpuRay {
                origin: (p + nrm * 1e-4).to_array(),
                tmin: 0.0,
                dir: d.to_array(),
                tmax: 1e30,
            }
        })
        .collect()
}

pub(super) fn trace(ctx: &Context, pipe: &Pipeline, tlas: &Tlas, rays: &[GpuRay]) -> Result<f64> {
    let ray_buf =
        ctx.create_buffer_init("bench.rays", vk::BufferUsageFlags::STORAGE_BUFFER, rays)?;
    let hits = Buffer::new(
        ctx,
        &BufferDesc {
            name: "bench.hits",
            size: rays.len() as u64 * 32,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
            alignment: 0,
        },
    )?;
    let n = rays.len() as u32;
    let mut times = Vec::new();
    for run in 0..4 {
        let mut rec = ctx.begin("bench.rays")?;
        rec.pass("bench.trace", |rec| {
            rec.bind_pipeline(pipe);
            rec.push_bindings(&[
                (0, Resource::Tlas(tlas)),
                (1, Resource::Buffer(&ray_buf)),
                (2, Resource::Buffer(&hits)),
            ]);
            rec.push_constants(&Push {
                count: n,
                flags: 0,
                row_width: ROW,
                pad: 0,
            });
            rec.dispatch(ROW / 64, n.div_ceil(ROW), 1)
        })?;
        let t = ctx.submit(rec)?.wait()?;
        if run > 0 {
            times.push(t[0].duration_ms);
        }
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

pub fn run(args: &[&str]) -> Result<()> {
    let n: usize = match args {
        ["--rays", v] => v.parse().context("--rays N")?,
        [] => 2_000_000,
        _ => anyhow::bail!("usage: cargo xtask bench rays [--rays N]"),
    };
    let mut bench = Bench::new("rays")?;
    let info = bench.ctx().info().clone();
    println!("device: {} ({}), {}", info.name, info.kind, info.driver);
    // This benchmark's rows name the driver too.
    bench.set_device_label(format!("{} ({})", info.name, info.driver));
    let m = measure(bench.ctx(), bench.shaders(), n)?;
    let figures = report(&m, n);
    bench.finish(&figures)
}

/// The raw incoherent ray-query rate of `ctx`'s device, rays/s (1M hemisphere rays).
pub fn incoherent_rate(ctx: &Context, compiler: &ShaderCompiler) -> Result<f64> {
    let n = 1_000_000;
    let m = measure(ctx, compiler, n)?;
    Ok(n as f64 / (m.incoherent_ms * 1e-3))
}

struct Measured {
    stats: radcache_vk::BlasBuildStats,
    blas_wall_ms: f64,
    tlas_ms: f64,
    instances: usize,
    tris: usize,
    coherent_ms: f64,
    incoherent_ms: f64,
}

fn measure(ctx: &Context, compiler: &ShaderCompiler, n: usize) -> Result<Measured> {
    let s = scene();
    let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
        | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
    let flat = |m: &Mesh| {
        m.positions
            .iter()
            .map(|p| p.to_array())
            .collect::<Vec<[f32; 3]>>()
    };
    let sv = ctx.create_buffer_init("bench.sphere_vertices", input, &flat(&s.sphere))?;
    let si = ctx.create_buffer_init("bench.sphere_indices", input, &s.sphere.indices)?;
    let rv = ctx.create_buffer_init("bench.room_vertices", input, &flat(&s.room))?;
    let ri = ctx.create_buffer_init("bench.room_indices", input, &s.room.indices)?;
    let geometry = |name, m: &Mesh, vb, ib| BlasGeometry {
        name,
        vertices: vb,
        vertex_offset: 0,
        vertex_stride: 12,
        vertex_count: m.positions.len() as u32,
        indices: ib,
        index_offset: 0,
        triangle_count: m.triangle_count() as u32,
        opaque: true,
    };
    let wall = std::time::Instant::now();
    let (blases, stats) = ctx.build_blases(&[
        geometry("bench.sphere_blas", &s.sphere, &sv, &si),
        geometry("bench.room_blas", &s.room, &rv, &ri),
    ])?;
    let blas_wall_ms = wall.elapsed().as_secs_f64() * 1e3;
    let mut tlas = Tlas::new(ctx, "bench.tlas", 8)?;
    let mut instances: Vec<TlasInstance<'_>> = s
        .transforms
        .iter()
        .enumerate()
        .map(|(i, m)| TlasInstance {
            blas: &blases[0],
            transform: rows(*m),
            custom_index: i as u32,
            mask: 0xff,
        })
        .collect();
    instances.push(TlasInstance {
        blas: &blases[1],
        transform: rows(Mat4::IDENTITY),
        custom_index: 4,
        mask: 0xff,
    });
    let mut rec = ctx.begin("bench.tlas")?;
    rec.build_tlas(ctx, &mut tlas, &instances, TlasUpdate::Rebuild)?;
    let tlas_ms = ctx.submit(rec)?.wait()?[0].duration_ms;

    let spirv = compiler.compile("tests/ray_query.comp", &[])?;
    let bindings = [
        BindingLayout::new(0, BindingKind::AccelerationStructure),
        BindingLayout::new(1, BindingKind::StorageBuffer),
        BindingLayout::new(2, BindingKind::StorageBuffer),
    ];
    let pipe = Pipeline::compute(ctx, "bench.ray_query", &spirv, &bindings, 16)?;
    let coherent_ms = trace(ctx, &pipe, &tlas, &camera_rays(n))?;
    let incoherent_ms = trace(ctx, &pipe, &tlas, &hemisphere_rays(&s, n))?;
    let tris = s.sphere.triangle_count();
    let count = instances.len();
    drop(instances);
    Ok(Measured {
        stats,
        blas_wall_ms,
        tlas_ms,
        instances: count,
        tris,
        coherent_ms,
        incoherent_ms,
    })
}

/// Prints the figures of `m` and returns them.
fn report(m: &Measured, n: usize) -> Vec<Figure> {
    let Measured {
        stats,
        blas_wall_ms,
        tlas_ms,
        instances,
        tris,
        coherent_ms,
        incoherent_ms,
    } = m;
    let (tlas_ms, coherent_ms, incoherent_ms) = (*tlas_ms, *coherent_ms, *incoherent_ms);
    let mrays = |ms: f64| n as f64 / (ms * 1e-3) / 1e6;
    println!(
        "sphere BLAS: {tris} triangles; {} instances + room",
        instances - 1
    );
    println!(
        "BLAS build + compaction: {:.2} ms GPU ({:.2} + {:.2}), {:.1} ms wall; {} -> {} bytes",
        stats.build_ms + stats.compact_ms,
        stats.build_ms,
        stats.compact_ms,
        blas_wall_ms,
        stats.bytes_built,
        stats.bytes_compacted
    );
    println!(
        "TLAS build ({} instances): {:.3} ms GPU",
        instances, tlas_ms
    );
    println!(
        "coherent camera rays:     {n} rays in {coherent_ms:.1} ms = {:.2} Mrays/s",
        mrays(coherent_ms)
    );
    println!(
        "incoherent hemisphere rays: {n} rays in {incoherent_ms:.1} ms = {:.2} Mrays/s",
        mrays(incoherent_ms)
    );
    let case = format!("sphere{}k_x4+room", tris / 1000);
    vec![
        Figure::new(&case, "coherent_mrays_per_s", mrays(coherent_ms), "Mrays/s"),
        Figure::new(
            &case,
            "incoherent_mrays_per_s",
            mrays(incoherent_ms),
            "Mrays/s",
        ),
        Figure::new(&case, "blas_build_ms", stats.build_ms, "ms"),
        Figure::new(&case, "blas_compact_ms", stats.compact_ms, "ms"),
        Figure::new(&case, "tlas_build_ms", tlas_ms, "ms"),
        Figure::new(&case, "rays", n as f64, "rays"),
    ]
}
