//! Shared fixture of the cache's per-pixel pass tests (`tests/tests/ic_gbuffer.rs`,
//! `tests/tests/ic_direct.rs`): a scene on the GPU with its G-buffer, the scene's world-space
//! triangles for CPU ray casting, and comparison helpers.

use glam::{DVec3, Mat3, Quat, Vec3};
use radcache_render::{
    passes::direct::DirectImage, passes::direct::DirectInputs, passes::direct::DirectPass,
    passes::gbuffer::GBuffer, passes::gbuffer::GBufferPass, passes::gbuffer::GBufferVariant,
    EnvMap, GpuScene,
};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::Scene;
use radcache_vk::{Context, PassTiming, ShaderCompiler};

use crate::geometry::intersect;
use crate::scenes::{camera_node, load, temp_dir, write_and_load};
use crate::{context, finish, shaders};

pub type Px = [f32; 4];

/// A world-space triangle of the scene: corners, vertex normals (world, unnormalised), unit
/// front normal (glTF: counter-clockwise, reversed by mirroring transforms), material, instance.
#[derive(Debug)]
pub struct Tri {
    pub p: [Vec3; 3],
    pub n: [Vec3; 3],
    pub front: DVec3,
    pub material: u32,
    pub mirrored: bool,
}

pub fn world_triangles(scene: &Scene) -> Vec<Tri> {
    let mut out = Vec::new();
    for (inst, m) in scene.instances.iter().zip(scene.instance_transforms(0.0)) {
        let mesh = &scene.meshes[inst.mesh];
        let normal_m = Mat3::from_mat4(m).inverse().transpose();
        let mirrored = m.determinant() < 0.0;
        for t in 0..mesh.triangle_count() {
            let p = mesh.triangle(t).map(|v| m.transform_point3(v));
            let idx = &mesh.indices[3 * t..3 * t + 3];
            let n = [0, 1, 2].map(|k| normal_m * mesh.normals[idx[k] as usize]);
            let cross = (p[1] - p[0]).as_dvec3().cross((p[2] - p[0]).as_dvec3());
            let front = cross.normalize() * if mirrored { -1.0 } else { 1.0 };
            let material = mesh.triangle_materials[t];
            out.push(Tri {
                p,
                n,
                front,
                material,
                mirrored,
            });
        }
    }
    out
}

/// The nearest hit along a ray (t > 0, up to `t_max`): distance, triangle, barycentrics.
pub fn cast(tris: &[Tri], o: DVec3, d: DVec3, t_max: f64) -> Option<(f64, usize, f64, f64)> {
    tris.iter()
        .enumerate()
        .filter_map(|(i, tri)| intersect(o, d, tri.p, 0.0).map(|h| (h.t, i, h.u, h.v)))
        .filter(|h| h.0 > 1e-9 && h.0 < t_max)
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// A context, the scene on the GPU with the view set, a G-buffer and its pass.
pub struct Gpu {
    pub ctx: Context,
    pub shaders: ShaderCompiler,
    pub scene: GpuScene,
    pub gbuffer: GBuffer,
    pub pass: GBufferPass,
    pub size: (u32, u32),
}

/// The G-buffer read back, one vector per image.
#[derive(Debug)]
pub struct GRead {
    pub position: Vec<Px>,
    pub normal: Vec<Px>,
    pub geometric: Vec<Px>,
    pub albedo: Vec<Px>,
    pub emission: Vec<Px>,
}

pub fn names(timings: &[PassTiming]) -> Vec<String> {
    timings.iter().map(|t| t.name.clone()).collect()
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu")
            .field("size", &self.size)
            .finish_non_exhaustive()
    }
}

impl Gpu {
    pub fn new(scene: &Scene, env: Option<&EnvMap>, size: (u32, u32)) -> Gpu {
        Self::with_gbuffer(scene, env, size, None)
    }

    /// As [`Gpu::new`], the G-buffer traced (`Some(true)`) or rasterized (`Some(false)`)
    /// whatever the scene's plan says (`None`: as it says).
    pub fn with_gbuffer(
        scene: &Scene,
        env: Option<&EnvMap>,
        size: (u32, u32),
        traced: Option<bool>,
    ) -> Gpu {
        let ctx = context();
        let shaders = shaders();
        let mut gpu = GpuScene::new(&ctx, scene, env).unwrap();
        gpu.set_time(scene, 0.0).unwrap();
        gpu.set_view(&scene.camera_at(0.0), size.0, size.1, 1, 0)
            .unwrap();
        let mut rec = ctx.begin("test.tlas").unwrap();
        gpu.record_update(&ctx, &mut rec).unwrap();
        ctx.submit(rec).unwrap().wait().unwrap();
        let gbuffer = GBuffer::new(&ctx, size.0, size.1).unwrap();
        let variant = match traced {
            None => GBufferVariant::planned(gpu.plan()),
            Some(true) => GBufferVariant::Traced,
            Some(false) => GBufferVariant::Rasterized,
        };
        let pass = GBufferPass::new(&ctx, &shaders, &gpu, variant).unwrap();
        Gpu {
            ctx,
            shaders,
            scene: gpu,
            gbuffer,
            pass,
            size,
        }
    }

