//! Indirect arguments, host access to buffers in flight, record-order resource tracking, transfer
//! ranges and the binding table against the shader: each misuse is refused (a panic for a
//! recording call, an error for a host access or a pipeline), and correct use still works.

mod common;

use common::{
    colour_image, compiler, context, expect_panic, fill_pipeline, finish, host_buffer,
    tri_pipeline, FillPush,
};
use radcache_vk::{
    vk, BindingKind, BindingLayout, ColorTarget, Error, Pipeline, RenderTargets, Resource,
};

const STORAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::STORAGE_BUFFER;
const INDIRECT: vk::BufferUsageFlags = vk::BufferUsageFlags::INDIRECT_BUFFER;

#[test]
fn indirect_arguments_need_indirect_usage_and_fit_their_buffer() {
    let ctx = context();
    let shaders = compiler();
    let fill = fill_pipeline(&ctx, &shaders);
    let tri = tri_pipeline(&ctx, &shaders);
    let data = host_buffer(&ctx, "test.data", STORAGE, &[0; 128]);
    let extra = host_buffer(&ctx, "test.extra", STORAGE, &[1]);
    let colour = host_buffer(&ctx, "test.colour", STORAGE, &[0; 4]);
    let storage_args = host_buffer(&ctx, "test.storage_args", STORAGE, &[2, 1, 1, 0]);
    // Dispatch (2, 1, 1) at offset 4; a draw of 3 vertices, 1 instance at offset 0.
    let args = host_buffer(&ctx, "test.args", INDIRECT, &[0, 2, 1, 1]);
    let draw_args = host_buffer(&ctx, "test.draw_args", INDIRECT, &[3, 1, 0, 0]);
    let target = colour_image(&ctx, "test.target", 8);
    let mut rec = ctx.begin("test").unwrap();
    rec.bind_pipeline(&fill);
    rec.push_bindings(&[(0, Resource::Buffer(&data)), (1, Resource::Buffer(&extra))]);
    rec.push_constants(&FillPush {
        value: 3,
        count: 128,
    });
    expect_panic(
        "dispatch_indirect with pipeline \"test.fill\": buffer \"test.storage_args\" was not \
         created with INDIRECT_BUFFER usage",
        || rec.dispatch_indirect(&storage_args, 0),
    );
    expect_panic(
        "12 bytes of arguments at offset 8 run past the end of buffer \"test.args\" (16 bytes)",
        || rec.dispatch_indirect(&args, 8),
    );
    expect_panic(
        "offset 2 into buffer \"test.args\" is not a multiple of 4",
        || rec.dispatch_indirect(&args, 2),
    );
    rec.dispatch_indirect(&args, 4);
    rec.bind_pipeline(&tri);
    rec.push_bindings(&[(0, Resource::Buffer(&colour))]);
    rec.begin_rendering(&RenderTargets {
        colors: &[ColorTarget {
            image: &target,
            clear: Some([0.0; 4]),
        }],
        depth: None,
        indirect: &[&draw_args],
    });
    expect_panic(
        "draw_indirect with pipeline \"test.tri\": 16 bytes of arguments at offset 4 run past \
         the end of buffer \"test.draw_args\"",
        || rec.draw_indirect(&draw_args, 4, 1),
    );
    expect_panic("draw_count 2 needs multiDrawIndirect", || {
        rec.draw_indirect(&draw_args, 0, 2)
    });
    expect_panic("was not created with INDIRECT_BUFFER usage", || {
        rec.draw_indirect(&storage_args, 0, 1)
    });
    rec.draw_indirect(&draw_args, 0, 1);
    rec.end_rendering();
    ctx.submit(rec).unwrap().wait().unwrap();
    // Two groups of 64: all 128 words written.
    assert_eq!(data.read::<u32>(128).unwrap(), vec![4; 128]);
    drop((
        fill,
        tri,
        data,
        extra,
        colour,
        storage_args,
        args,
        draw_args,
        target,
    ));
    finish(ctx);
}

#[test]
fn host_access_waits_for_the_submissions_that_use_a_buffer() {
    let ctx = context();
    let shaders = compiler();
    let fill = fill_pipeline(&ctx, &shaders);
    let mut data = host_buffer(&ctx, "test.data", STORAGE, &[0; 64]);
    let mut extra = host_buffer(&ctx, "test.extra", STORAGE, &[1]);
    let record = |data: &radcache_vk::Buffer, extra: &radcache_vk::Buffer| {
        let mut rec = ctx.begin("test.fill").unwrap();
        rec.bind_pipeline(&fill);
        rec.push_bindings(&[(0, Resource::Buffer(data)), (1, Resource::Buffer(extra))]);
        rec.push_constants(&FillPush {
            value: 10,
            count: 64,
        });
        rec.dispatch(1, 1, 1).unwrap();
        rec
    };
    // Writing between recording and submitting is sound: submission makes host writes visible.
    let rec = record(&data, &extra);
    extra.write(0, &[2u32]).unwrap();
    let submission = ctx.submit(rec).unwrap();
    // In flight: the host may neither write what the GPU reads nor read what it writes.
    let err = extra.write(0, &[3u32]).unwrap_err();
    assert!(matches!(err, Error::Invalid(_)), "{err}");
    let message = err.to_string();
    assert!(
        message.contains("host write of buffer \"test.extra\"")
            && message.contains("still in flight"),
        "{message}"
    );
    let err = data.read::<u32>(64).unwrap_err().to_string();
    assert!(err.contains("host read of buffer \"test.data\""), "{err}");
    submission.wait().unwrap();
    assert_eq!(data.read::<u32>(64).unwrap(), vec![12; 64]);
    extra.write(0, &[3u32]).unwrap();
    // A dropped submission waits, so it no longer counts either.
    drop(ctx.submit(record(&data, &extra)).unwrap());
    assert_eq!(data.read::<u32>(64).unwrap(), vec![13; 64]);
    data.write(0, &[0u32; 64]).unwrap();
    drop((fill, data, extra));
    finish(ctx);
}

