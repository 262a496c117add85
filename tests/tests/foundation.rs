//! The Vulkan foundation on lavapipe: additive float blending under a depth test, timestamp scopes,
//! the missing-capability refusal, leak reporting, and shader compilation errors.

use bytemuck::{Pod, Zeroable};
use radcache_tests::{context, finish, init_log, shaders, Rng};
use radcache_vk::{
    vk, BindingKind, BindingLayout, Blend, Buffer, BufferDesc, ColorTarget, Context,
    ContextOptions, DepthState, DepthTarget, Error, GraphicsDesc, Image, ImageDesc, MemoryLocation,
    Pipeline, RenderTargets, Resource, ShaderCompiler,
};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable, Debug)]
struct Quad {
    rect: [f32; 4],
    color: [f32; 4],
    depth: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SplatPush {
    viewport: [f32; 2],
    pad: [f32; 2],
}

const W: u32 = 64;
const H: u32 = 48;
/// The depth prepass covers the left half at this depth; the right half keeps the clear value 1.
const PREPASS_DEPTH: f32 = 0.5;

fn splat_pipeline(
    ctx: &Context,
    compiler: &ShaderCompiler,
    name: &str,
    depth_write: bool,
) -> Pipeline {
    let vs = compiler.compile("tests/splat.vert", &[]).unwrap();
    let fs = compiler.compile("tests/splat.frag", &[]).unwrap();
    Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            name,
            vertex: &vs,
            fragment: &fs,
            bindings: &[BindingLayout::new(0, BindingKind::StorageBuffer)],
            push_constant_size: 16,
            color_formats: &[vk::Format::R32G32B32A32_SFLOAT],
            depth: Some(DepthState {
                format: vk::Format::D32_SFLOAT,
                compare: vk::CompareOp::LESS,
                write: depth_write,
            }),
            blend: Blend::Additive,
            cull: vk::CullModeFlags::NONE,
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
        },
    )
    .unwrap()
}

