//! The recording functions check their preconditions: each misuse panics with a message naming
//! the call, the pipeline and the resource, before anything reaches Vulkan (the context ends
//! with no validation error), and correct use still records and runs.

mod common;

use common::{
    colour_image, compiler, context, expect_panic, fill_pipeline, finish, host_buffer,
    tri_pipeline, FillPush,
};
use radcache_vk::{vk, ColorTarget, RenderTargets, Resource};

const STORAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::STORAGE_BUFFER;
const INDIRECT: vk::BufferUsageFlags = vk::BufferUsageFlags::INDIRECT_BUFFER;

#[test]
fn draws_need_an_open_rendering_and_a_graphics_pipeline() {
    let ctx = context();
    let shaders = compiler();
    let tri = tri_pipeline(&ctx, &shaders);
    let fill = fill_pipeline(&ctx, &shaders);
    let colour = host_buffer(&ctx, "test.colour", STORAGE, &[0; 4]);
    let target = colour_image(&ctx, "test.target", 8);
    let mut rec = ctx.begin("test").unwrap();
    rec.bind_pipeline(&tri);
    rec.push_bindings(&[(0, Resource::Buffer(&colour))]);
    expect_panic(
        "draw with pipeline \"test.tri\": no rendering is open",
        || rec.draw(3, 1),
    );
    expect_panic(
        "end_rendering in recording \"test\": no rendering is open",
        || rec.end_rendering(),
    );
    let colors = [ColorTarget {
        image: &target,
        clear: Some([0.0; 4]),
    }];
    let targets = RenderTargets {
        colors: &colors,
        ..Default::default()
    };
    rec.begin_rendering(&targets);
    expect_panic("a rendering is already open", || {
        rec.begin_rendering(&targets)
    });
    expect_panic(
        "clear_color in recording \"test\": not allowed inside a rendering",
        || rec.clear_color(&target, [0.0; 4]),
    );
    rec.bind_pipeline(&fill);
    expect_panic("draw: pipeline \"test.fill\" is a compute pipeline", || {
        rec.draw(3, 1)
    });
    expect_panic(
        "dispatch with pipeline \"test.fill\": a rendering is open",
        || {
            rec.dispatch(1, 1, 1).unwrap();
        },
    );
    // Correct use: the graphics pipeline again, its binding pushed, inside the rendering.
    rec.bind_pipeline(&tri);
    rec.push_bindings(&[(0, Resource::Buffer(&colour))]);
    rec.draw(3, 1);
    rec.end_rendering();
    ctx.submit(rec).unwrap().wait().unwrap();
    drop((tri, fill, colour, target));
    finish(ctx);
}

#[test]
fn a_recording_with_an_open_rendering_is_not_submitted() {
    let ctx = context();
    let target = colour_image(&ctx, "test.target", 8);
    let mut rec = ctx.begin("open").unwrap();
    rec.begin_rendering(&RenderTargets {
        colors: &[ColorTarget {
            image: &target,
            clear: Some([0.0; 4]),
        }],
        ..Default::default()
    });
    expect_panic(
        "recording \"open\" submitted with an open rendering",
        || {
            let _ = ctx.submit(rec);
        },
    );
    drop(target);
    finish(ctx);
}

#[test]
fn a_rendering_checks_its_attachments_against_the_pipeline() {
    let ctx = context();
    let shaders = compiler();
    let tri = tri_pipeline(&ctx, &shaders);
    let colour = host_buffer(&ctx, "test.colour", STORAGE, &[0; 4]);
    let target = colour_image(&ctx, "test.target", 8);
    let other = colour_image(&ctx, "test.other", 8);
    let mut rec = ctx.begin("test").unwrap();
    rec.bind_pipeline(&tri);
    rec.push_bindings(&[(0, Resource::Buffer(&colour))]);
    rec.begin_rendering(&RenderTargets {
        colors: &[
            ColorTarget {
                image: &target,
                clear: Some([0.0; 4]),
            },
            ColorTarget {
                image: &other,
                clear: Some([0.0; 4]),
            },
        ],
        ..Default::default()
    });
    expect_panic(
        "the open rendering has colours [R32G32B32A32_SFLOAT, R32G32B32A32_SFLOAT]",
        || rec.draw(3, 1),
    );
    rec.end_rendering();
    drop(rec);
    drop((tri, colour, target, other));
    finish(ctx);
}

