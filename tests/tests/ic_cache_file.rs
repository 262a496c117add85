//! Cache files on lavapipe (`IcRenderer::export_cache` / `import_cache`, the format of
//! `radcache_cache::cache_file`): records exported, written, read and imported into a fresh
//! renderer come back bit for bit; the same view rendered from them creates (nearly) no record;
//! and a new view takes the path of a camera move, re-clamping the imported records as the
//! exporting renderer re-clamps its kept ones.

use std::path::PathBuf;

use radcache_cache::cache_file::{CacheFile, CacheIdentity, CacheRecords, CacheSettings};
use radcache_cache::IcParams;
use radcache_render::{GpuScene, IcRenderer, IcSettings, IcStats};
use radcache_scene::{AnimationKind, Scene};
use radcache_tests::ic_fixture::sequence_settings;
use radcache_tests::scenes::{load, temp_dir};
use radcache_tests::{context, finish, shaders};
use radcache_vk::Context;

const SIZE: u32 = 48;

fn fly_through() -> Scene {
    load(&PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/cornell_fly/cornell_fly.gltf"
    )))
}

fn settings(time: f32, frame: u32) -> IcSettings {
    sequence_settings(SIZE, time, frame)
}

fn frame(
    ctx: &Context,
    scene: &Scene,
    gpu: &mut GpuScene,
    r: &mut IcRenderer,
    time: f32,
    n: u32,
) -> (Vec<[f32; 3]>, IcStats) {
    let (out, stats) = r
        .render(ctx, scene, gpu, &settings(time, n), &mut |_| {})
        .unwrap();
    (out.pixels, stats)
}

fn created(s: &IcStats) -> u64 {
    s.records_per_level.iter().sum()
}

fn bits<T: bytemuck::Pod>(v: &[T]) -> &[u8] {
    bytemuck::cast_slice(v)
}

fn same_records(a: &CacheRecords, b: &CacheRecords) -> bool {
    bits(&a.records) == bits(&b.records)
        && bits(&a.temporal) == bits(&b.temporal)
        && a.last_used == b.last_used
        && bits(&a.radiance) == bits(&b.radiance)
        && (a.frames, a.lifespans, a.sky) == (b.frames, b.lifespans, b.sky)
}

/// Relative mean squared difference of two images.
fn rel_diff(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let mut sum = 0.0;
    for (x, y) in a.iter().zip(b) {
        for c in 0..3 {
            let (x, y) = (f64::from(x[c]), f64::from(y[c]));
            sum += (x - y).powi(2) / (y * y + 0.01);
        }
    }
    sum / (3 * a.len()) as f64
}

#[test]
fn records_round_trip_through_a_file_into_a_fresh_renderer() {
    let scene = fly_through();
    assert_eq!(scene.plan().animation.kind, AnimationKind::CameraOnly);
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut first = IcRenderer::new(&ctx, &shaders, &gpu, &settings(0.0, 1)).unwrap();
    let (_, s1) = frame(&ctx, &scene, &mut gpu, &mut first, 0.0, 1);
    assert!(s1.records > 100, "{s1:?}");
    let exported = first.export_cache(&ctx).unwrap();
    assert_eq!(exported.records.len() as u64, s1.records);
    assert_eq!(exported.frames, 1);
    assert!(exported.last_used.contains(&1));

    let identity = CacheIdentity {
        scene_hash: scene.content_hash(),
        settings: CacheSettings {
            width: SIZE,
            height: SIZE,
            time_step_s: 0.0,
        },
        params: IcParams::draft(),
    };
    let path = temp_dir("ic-cache-file").join("fly.rcache");
    let encoded = CacheFile::new(identity, exported.clone()).encode();
    std::fs::write(&path, encoded).unwrap();
    let file = CacheFile::load(&path, &identity, settings(0.0, 1).record_capacity).unwrap();
    assert!(same_records(&file.records, &exported));

    // A fresh renderer holds exactly the file's records.
    let mut second = IcRenderer::new(&ctx, &shaders, &gpu, &settings(0.0, 1)).unwrap();
    second
        .import_cache(&ctx, &shaders, &gpu, &file.records)
        .unwrap();
    assert!(same_records(&second.export_cache(&ctx).unwrap(), &exported));

    // The same view from the imported records: they are re-clamped to it (they could have
    // been made for any view), which leaves (nearly) no hole, and the image is the exporting
    // renderer's next frame.
    let (kept, s2) = frame(&ctx, &scene, &mut gpu, &mut first, 0.0, 2);
    let (loaded, t2) = frame(&ctx, &scene, &mut gpu, &mut second, 0.0, 2);
    eprintln!(
        "same view: {} created after the export, {} after the import, of {} records",
        created(&s2),
        created(&t2),
        s1.records
    );
    assert_eq!(t2.records_kept, s1.records);
    assert!(created(&t2) * 100 <= s1.records, "{t2:?}");
    let d = rel_diff(&loaded, &kept);
    assert!(d < 1e-5, "relative difference {d:e}");

    // A new view: the imported records take the camera move's path, as the kept ones do.
    let t = 0.5;
    let mut third = IcRenderer::new(&ctx, &shaders, &gpu, &settings(0.0, 1)).unwrap();
    let before = first.export_cache(&ctx).unwrap();
    third.import_cache(&ctx, &shaders, &gpu, &before).unwrap();
    let (moved_kept, s3) = frame(&ctx, &scene, &mut gpu, &mut first, t, 3);
    let (moved_loaded, t3) = frame(&ctx, &scene, &mut gpu, &mut third, t, 3);
    eprintln!(
        "new view: {} kept + {} created after the export, {} + {} after the import",
        s3.records_kept,
        created(&s3),
        t3.records_kept,
        created(&t3)
    );
    assert_eq!(t3.records_kept, s3.records_kept);
    assert!(created(&t3) * 4 <= s1.records, "{t3:?}");
    let (a, b) = (created(&t3) as f64, created(&s3) as f64);
    assert!((a - b).abs() <= 0.1 * b.max(10.0), "{a} vs {b}");
    let d = rel_diff(&moved_loaded, &moved_kept);
    assert!(d < 1e-3, "relative difference {d:e}");
    drop((first, second, third, gpu));
    finish(ctx);
}