/// Random integer-aligned quads with colours in multiples of 1/16 (every sum is exact in f32).
fn random_quads(n: usize) -> Vec<Quad> {
    let mut rng = Rng::new(42);
    (0..n)
        .map(|_| {
            let x0 = rng.below(W - 1);
            let y0 = rng.below(H - 1);
            let x1 = x0 + 1 + rng.below(W - x0);
            let y1 = y0 + 1 + rng.below(H - y0);
            let c = |rng: &mut Rng| rng.below(64) as f32 / 16.0;
            Quad {
                rect: [x0 as f32, y0 as f32, x1.min(W) as f32, y1.min(H) as f32],
                color: [c(&mut rng), c(&mut rng), c(&mut rng), 1.0],
                depth: [if rng.below(2) == 0 { 0.25 } else { 0.75 }, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

fn cpu_sum(quads: &[Quad]) -> Vec<[f32; 4]> {
    let mut out = vec![[0.0f32; 4]; (W * H) as usize];
    for y in 0..H {
        for x in 0..W {
            let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
            let depth = if x < W / 2 { PREPASS_DEPTH } else { 1.0 };
            for q in quads {
                let inside = cx > q.rect[0] && cx < q.rect[2] && cy > q.rect[1] && cy < q.rect[3];
                if inside && q.depth[0] < depth {
                    let px = &mut out[(y * W + x) as usize];
                    for (sum, value) in px.iter_mut().zip(q.color) {
                        *sum += value;
                    }
                }
            }
        }
    }
    out
}

#[test]
fn additive_splats_under_depth_test_sum_exactly() {
    let ctx = context();
    let compiler = shaders();
    let accum = Image::new(
        &ctx,
        &ImageDesc {
            name: "test.accum",
            width: W,
            height: H,
            format: vk::Format::R32G32B32A32_SFLOAT,
            usage: vk::ImageUsageFlags::COLOR_ATTACHMENT,
        },
    )
    .unwrap();
    let depth = Image::new(
        &ctx,
        &ImageDesc {
            name: "test.depth",
            width: W,
            height: H,
            format: vk::Format::D32_SFLOAT,
            usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        },
    )
    .unwrap();
    // The prepass writes depth only: its quad has colour 0, which additive blending leaves as is.
    let prepass = [Quad {
        rect: [0.0, 0.0, (W / 2) as f32, H as f32],
        color: [0.0; 4],
        depth: [PREPASS_DEPTH, 0.0, 0.0, 0.0],
    }];
    let quads = random_quads(300);
    let prepass_buf = ctx
        .create_buffer_init(
            "test.prepass",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            &prepass,
        )
        .unwrap();
    let quad_buf = ctx
        .create_buffer_init("test.quads", vk::BufferUsageFlags::STORAGE_BUFFER, &quads)
        .unwrap();
    let depth_pipe = splat_pipeline(&ctx, &compiler, "test.depth_prepass", true);
    let splat_pipe = splat_pipeline(&ctx, &compiler, "test.splat", false);
    let push = SplatPush {
        viewport: [W as f32, H as f32],
        pad: [0.0; 2],
    };

    let mut rec = ctx.begin("test").unwrap();
    rec.pass("test.depth_prepass", |rec| {
        rec.bind_pipeline(&depth_pipe);
        rec.push_bindings(&[(0, Resource::Buffer(&prepass_buf))]);
        rec.push_constants(&push);
        rec.begin_rendering(&RenderTargets {
            colors: &[ColorTarget {
                image: &accum,
                clear: Some([0.0; 4]),
            }],
            depth: Some(DepthTarget {
                image: &depth,
                clear: Some(1.0),
            }),
            indirect: &[],
        });
        rec.draw(6, 1);
        rec.end_rendering();
    });
    rec.pass("test.splat", |rec| {
        rec.bind_pipeline(&splat_pipe);
        rec.push_bindings(&[(0, Resource::Buffer(&quad_buf))]);
        rec.push_constants(&push);
        rec.begin_rendering(&RenderTargets {
            colors: &[ColorTarget {
                image: &accum,
                clear: None,
            }],
            depth: Some(DepthTarget {
                image: &depth,
                clear: None,
            }),
            indirect: &[],
        });
        rec.draw(6, quads.len() as u32);
        rec.end_rendering();
    });
    let timings = ctx.submit(rec).unwrap().wait().unwrap();
    assert_eq!(timings.len(), 2);
    let gpu: Vec<[f32; 4]> = ctx.read_image(&accum).unwrap();
    let cpu = cpu_sum(&quads);
    let mut covered = 0;
    for (i, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        assert_eq!(g, c, "pixel ({}, {})", i as u32 % W, i as u32 / W);
        covered += usize::from(c[3] > 0.0);
    }
    // The test must exercise both sides of the depth test.
    assert!(covered > (W * H) as usize / 2, "covered {covered}");
    assert!(cpu
        .iter()
        .enumerate()
        .any(|(i, c)| (i as u32 % W) < W / 2 && c[3] > 0.0));
    drop((depth_pipe, splat_pipe, prepass_buf, quad_buf, accum, depth));
    finish(ctx);
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BusyPush {
    iterations: u32,
    pad: [u32; 3],
}

#[test]
fn pass_scopes_give_named_positive_timings() {
    let ctx = context();
    let compiler = shaders();
    let spirv = compiler.compile("tests/busy.comp", &[]).unwrap();
    let pipe = Pipeline::compute(
        &ctx,
        "test.busy",
        &spirv,
        &[BindingLayout::new(0, BindingKind::StorageBuffer)],
        16,
    )
    .unwrap();
    let out = Buffer::new(
        &ctx,
        &BufferDesc {
            name: "test.busy_out",
            size: 4 * 65536,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
            alignment: 0,
        },
    )
    .unwrap();
    let mut rec = ctx.begin("test").unwrap();
    rec.pass("outer", |rec| {
        for name in ["busy.a", "busy.b"] {
            rec.pass(name, |rec| {
                rec.bind_pipeline(&pipe);
                rec.push_bindings(&[(0, Resource::Buffer(&out))]);
                rec.push_constants(&BusyPush {
                    iterations: 200,
                    pad: [0; 3],
                });
                rec.dispatch(1024, 1, 1).unwrap();
            });
        }
    });
    assert_eq!(rec.scope_names(), ["outer", "busy.a", "busy.b"]);
    let t = ctx.submit(rec).unwrap().wait().unwrap();
    let names: Vec<(&str, u32)> = t.iter().map(|p| (p.name.as_str(), p.depth)).collect();
    assert_eq!(names, [("outer", 0), ("busy.a", 1), ("busy.b", 1)]);
    for p in &t {
        assert!(p.duration_ms > 0.0 && p.duration_ms.is_finite(), "{p:?}");
    }
    assert!(
        t[0].duration_ms >= t[1].duration_ms + t[2].duration_ms - 1e-3,
        "{t:?}"
    );
    assert!(
        t[2].start_ms >= t[1].start_ms + t[1].duration_ms - 1e-3,
        "{t:?}"
    );
    drop((pipe, out));
    finish(ctx);
}

#[test]
fn missing_extension_is_refused_with_a_report() {
    init_log();
    let mut opts = ContextOptions::from_env();
    opts.extra_device_extensions = vec!["VK_NV_radcache_does_not_exist".into()];
    let err = Context::with_options(&opts).expect_err("no device has a made-up extension");
    let Error::NoSuitableDevice(report) = &err else {
        panic!("wrong error: {err}")
    };
    assert!(!report.devices.is_empty());
    let text = err.to_string();
    assert!(text.contains("VK_NV_radcache_does_not_exist"), "{text}");
    assert!(
        text.contains("llvmpipe") || std::env::var("VK_DRIVER_FILES").is_err(),
        "{text}"
    );
}

#[test]
fn shutdown_reports_leaked_allocations() {
    let ctx = context();
    let kept = Buffer::new(
        &ctx,
        &BufferDesc {
            name: "test.kept_alive",
            size: 256,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
            alignment: 0,
        },
    )
    .unwrap();
    let dropped = ctx
        .create_buffer_init(
            "test.dropped",
            vk::BufferUsageFlags::STORAGE_BUFFER,
            &[1u32, 2, 3],
        )
        .unwrap();
    assert_eq!(ctx.read_buffer::<u32>(&dropped, 3).unwrap(), [1, 2, 3]);
    drop(dropped);
    let report = ctx.clone().shutdown();
    assert_eq!(report.leaked, ["test.kept_alive"]);
    drop(kept);
    finish(ctx);
}

#[test]
fn shader_errors_name_file_and_line() {
    let dir = std::env::temp_dir().join(format!("radcache-shader-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(
        dir.join("sub/inc.glsl"),
        "float helper() { return 1.0; }\nfloat broken() { return undefined_name; }\n",
    )
    .unwrap();
    std::fs::write(dir.join("good.comp"), "#version 460\n#extension GL_GOOGLE_include_directive : require\n#define X 1\nlayout(local_size_x = 1) in;\nvoid main() { float v = VALUE; }\n").unwrap();
    std::fs::write(dir.join("bad.comp"), "#version 460\n#extension GL_GOOGLE_include_directive : require\n#include \"sub/inc.glsl\"\nlayout(local_size_x = 1) in;\nvoid main() {}\n").unwrap();
    let compiler = ShaderCompiler::new(&dir).unwrap();
    let good = compiler.compile("good.comp", &[("VALUE", "2.0")]).unwrap();
    assert_eq!(good[0], 0x0723_0203, "SPIR-V magic");
    assert!(
        compiler.compile("good.comp", &[]).is_err(),
        "VALUE undefined without the define"
    );
    let err = compiler.compile("bad.comp", &[]).unwrap_err().to_string();
    assert!(err.contains("sub/inc.glsl:2"), "{err}");
    assert!(err.contains("undefined_name"), "{err}");
    // Editing the included file is picked up by the cache.
    std::fs::write(dir.join("sub/inc.glsl"), "float helper() { return 1.0; }\n").unwrap();
    assert!(compiler.compile("bad.comp", &[]).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}
