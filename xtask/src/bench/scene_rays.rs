//! The raw incoherent ray-query rate on a given scene: the figure a pass tracing that scene is
//! judged against (the rate depends on the scene's size and layout, so the record pass of the
//! Cornell box is compared with raw rays in the Cornell box, not in `bench rays`' 100k-triangle
//! scene). The scene's triangles at t = 0 go into one BLAS; 1M cosine-distributed rays leave
//! random surface points (area-uniform); closest hit; the median GPU time of 3 dispatches.

use anyhow::Result;
use radcache_scene::Scene;
use radcache_tests::Rng;
use radcache_vk::{
    vk, BindingKind, BindingLayout, BlasGeometry, Context, Pipeline, ShaderCompiler, Tlas,
    TlasInstance, TlasUpdate,
};

use super::rays::{trace, GpuRay};

/// Rays per measurement.
const RAYS: usize = 1_000_000;

/// Raw incoherent ray-query rate in `scene`, rays/s.
pub fn incoherent_rate_in(ctx: &Context, compiler: &ShaderCompiler, scene: &Scene) -> Result<f64> {
    let mut tris = Vec::new();
    for (inst, m) in scene.instances.iter().zip(scene.instance_transforms(0.0)) {
        let mesh = &scene.meshes[inst.mesh];
        for t in 0..mesh.triangle_count() {
            let p = mesh.triangle(t).map(|v| m.transform_point3(v));
            if (p[1] - p[0]).cross(p[2] - p[0]).length() > 0.0 {
                tris.push(p);
            }
        }
    }
    anyhow::ensure!(!tris.is_empty(), "the scene has no triangle");
    let positions: Vec<[f32; 3]> = tris.iter().flatten().map(|p| p.to_array()).collect();
    let indices: Vec<u32> = (0..positions.len() as u32).collect();
    let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
        | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
    let vb = ctx.create_buffer_init("bench.scene_vertices", input, &positions)?;
    let ib = ctx.create_buffer_init("bench.scene_indices", input, &indices)?;
    let (blases, _) = ctx.build_blases(&[BlasGeometry {
        name: "bench.scene_blas",
        vertices: &vb,
        vertex_offset: 0,
        vertex_stride: 12,
        vertex_count: positions.len() as u32,
        indices: &ib,
        index_offset: 0,
        triangle_count: tris.len() as u32,
        opaque: true,
    }])?;
    let mut tlas = Tlas::new(ctx, "bench.scene_tlas", 1)?;
    let identity = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let instances = [TlasInstance {
        blas: &blases[0],
        transform: identity,
        custom_index: 0,
        mask: 0xff,
    }];
    let mut rec = ctx.begin("bench.scene_tlas")?;
    rec.build_tlas(ctx, &mut tlas, &instances, TlasUpdate::Rebuild)?;
    ctx.submit(rec)?.wait()?;

    // Area-uniform surface points, cosine-distributed directions about the side facing the
    // scene's centre (so the rays stay inside closed rooms like the Cornell box's).
    let areas: Vec<f32> = tris
        .iter()
        .map(|p| 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length())
        .collect();
    let total: f32 = areas.iter().sum();
    let centre = tris.iter().flatten().copied().sum::<glam::Vec3>() / (3 * tris.len()) as f32;
    let scale = scene_extent(&tris);
    let mut rng = Rng::new(5);
    let rays: Vec<GpuRay> = (0..RAYS)
        .map(|_| {
            let mut pick = rng.f32() * total;
            let mut k = 0;
            while k + 1 < tris.len() && pick >= areas[k] {
                pick -= areas[k];
                k += 1;
            }
            let p = tris[k];
            let (mut a, mut b) = (rng.f32(), rng.f32());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let q = p[0] + (p[1] - p[0]) * a + (p[2] - p[0]) * b;
            let mut n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            if n.dot(centre - q) < 0.0 {
                n = -n;
            }
            let (r, phi) = (rng.f32().sqrt(), std::f32::consts::TAU * rng.f32());
            let (t, bt) = n.any_orthonormal_pair();
            let d = (t * r * phi.cos() + bt * r * phi.sin() + n * (1.0 - r * r).max(0.0).sqrt())
                .normalize();
            GpuRay {
                origin: (q + n * 1e-5 * scale).to_array(),
                tmin: 0.0,
                dir: d.to_array(),
                tmax: 1e30,
            }
        })
        .collect();
    let spirv = compiler.compile("tests/ray_query.comp", &[])?;
    let bindings = [
        BindingLayout::new(0, BindingKind::AccelerationStructure),
        BindingLayout::new(1, BindingKind::StorageBuffer),
        BindingLayout::new(2, BindingKind::StorageBuffer),
    ];
    let pipe = Pipeline::compute(ctx, "bench.scene_ray_query", &spirv, &bindings, 16)?;
    let ms = trace(ctx, &pipe, &tlas, &rays)?;
    Ok(RAYS as f64 / (ms * 1e-3))
}

fn scene_extent(tris: &[[glam::Vec3; 3]]) -> f32 {
    let (mut lo, mut hi) = (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN));
    for p in tris.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (hi - lo).length()
}
