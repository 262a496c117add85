//! Ray queries against a BLAS/TLAS agree with a CPU ray–triangle reference.
//!
//! Two instances of a few-thousand-triangle sphere with different transforms; 10,000 random rays
//! traced with `rayQueryEXT` in a compute shader; hit/miss, primitive id, instance id and custom
//! index must match, and the distance within 1e-4 relative. A ray that grazes an edge shared by two
//! triangles may legitimately report either one; such rays are accepted only when both sides
//! agree on the distance and the reference hit lies within 1e-5 (barycentric) of an edge.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Quat, Vec3};
use radcache_tests::geometry::{intersect, uv_sphere, Mesh, TriHit};
use radcache_tests::{context, finish, shaders, Rng};
use radcache_vk::{
    vk, BindingKind, BindingLayout, BlasGeometry, Buffer, BufferDesc, MemoryLocation, Pipeline,
    Resource, Tlas, TlasInstance, TlasUpdate,
};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
struct GpuRay {
    origin: [f32; 3],
    tmin: f32,
    dir: [f32; 3],
    tmax: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
struct GpuHit {
    t: f32,
    primitive: i32,
    instance: i32,
    custom_index: i32,
    barycentrics: [f32; 2],
    hit: u32,
    pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Push {
    count: u32,
    flags: u32,
    row_width: u32,
    pad: u32,
}

/// Row-major 3×4 of an affine matrix, as the TLAS wants it.
fn rows(m: Mat4) -> [f32; 12] {
    let t = m.transpose().to_cols_array();
    let mut out = [0.0; 12];
    out.copy_from_slice(&t[..12]);
    out
}

struct CpuHit {
    hit: TriHit,
    instance: usize,
    primitive: usize,
}

/// World-space triangles of every instance: `world[instance][primitive]`.
fn world_triangles(mesh: &Mesh, transforms: &[Mat4]) -> Vec<Vec<[Vec3; 3]>> {
    transforms
        .iter()
        .map(|m| {
            (0..mesh.triangle_count())
                .map(|t| mesh.triangle(t).map(|p| m.transform_point3(p)))
                .collect()
        })
        .collect()
}

fn cpu_closest(
    world: &[Vec<[Vec3; 3]>],
    o: Vec3,
    d: Vec3,
    tmax: f64,
    slack: f64,
) -> Option<CpuHit> {
    let mut best: Option<CpuHit> = None;
    for (instance, tris) in world.iter().enumerate() {
        for (primitive, tri) in tris.iter().enumerate() {
            if let Some(hit) = intersect(o.as_dvec3(), d.as_dvec3(), *tri, slack) {
                if hit.t >= 0.0 && hit.t <= tmax && best.as_ref().is_none_or(|b| hit.t < b.hit.t) {
                    best = Some(CpuHit {
                        hit,
                        instance,
                        primitive,
                    });
                }
            }
        }
    }
    best
}

#[test]
fn ray_queries_match_cpu_reference() {
    let ctx = context();
    let compiler = shaders();
    let mesh = uv_sphere(1.0, 40, 64); // 2·64·39 = 4992 triangles
    assert!(mesh.triangle_count() > 4000);
    let transforms = [
        Mat4::from_scale_rotation_translation(
            Vec3::splat(1.0),
            Quat::from_rotation_y(0.3),
            Vec3::new(-1.5, 0.0, 0.0),
        ),
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.7, 1.2, 0.9),
            Quat::from_rotation_x(0.8),
            Vec3::new(1.4, 0.3, -0.2),
        ),
    ];
    let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
        | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
    let vbuf = ctx
        .create_buffer_init("test.vertices", input, &positions)
        .unwrap();
    let ibuf = ctx
        .create_buffer_init("test.indices", input, &mesh.indices)
        .unwrap();
    let (blases, stats) = ctx
        .build_blases(&[BlasGeometry {
            name: "test.sphere_blas",
            vertices: &vbuf,
            vertex_offset: 0,
            vertex_stride: 12,
            vertex_count: mesh.positions.len() as u32,
            indices: &ibuf,
            index_offset: 0,
            triangle_count: mesh.triangle_count() as u32,
            opaque: true,
        }])
        .unwrap();
    assert!(
        stats.bytes_compacted > 0 && stats.bytes_compacted <= stats.bytes_built,
        "{stats:?}"
    );
    let mut tlas = Tlas::new(&ctx, "test.tlas", 4).unwrap();
    let instances: Vec<TlasInstance<'_>> = transforms
        .iter()
        .enumerate()
        .map(|(i, m)| TlasInstance {
            blas: &blases[0],
            transform: rows(*m),
            custom_index: 100 + i as u32,
            mask: 0xff,
        })
        .collect();

