//! A scene is planned against the device's memory before anything is uploaded: the packed
//! buffers' sizes and the driver's build sizes of its acceleration structures. One that does not
//! fit (here: the Cornell box, about 12 KiB, under a 4 KiB `ContextOptions::memory_limit`, what
//! `RADCACHE_DEVICE_MEMORY` sets) is refused with its parts and sizes named, having allocated
//! nothing; one that fits keeps no more than was planned.

use radcache_render::scene::budget::MemoryNeed;
use radcache_render::{Error, GpuScene};
use radcache_tests::ic_fixture::cornell;
use radcache_tests::{context, context_with, finish};

fn allocated(ctx: &radcache_vk::Context) -> u64 {
    ctx.memory_by_category().values().sum()
}

#[test]
fn a_scene_larger_than_the_device_memory_is_refused_before_any_upload() {
    let ctx = context_with(|o| o.memory_limit = Some(4 << 10));
    let scene = cornell();
    let before = allocated(&ctx);
    let e = match GpuScene::new(&ctx, &scene, None) {
        Ok(_) => panic!("the Cornell box fitted in 4 KiB"),
        Err(e) => e,
    };
    assert!(matches!(e, Error::SceneTooLarge(_)), "{e:?}");
    let text = e.to_string();
    let file = format!("{}: ", scene.path.display());
    for part in [
        &file,
        "device memory at the peak of its upload",
        "geometry ",
        "acceleration structures ",
        &ctx.info().name,
        "RADCACHE_DEVICE_MEMORY=4.00 KiB",
    ] {
        assert!(text.contains(part), "no {part:?} in: {text}");
    }
    assert_eq!(
        allocated(&ctx),
        before,
        "the refused scene allocated device memory"
    );
    finish(ctx);
}

#[test]
fn a_scene_that_fits_keeps_no_more_than_it_was_planned_for() {
    let ctx = context();
    let scene = cornell();
    let before = allocated(&ctx);
    let gpu = GpuScene::new(&ctx, &scene, None).expect("the Cornell box fits");
    let need: MemoryNeed = gpu.stats().memory_need;
    let kept = allocated(&ctx) - before;
    assert!(need.geometry > 0 && need.acceleration > 0, "{need:?}");
    // The plan is the peak (uncompacted BLASes, their scratch and compacted copies at once):
    // what stays after the upload is at most that, and not far below it (the plan is not padding).
    assert!(
        kept <= need.total() && kept * 8 >= need.total(),
        "kept {kept} B against a plan of {} B ({need:?})",
        need.total()
    );
    drop(gpu);
    finish(ctx);
}
