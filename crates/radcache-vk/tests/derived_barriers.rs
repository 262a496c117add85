//! The barriers and layout transitions derived from each command's uses (`src/hazard.rs`), under
//! the validation layer's synchronization check: a read after a write, a write after a read or a
//! write, a layout change and a rendering's attachments and indirect arguments, in one recording
//! and across recordings. No test places a barrier; a hazard that no derived barrier orders is a
//! validation error, which fails the test at `finish`, and the values read back show that every
//! command saw its predecessor's result.

mod common;

use common::{colour_image, compiler, expect_panic, fill_pipeline, finish, host_buffer};
use common::{tri_pipeline, FillPush};
use radcache_vk::{
    vk, Buffer, ColorTarget, Context, ContextOptions, Image, Pipeline, Recorder, RenderTargets,
    Resource,
};

const STORAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::STORAGE_BUFFER;
const INDIRECT: vk::BufferUsageFlags = vk::BufferUsageFlags::INDIRECT_BUFFER;

/// A context with validation and synchronization validation on, whatever the environment says.
fn checked_context() -> Context {
    let mut opts = ContextOptions::from_env();
    opts.validation = true;
    opts.sync_validation = true;
    opts.pipeline_cache_dir = None;
    let ctx = Context::with_options(&opts).unwrap_or_else(|e| panic!("creating the context: {e}"));
    assert!(
        ctx.info().validation,
        "the Khronos validation layer is missing"
    );
    ctx
}

#[test]
fn transfers_after_transfers_are_ordered() {
    let ctx = checked_context();
    let a = host_buffer(&ctx, "test.a", STORAGE, &[1, 2, 3, 4]);
    let b = host_buffer(&ctx, "test.b", STORAGE, &[0; 4]);
    let c = host_buffer(&ctx, "test.c", STORAGE, &[0; 4]);
    let mut rec = ctx.begin("test").unwrap();
    rec.fill_buffer(&b, 0, 16, 5); // write b
    rec.copy_buffer(&a, 0, &b, 0, 16); // write b after a write
    rec.copy_buffer(&b, 0, &c, 0, 16); // read b after a write
    rec.fill_buffer(&b, 0, 16, 6); // write b after a read
    rec.update_buffer(&c, 12, &[9u32]); // write c after a write
    ctx.submit(rec).unwrap().wait().unwrap();
    assert_eq!(c.read::<u32>(4).unwrap(), vec![1, 2, 3, 9]);
    assert_eq!(b.read::<u32>(4).unwrap(), vec![6; 4]);
    drop((a, b, c));
    finish(ctx);
}

#[test]
fn dispatches_see_what_the_commands_before_them_wrote() {
    let ctx = checked_context();
    let shaders = compiler();
    let fill = fill_pipeline(&ctx, &shaders);
    let data = host_buffer(&ctx, "test.data", STORAGE, &[0; 64]);
    let extra = host_buffer(&ctx, "test.extra", STORAGE, &[0]);
    let copy = host_buffer(&ctx, "test.copy", STORAGE, &[0; 64]);
    let mut rec = ctx.begin("test").unwrap();
    // A transfer write read by a dispatch (extra), a dispatch's write read by a copy (data),
    // then written again by a second dispatch after that read.
    rec.update_buffer(&extra, 0, &[10u32]);
    rec.bind_pipeline(&fill);
    rec.push_bindings(&[(0, Resource::Buffer(&data)), (1, Resource::Buffer(&extra))]);
    rec.push_constants(&FillPush {
        value: 1,
        count: 64,
    });
    rec.dispatch(1, 1, 1).unwrap();
    rec.copy_buffer(&data, 0, &copy, 0, 256);
    rec.push_constants(&FillPush {
        value: 2,
        count: 32,
    });
    rec.dispatch(1, 1, 1).unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    assert_eq!(copy.read::<u32>(64).unwrap(), vec![11; 64]);
    let written = data.read::<u32>(64).unwrap();
    assert!(written[..32].iter().all(|&v| v == 12) && written[32..].iter().all(|&v| v == 11));
    drop((fill, data, extra, copy));
    finish(ctx);
}