#[test]
fn every_declared_binding_is_pushed_before_a_dispatch() {
    let ctx = context();
    let shaders = compiler();
    let fill = fill_pipeline(&ctx, &shaders);
    let data = host_buffer(&ctx, "test.data", STORAGE, &[0; 64]);
    let extra = host_buffer(&ctx, "test.extra", STORAGE, &[5]);
    let push = FillPush {
        value: 7,
        count: 64,
    };
    let mut rec = ctx.begin("test").unwrap();
    expect_panic("dispatch: no pipeline is bound", || {
        rec.dispatch(1, 1, 1).unwrap();
    });
    rec.bind_pipeline(&fill);
    rec.push_constants(&push);
    rec.push_bindings(&[(0, Resource::Buffer(&data))]);
    expect_panic(
        "dispatch with pipeline \"test.fill\": declared binding(s) [1] not pushed",
        || {
            rec.dispatch(1, 1, 1).unwrap();
        },
    );
    // The rest in a second call: the dispatch is complete now.
    rec.push_bindings(&[(1, Resource::Buffer(&extra))]);
    rec.dispatch(1, 1, 1).unwrap();
    // Binding the pipeline again starts afresh: bindings and push constants are gone.
    rec.bind_pipeline(&fill);
    expect_panic(
        "declared binding(s) [0, 1] not pushed since bind_pipeline",
        || {
            rec.dispatch(1, 1, 1).unwrap();
        },
    );
    rec.push_bindings(&[(0, Resource::Buffer(&data)), (1, Resource::Buffer(&extra))]);
    expect_panic("its 8 bytes of push constants were not set", || {
        rec.dispatch(1, 1, 1).unwrap();
    });
    rec.push_constants(&push);
    rec.dispatch(1, 1, 1).unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    assert_eq!(data.read::<u32>(64).unwrap(), vec![12; 64]);
    drop((fill, data, extra));
    finish(ctx);
}

#[test]
fn pushed_resources_are_checked_against_the_table() {
    let ctx = context();
    let shaders = compiler();
    let fill = fill_pipeline(&ctx, &shaders);
    let tri = tri_pipeline(&ctx, &shaders);
    let indirect_only = host_buffer(&ctx, "test.args_only", INDIRECT, &[1, 1, 1]);
    let data = host_buffer(&ctx, "test.data", STORAGE, &[0; 4]);
    let image = colour_image(&ctx, "test.image", 8);
    let mut rec = ctx.begin("test").unwrap();
    rec.bind_pipeline(&fill);
    expect_panic("pipeline \"test.fill\" has no binding 2", || {
        rec.push_bindings(&[(2, Resource::Buffer(&data))])
    });
    expect_panic("binding 0 is StorageBuffer, got StorageImage", || {
        rec.push_bindings(&[(0, Resource::StorageImage(&image))])
    });
    expect_panic(
        "buffer \"test.args_only\" has no STORAGE_BUFFER usage",
        || rec.push_bindings(&[(0, Resource::Buffer(&indirect_only))]),
    );
    expect_panic("range 8+16 of buffer \"test.data\" (16 bytes)", || {
        rec.push_bindings(&[(0, Resource::BufferRange(&data, 8, 16))])
    });
    rec.bind_pipeline(&tri);
    expect_panic("pipeline \"test.tri\" declares no push constants", || {
        rec.push_constants(&[0u32; 4])
    });
    drop(rec);
    drop((fill, tri, indirect_only, data, image));
    finish(ctx);
}

#[test]
fn a_pushed_image_is_transitioned_for_each_use() {
    let ctx = context();
    let shaders = compiler();
    let spirv = shaders.compile("store.comp", &[]).unwrap();
    let store = radcache_vk::Pipeline::compute(
        &ctx,
        "test.store",
        &spirv,
        &[radcache_vk::BindingLayout::new(
            0,
            radcache_vk::BindingKind::StorageImage,
        )],
        0,
    )
    .unwrap();
    let image = colour_image(&ctx, "test.image", 8);
    let mut rec = ctx.begin("test").unwrap();
    rec.bind_pipeline(&store);
    // Cleared (TRANSFER_DST), stored into (GENERAL), read back (TRANSFER_SRC, by another
    // recording): every transition derived from the use.
    rec.clear_color(&image, [9.0; 4]);
    rec.push_bindings(&[(0, Resource::StorageImage(&image))]);
    rec.dispatch(1, 1, 1).unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    let texels: Vec<[f32; 4]> = ctx.read_image(&image).unwrap();
    assert_eq!(texels[8 * 3 + 5], [5.0, 3.0, 0.0, 1.0]);
    drop((store, image));
    finish(ctx);
}