    /// Renders the G-buffer with `jitter` (and runs `direct` after it, when given).
    pub fn render(&self, jitter: [f32; 2], direct: Option<(&DirectPass, u32, u32)>) -> Vec<String> {
        let mut rec = self.ctx.begin("test.gbuffer").unwrap();
        self.pass
            .record(&mut rec, &self.scene, &self.gbuffer, jitter)
            .unwrap();
        if let Some((pass, samples, seed)) = direct {
            let inputs = DirectInputs {
                scene: &self.scene,
                gbuffer: &self.gbuffer,
                samples,
                sub_frame: 0,
                seed,
                glossy: None,
            };
            pass.record(&mut rec, &inputs, &DirectImage).unwrap();
        }
        names(&self.ctx.submit(rec).unwrap().wait().unwrap())
    }

    /// Runs `direct` alone on the G-buffer as it is, for sub-frame `sub_frame` of `seed`, and
    /// returns its direct image and its ray count.
    pub fn direct(
        &self,
        direct: &DirectPass,
        samples: u32,
        sub_frame: u32,
        seed: u32,
    ) -> (Vec<Px>, u64) {
        let mut rec = self.ctx.begin("test.direct").unwrap();
        // A read-back leaves the images in transfer layouts.
        let inputs = DirectInputs {
            scene: &self.scene,
            gbuffer: &self.gbuffer,
            samples,
            sub_frame,
            seed,
            glossy: None,
        };
        direct.record(&mut rec, &inputs, &DirectImage).unwrap();
        self.ctx.submit(rec).unwrap().wait().unwrap();
        (self.read(&self.gbuffer.direct), direct.rays().unwrap())
    }

    pub fn read(&self, image: &radcache_vk::Image) -> Vec<Px> {
        self.ctx.read_image(image).unwrap()
    }

    pub fn read_gbuffer(&self) -> GRead {
        let g = &self.gbuffer;
        GRead {
            position: self.read(&g.position),
            normal: self.read(&g.normal),
            geometric: self.read(&g.geometric),
            albedo: self.read(&g.albedo),
            emission: self.read(&g.emission),
        }
    }

    pub fn end(self) {
        let Gpu {
            ctx,
            scene,
            gbuffer,
            pass,
            ..
        } = self;
        drop((scene, gbuffer, pass));
        finish(ctx);
    }
}

pub fn cornell() -> Scene {
    load(
        &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/cornell/cornell.gltf"),
    )
}

pub fn xyz(v: Px) -> DVec3 {
    DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
}

pub fn close(what: &str, pixel: usize, gpu: DVec3, cpu: DVec3, tol: f64) {
    assert!(
        (gpu - cpu).abs().max_element() <= tol,
        "pixel {pixel} {what}: GPU {gpu}, CPU {cpu}"
    );
}

/// A square in the XY plane of half-size `s`, facing +Z (or −Z) with the given vertex normals.
pub fn quad(s: f32, facing_z: bool, normals: [[f32; 3]; 4], material: usize) -> PrimitiveDesc {
    let p = vec![[-s, -s, 0.0], [s, -s, 0.0], [s, s, 0.0], [-s, s, 0.0]];
    let normals = normals.map(|n| Vec3::from(n).normalize().to_array());
    let idx = if facing_z {
        vec![0, 1, 2, 0, 2, 3]
    } else {
        vec![0, 2, 1, 0, 3, 2]
    };
    PrimitiveDesc::triangles(p, Some(normals.to_vec()), idx, Some(material))
}