/// A triangle over an 8×8 target, its colour and its indirect arguments (written by transfers).
struct Draw {
    tri: Pipeline,
    colour: Buffer,
    args: Buffer,
    target: Image,
}

impl Draw {
    fn new(ctx: &Context) -> Draw {
        Draw {
            tri: tri_pipeline(ctx, &compiler()),
            colour: host_buffer(ctx, "test.colour", STORAGE, &[0; 4]),
            args: host_buffer(ctx, "test.draw_args", INDIRECT, &[0; 4]),
            target: colour_image(ctx, "test.target", 8),
        }
    }

    /// Records writing `colour` and the arguments of one triangle (transfers).
    fn write_inputs(&self, rec: &mut Recorder, colour: [f32; 4]) {
        rec.update_buffer(&self.colour, 0, &colour);
        rec.update_buffer(&self.args, 0, &[3u32, 1, 0, 0]);
    }

    fn colors(&self) -> [ColorTarget<'_>; 1] {
        [ColorTarget {
            image: &self.target,
            clear: None,
        }]
    }
}

#[test]
fn images_change_layout_with_their_use_across_recordings() {
    let ctx = checked_context();
    let d = Draw::new(&ctx);
    // Cleared by a transfer, then drawn into with the colour and the draw's arguments both
    // written by transfers in the same recording.
    let mut rec = ctx.begin("first").unwrap();
    rec.clear_color(&d.target, [1.0; 4]);
    d.write_inputs(&mut rec, [0.25, 0.5, 0.75, 1.0]);
    rec.bind_pipeline(&d.tri);
    rec.push_bindings(&[(0, Resource::Buffer(&d.colour))]);
    rec.begin_rendering(&RenderTargets {
        colors: &d.colors(),
        depth: None,
        indirect: &[&d.args],
    });
    rec.draw_indirect(&d.args, 0, 1);
    rec.end_rendering();
    ctx.submit(rec).unwrap().wait().unwrap();
    // Read back by another recording (TRANSFER_SRC), then cleared again by a third.
    let drawn: Vec<[f32; 4]> = ctx.read_image(&d.target).unwrap();
    assert!(
        drawn.iter().all(|t| *t == [0.25, 0.5, 0.75, 1.0]),
        "{:?}",
        drawn[0]
    );
    let mut rec = ctx.begin("third").unwrap();
    rec.clear_color(&d.target, [2.0; 4]);
    ctx.submit(rec).unwrap().wait().unwrap();
    let cleared: Vec<[f32; 4]> = ctx.read_image(&d.target).unwrap();
    assert!(cleared.iter().all(|t| *t == [2.0; 4]));
    drop(d);
    finish(ctx);
}

#[test]
fn a_draw_whose_resource_was_not_prepared_is_refused() {
    let ctx = checked_context();
    let d = Draw::new(&ctx);
    // The colour pushed inside the rendering, just after a transfer wrote it.
    let mut rec = ctx.begin("inside").unwrap();
    d.write_inputs(&mut rec, [1.0; 4]);
    rec.begin_rendering(&RenderTargets {
        colors: &d.colors(),
        ..Default::default()
    });
    rec.bind_pipeline(&d.tri);
    expect_panic(
        "push_bindings in recording \"inside\": \"test.colour\" needs a barrier",
        || rec.push_bindings(&[(0, Resource::Buffer(&d.colour))]),
    );
    rec.end_rendering();
    drop(rec);
    // The arguments not named in the rendering's `indirect`.
    let mut rec = ctx.begin("unnamed").unwrap();
    d.write_inputs(&mut rec, [1.0; 4]);
    rec.bind_pipeline(&d.tri);
    rec.push_bindings(&[(0, Resource::Buffer(&d.colour))]);
    rec.begin_rendering(&RenderTargets {
        colors: &d.colors(),
        ..Default::default()
    });
    expect_panic(
        "draw_indirect in recording \"unnamed\": \"test.draw_args\" needs a barrier",
        || rec.draw_indirect(&d.args, 0, 1),
    );
    rec.end_rendering();
    drop(rec);
    drop(d);
    finish(ctx);
}