#[test]
fn resources_are_tracked_in_record_order() {
    let ctx = context();
    let image = colour_image(&ctx, "test.image", 8);
    let a = host_buffer(&ctx, "test.a", STORAGE, &[1, 2, 3, 4]);
    let mut first = ctx.begin("first").unwrap();
    first.clear_color(&image, [0.0; 4]);
    first.fill_buffer(&a, 0, 16, 7);
    let mut second = ctx.begin("second").unwrap();
    expect_panic(
        "clear_color in recording \"second\": \"test.image\" was last used by recording",
        || second.clear_color(&image, [1.0; 4]),
    );
    expect_panic(
        "fill_buffer in recording \"second\": \"test.a\" was last used by recording",
        || second.fill_buffer(&a, 0, 16, 8),
    );
    // Abandoning `first` forgets what it recorded: `second` starts from UNDEFINED (always a
    // valid old layout) after a barrier from every earlier write.
    drop(first);
    second.clear_color(&image, [1.0, 2.0, 3.0, 4.0]);
    second.fill_buffer(&a, 0, 16, 8);
    ctx.submit(second).unwrap().wait().unwrap();
    assert_eq!(a.read::<u32>(4).unwrap(), vec![8; 4]);
    let texels: Vec<[f32; 4]> = ctx.read_image(&image).unwrap();
    assert!(texels.iter().all(|t| *t == [1.0, 2.0, 3.0, 4.0]));
    drop((image, a));
    finish(ctx);
}

#[test]
fn transfers_stay_inside_their_buffers() {
    let ctx = context();
    let a = host_buffer(&ctx, "test.a", STORAGE, &[1, 2, 3, 4]);
    let b = host_buffer(&ctx, "test.b", STORAGE, &[0; 4]);
    let mut rec = ctx.begin("test").unwrap();
    expect_panic("copy_buffer: 16 bytes from \"test.a\"+4", || {
        rec.copy_buffer(&a, 4, &b, 0, 16)
    });
    expect_panic(
        "copy_buffer: overlapping ranges within buffer \"test.a\"",
        || rec.copy_buffer(&a, 0, &a, 4, 8),
    );
    expect_panic("fill_buffer: 8 bytes at 12 of buffer \"test.b\"", || {
        rec.fill_buffer(&b, 12, 8, 0)
    });
    expect_panic(
        "update_buffer: 8 bytes at 12 run past the end of buffer \"test.b\"",
        || rec.update_buffer(&b, 12, &[0u32; 2]),
    );
    rec.copy_buffer(&a, 0, &b, 4, 8);
    rec.fill_buffer(&b, 12, 4, 9);
    ctx.submit(rec).unwrap().wait().unwrap();
    assert_eq!(b.read::<u32>(4).unwrap(), vec![0, 1, 2, 9]);
    drop((a, b));
    finish(ctx);
}

#[test]
fn pipelines_declare_every_resource_their_shader_uses() {
    let ctx = context();
    let shaders = compiler();
    let spirv = shaders.compile("fill.comp", &[]).unwrap();
    let push = std::mem::size_of::<FillPush>() as u32;
    let storage = |n| BindingLayout::new(n, BindingKind::StorageBuffer);
    let err = Pipeline::compute(&ctx, "test.fill", &spirv, &[storage(0)], push).unwrap_err();
    assert!(
        err.to_string()
            .contains("pipeline \"test.fill\": the shader uses binding 1 (StorageBuffer)"),
        "{err}"
    );
    let wrong = [
        storage(0),
        BindingLayout::new(1, BindingKind::UniformBuffer),
    ];
    let err = Pipeline::compute(&ctx, "test.fill", &spirv, &wrong, push).unwrap_err();
    assert!(
        err.to_string()
            .contains("binding 1 is declared UniformBuffer, the shader uses it as StorageBuffer"),
        "{err}"
    );
    let err =
        Pipeline::compute(&ctx, "test.fill", &spirv, &[storage(0), storage(1)], 0).unwrap_err();
    assert!(err.to_string().contains("reads push constants"), "{err}");
    let err =
        Pipeline::compute(&ctx, "test.fill", &spirv, &[storage(0), storage(1)], 4).unwrap_err();
    assert!(
        err.to_string()
            .contains("push-constant block spans 8 bytes, the pipeline declares 4"),
        "{err}"
    );
    let err = Pipeline::compute(&ctx, "test.fill", &[1, 2, 3, 4, 5, 6], &[], 0).unwrap_err();
    assert!(err.to_string().contains("not a SPIR-V module"), "{err}");
    // A table that declares more than the shader uses is fine.
    let more = [storage(0), storage(1), storage(2)];
    drop(Pipeline::compute(&ctx, "test.fill", &spirv, &more, push).unwrap());
    finish(ctx);
}