/// Six squares in front of a wall, seen by a camera at (0, 0, 3) looking down −Z: an emitter
/// facing the camera, one facing away, a double-sided one facing away, both single-sided ones
/// mirrored (scale −1 in x), a diffuse one with tilted vertex normals and one with inward normals;
/// a large square behind the camera must not appear. The sides of the image are background.
pub fn faces_scene() -> Scene {
    let mut b = GltfBuilder::new();
    let white = b.add_material(&MaterialDesc::diffuse("white", [0.7, 0.6, 0.5]));
    let single = b.add_material(&MaterialDesc::emitter(
        "single",
        [0.2, 0.3, 0.4],
        [1.0, 2.0, 3.0],
    ));
    let double = b.add_material(&MaterialDesc {
        double_sided: true,
        ..MaterialDesc::emitter("double", [0.5; 3], [4.0, 5.0, 6.0])
    });
    let (pz, mz) = ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]);
    let tilted = [
        [-0.3, -0.3, 1.0],
        [0.3, -0.3, 1.0],
        [0.3, 0.4, 1.0],
        [-0.3, 0.4, 1.0],
    ];
    let meshes = [
        b.add_mesh("front", &[quad(0.35, true, [pz; 4], single)]),
        b.add_mesh("back", &[quad(0.35, false, [mz; 4], single)]),
        b.add_mesh("double", &[quad(0.35, false, [mz; 4], double)]),
        b.add_mesh("tilted", &[quad(0.35, true, tilted, white)]),
        b.add_mesh("inward", &[quad(0.35, true, [mz; 4], white)]),
        b.add_mesh("wall", &[quad(1.2, true, [pz; 4], white)]),
        b.add_mesh("behind", &[quad(3.0, false, [mz; 4], white)]),
    ];
    let placed = [
        (0, [-0.9, 0.5, 0.0], 1.0),
        (1, [0.0, 0.5, 0.0], 1.0),
        (2, [0.9, 0.5, 0.0], 1.0),
        (0, [-0.9, -0.5, 0.2], -1.0),
        (1, [0.0, -0.5, 0.1], -1.0),
        (3, [0.9, -0.5, 0.0], 1.0),
        (4, [0.0, -1.05, 0.3], 1.0),
        (5, [0.0, 0.0, -1.0], 1.0),
        (6, [0.0, 0.0, 4.0], 1.0),
    ];
    let mut roots: Vec<usize> = placed
        .iter()
        .map(|&(m, t, sx)| {
            b.add_node(&NodeDesc {
                mesh: Some(meshes[m]),
                translation: Some(t),
                scale: (sx < 0.0).then_some([sx, 1.0, 1.0]),
                ..NodeDesc::default()
            })
        })
        .collect();
    roots.push(camera_node(
        &mut b,
        Vec3::new(0.0, 0.0, 3.0),
        Quat::IDENTITY,
        0.9,
    ));
    b.add_scene("faces", &roots, None);
    write_and_load(&b, &temp_dir("ic-passes-faces"), "faces")
}

/// The pipeline of `shaders/tests/gbuffer_fill.comp`, for [`fill_gbuffer_points`].
pub fn gbuffer_fill_pipeline(
    ctx: &radcache_vk::Context,
    shaders: &radcache_vk::ShaderCompiler,
) -> radcache_vk::Pipeline {
    use radcache_vk::{BindingKind, BindingLayout};
    let spirv = shaders.compile("tests/gbuffer_fill.comp", &[]).unwrap();
    let image = |b| BindingLayout::new(b, BindingKind::StorageImage);
    let layout = [
        image(0),
        image(1),
        image(2),
        BindingLayout::new(3, BindingKind::StorageBuffer),
        image(4),
    ];
    radcache_vk::Pipeline::compute(ctx, "gbuffer_fill", &spirv, &layout, 4).unwrap()
}

/// Records clearing `g` and writing `count` surface points from `texels` into its position,
/// normal, geometric and emission images with the pipeline of [`gbuffer_fill_pipeline`]
/// (push constant: the count).
pub fn fill_gbuffer_points(
    rec: &mut radcache_vk::Recorder,
    fill: &radcache_vk::Pipeline,
    g: &radcache_render::passes::gbuffer::GBuffer,
    texels: &radcache_vk::Buffer,
    count: u32,
) {
    use radcache_vk::Resource;
    for image in g.images() {
        rec.clear_color(image, [0.0; 4]);
    }
    rec.bind_pipeline(fill);
    rec.push_bindings(&[
        (0, Resource::StorageImage(&g.position)),
        (1, Resource::StorageImage(&g.normal)),
        (2, Resource::StorageImage(&g.geometric)),
        (3, Resource::Buffer(texels)),
        (4, Resource::StorageImage(&g.emission)),
    ]);
    rec.push_constants(&count);
    rec.dispatch(1, 1, 1).unwrap();
}

/// The settings of a small sequence frame that keeps its records (`size`², draft, 4 sub-frames
/// of 4 direct samples, records settled so a static frame creates none) at `time`, frame `frame`.
pub fn sequence_settings(size: u32, time: f32, frame: u32) -> radcache_render::IcSettings {
    radcache_render::IcSettings {
        width: size,
        height: size,
        params: radcache_cache::IcParams::draft(),
        sub_frames: 4,
        direct_samples: 4,
        time,
        frame,
        settle_records: true,
        ..radcache_render::IcSettings::default()
    }
}

/// A G-buffer texel as `shaders/tests/gbuffer_fill.comp` reads it: pixel, position, shading
/// normal and footprint, geometric normal (the record-pass tests write G-buffers from these).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GbufferPoint {
    /// Pixel (x, y).
    pub pixel: [u32; 4],
    /// Position.
    pub p: Vec3,
    /// Metallic and roughness, packed as `gbuffer_pack_metallic_roughness` does (0: a
    /// dielectric of roughness 0).
    pub metallic_roughness: f32,
    /// Shading normal.
    pub n: Vec3,
    /// World size of one pixel at `p`.
    pub footprint: f32,
    /// Geometric normal.
    pub ng: Vec3,
    /// Material index (as a float, as the G-buffer stores it).
    pub material: f32,
}