    // Rays: origins in a box around both spheres, aimed at random points near them (most hit,
    // some miss); a few with a short tmax that must stop before the surface.
    let mut rng = Rng::new(7);
    let n = 10_000usize;
    let rays: Vec<GpuRay> = (0..n)
        .map(|i| {
            let o = Vec3::new(
                rng.range(-4.0, 4.0),
                rng.range(-3.0, 3.0),
                rng.range(3.0, 5.0),
            ) * if i % 2 == 0 { 1.0 } else { -1.0 };
            let target = Vec3::new(
                rng.range(-3.0, 3.0),
                rng.range(-1.6, 1.6),
                rng.range(-1.2, 1.2),
            );
            let d = (target - o).normalize();
            let tmax = if i % 10 == 0 {
                rng.range(0.5, 6.0)
            } else {
                1.0e30
            };
            GpuRay {
                origin: o.to_array(),
                tmin: 0.0,
                dir: d.to_array(),
                tmax,
            }
        })
        .collect();
    let ray_buf = ctx
        .create_buffer_init("test.rays", vk::BufferUsageFlags::STORAGE_BUFFER, &rays)
        .unwrap();
    let hit_buf = Buffer::new(
        &ctx,
        &BufferDesc {
            name: "test.hits",
            size: (n * std::mem::size_of::<GpuHit>()) as u64,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
            alignment: 0,
        },
    )
    .unwrap();
    let spirv = compiler.compile("tests/ray_query.comp", &[]).unwrap();
    let bindings = [
        BindingLayout::new(0, BindingKind::AccelerationStructure),
        BindingLayout::new(1, BindingKind::StorageBuffer),
        BindingLayout::new(2, BindingKind::StorageBuffer),
    ];
    let pipeline = Pipeline::compute(&ctx, "test.ray_query", &spirv, &bindings, 16).unwrap();

    let mut rec = ctx.begin("test").unwrap();
    rec.build_tlas(&ctx, &mut tlas, &instances, TlasUpdate::Rebuild)
        .unwrap();
    rec.pass("test.trace", |rec| {
        rec.bind_pipeline(&pipeline);
        rec.push_bindings(&[
            (0, Resource::Tlas(&tlas)),
            (1, Resource::Buffer(&ray_buf)),
            (2, Resource::Buffer(&hit_buf)),
        ]);
        rec.push_constants(&Push {
            count: n as u32,
            flags: 0,
            row_width: n as u32,
            pad: 0,
        });
        rec.dispatch((n as u32).div_ceil(64), 1, 1).unwrap();
    });
    let timings = ctx.submit(rec).unwrap().wait().unwrap();
    let names: Vec<&str> = timings.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["accel.tlas_build", "test.trace"]);
    let hits: Vec<GpuHit> = ctx.read_buffer(&hit_buf, n).unwrap();

    let world = world_triangles(&mesh, &transforms);
    let (mut hit_count, mut edge_cases) = (0, 0);
    for (i, (ray, gpu)) in rays.iter().zip(&hits).enumerate() {
        let o = Vec3::from_array(ray.origin);
        let d = Vec3::from_array(ray.dir);
        let tmax = f64::from(ray.tmax);
        let cpu = cpu_closest(&world, o, d, tmax, 0.0);
        let agree = match (&cpu, gpu.hit) {
            (None, 0) => true,
            (Some(c), 1) => {
                let rel = (f64::from(gpu.t) - c.hit.t).abs() / c.hit.t.max(1e-6);
                hit_count += 1;
                rel <= 1e-4
                    && gpu.instance == c.instance as i32
                    && gpu.custom_index == 100 + c.instance as i32
                    && gpu.primitive == c.primitive as i32
            }
            _ => false,
        };
        if agree {
            continue;
        }
        // Disagreement is only acceptable on an edge (or at the silhouette / tmax boundary):
        // the slack reference must explain the GPU's answer at the same distance.
        let slack = cpu_closest(&world, o, d, tmax, 1e-5);
        let explained = match (gpu.hit, &slack) {
            (1, Some(s)) => {
                let tri = world[gpu.instance as usize][gpu.primitive as usize];
                let own = intersect(o.as_dvec3(), d.as_dvec3(), tri, 1e-5);
                own.is_some_and(|h| {
                    (h.t - s.hit.t).abs() <= 1e-4 * s.hit.t && h.edge_distance() < 1e-5
                }) || s.hit.edge_distance() < 1e-5
            }
            (0, Some(s)) => s.hit.edge_distance() < 1e-5 || (s.hit.t - tmax).abs() <= 1e-4 * tmax,
            _ => false,
        };
        assert!(
            explained,
            "ray {i}: GPU {gpu:?} vs CPU {:?}",
            cpu.map(|c| (c.hit, c.instance, c.primitive))
        );
        edge_cases += 1;
    }
    assert!(
        hit_count > n / 3,
        "only {hit_count} hits: the test rays mostly miss"
    );
    assert!(edge_cases <= n / 1000, "{edge_cases} edge cases");
    drop(instances);
    drop((pipeline, hit_buf, ray_buf, tlas, blases, vbuf, ibuf));
    finish(ctx);
}
