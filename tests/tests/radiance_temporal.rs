//! Radiance records across frames and in cache files (issue 18, docs/radiance-caching.md §8), on
//! lavapipe: compaction moves each record's radiance block with it; in the sliding-box room with
//! a rough metal floor, temporal caching keeps the blocks of records it does not evaluate again
//! bit for bit, re-evaluates those the box changes, and a late frame stays as close to the path
//! tracer as a fresh cache; and a cache file carries the blocks into a fresh renderer, whose
//! next frame is the exporting renderer's (without the blocks, glossy lobes fall back to
//! per-pixel paths and that frame is noisier).

use std::collections::HashMap;

use glam::Vec3;
use radcache_cache::cache_file::{CacheFile, CacheIdentity, CacheSettings};
use radcache_cache::IcParams;
use radcache_image::{compare, Image};
use radcache_render::{
    state::IcStateDesc, state::RadianceBlock, FrameOutput, GpuScene, IcRenderer, IcState,
};
use radcache_scene::Scene;
use radcache_shared::gpu::{GpuRecord, GpuRecordTemporal};
use radcache_tests::ic_fixture::sequence_settings;
use radcache_tests::scenes::{load, temp_dir};
use radcache_tests::sliding_box::{self, distance_to_path, NEAR};
use radcache_tests::{context, finish, shaders};

fn image(o: &FrameOutput) -> Image {
    Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap()
}

/// A record's identity across frames and compactions: its creation pixel, level and sub-frame.
fn key(r: &GpuRecord) -> [u32; 3] {
    [r.info[0], r.info[1], r.info[2]]
}

/// A block whose every word tells record `i` apart (NaN bit patterns included).
fn block(i: u32) -> RadianceBlock {
    let mut b: RadianceBlock = bytemuck::Zeroable::zeroed();
    let w: &mut [u32] = bytemuck::cast_slice_mut(&mut b);
    for (k, w) in w.iter_mut().enumerate() {
        *w = (i << 16 | k as u32) ^ (0x7fc0_0000 * u32::from(k % 9 == 4));
    }
    b
}

#[test]
fn compaction_moves_each_radiance_block_with_its_record() {
    let (ctx, shaders) = (context(), shaders());
    let state = IcState::new(
        &ctx,
        &shaders,
        &IcStateDesc {
            radiance: true,
            ..IcStateDesc::new(16, 16)
        },
    )
    .unwrap();
    let n = 10u32;
    let records: Vec<GpuRecord> = (0..n)
        .map(|i| {
            let mut r: GpuRecord = bytemuck::Zeroable::zeroed();
            r.info = [100 + i, 0, 0, 1];
            r
        })
        .collect();
    let temporal = vec![<GpuRecordTemporal as bytemuck::Zeroable>::zeroed(); n as usize];
    // Marks: record i last used at frame i % 4 (0 = never).
    let marks: Vec<u32> = (0..n).map(|i| i % 4).collect();
    let blocks: Vec<RadianceBlock> = (0..n).map(block).collect();
    state.upload(&ctx, &records, &temporal, &marks).unwrap();
    state.upload_radiance(&ctx, &blocks).unwrap();
    assert_eq!(
        bytemuck::cast_slice::<RadianceBlock, u8>(&state.download_radiance(&ctx).unwrap()),
        bytemuck::cast_slice::<RadianceBlock, u8>(&blocks)
    );
    // Keep the records used at frames 2 and 3.
    let dropped = state.compact(&ctx, |_, used| used >= 2).unwrap();
    let (kept, _, _) = state.download(&ctx).unwrap();
    let kept_blocks = state.download_radiance(&ctx).unwrap();
    assert_eq!(dropped as usize, n as usize - kept.len());
    assert_eq!(kept.len(), (0..n).filter(|i| i % 4 >= 2).count());
    assert_eq!(kept.len(), kept_blocks.len());
    for (r, b) in kept.iter().zip(&kept_blocks) {
        let i = r.info[0] - 100;
        assert!(i % 4 >= 2, "record {i} should have been dropped");
        assert!(*b == block(i), "record {i} lost its radiance block");
    }
    // Too many blocks, or blocks for a cache without them, are refused.
    let too_many: Vec<RadianceBlock> = (0..17).map(block).collect();
    assert!(state.upload_radiance(&ctx, &too_many).is_err());
    let plain = IcState::new(&ctx, &shaders, &IcStateDesc::new(16, 16)).unwrap();
    let err = plain.upload_radiance(&ctx, &blocks).unwrap_err();
    assert!(err.to_string().contains("radiance"), "{err}");
    assert!(plain.download_radiance(&ctx).unwrap().is_empty());
    drop((state, plain));
    finish(ctx);
}

const SIZE: u32 = 48;

#[test]
fn temporal_caching_keeps_unlisted_radiance_blocks_and_re_evaluates_the_changed_ones() {
    let scene = sliding_box::sliding_box_scene("radiance-temporal", true);
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let settings = |f| sliding_box::settings(SIZE, f);
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &settings(1)).unwrap();
    assert!(r.state().radiance.is_some(), "no radiance blocks");
    let last = 8u32;
    let mut previous: HashMap<[u32; 3], RadianceBlock> = HashMap::new();
    let (mut unlisted, mut listed_near, mut changed_near) = (0usize, 0usize, 0usize);
    let mut out = None;
    for frame in 1..=last {
        let (o, stats) = r
            .render(&ctx, &scene, &mut gpu, &settings(frame), &mut |_| {})
            .unwrap();
        assert_eq!(o.nonfinite_pixels, 0);
        let (records, temporal, _) = r.state().download(&ctx).unwrap();
        let blocks = r.state().download_radiance(&ctx).unwrap();
        assert_eq!(records.len(), blocks.len());
        assert_eq!(records.len() as u64, stats.records);
        let mut seen: HashMap<[u32; 3], usize> = HashMap::new();
        for r in &records {
            *seen.entry(key(r)).or_default() += 1;
        }
        let mut now = HashMap::new();
        for ((rec, tr), b) in records.iter().zip(&temporal).zip(&blocks) {
            let k = key(rec);
            if tr.info[2] & 1 == 0 || seen[&k] > 1 {
                continue; // rejected, or not told apart by its key
            }
            now.insert(k, *b);
            let Some(before) = previous.get(&k) else {
                continue;
            };
            // Evaluated this frame (its known value is now the next frame's): a new block.
            if tr.info[1] == frame + 1 {
                let p = Vec3::new(
                    rec.position_radius[0],
                    rec.position_radius[1],
                    rec.position_radius[2],
                );
                if distance_to_path(p) <= NEAR {
                    listed_near += 1;
                    changed_near += usize::from(before != b);
                }
            } else {
                unlisted += 1;
                assert!(
                    before == b,
                    "frame {frame}: record {k:?} was not evaluated but its block changed"
                );
            }
        }
        previous = now;
        out = Some(o);
    }
    eprintln!(
        "kept blocks: {unlisted} unlisted (unchanged), {listed_near} re-evaluated near the box \
         ({changed_near} changed)"
    );
    assert!(unlisted >= 800, "{unlisted} unlisted records");
    assert!(
        listed_near >= 30,
        "{listed_near} re-evaluated records near the box"
    );
    assert!(
        2 * changed_near >= listed_near,
        "{changed_near} of {listed_near}"
    );

    // The last frame against the path tracer, and against a fresh cache of that frame.
    let out = out.unwrap();
    let (m_kept, m_fresh) =
        sliding_box::against_fresh_cache(&ctx, &shaders, &scene, &mut gpu, SIZE, last, &out);
    assert_eq!(m_kept.nonfinite_candidate, 0);
    assert!(m_kept.relmse <= 0.01, "relMSE {}", m_kept.relmse);
    assert!(
        m_kept.relmse <= 1.5 * m_fresh.relmse + 1e-3,
        "kept {} vs fresh {}",
        m_kept.relmse,
        m_fresh.relmse
    );
    drop((r, gpu));
    finish(ctx);
}

fn glossy_room() -> Scene {
    load(
        &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/glossy_room/glossy_room.gltf"),
    )
}

#[test]
fn a_cache_file_carries_the_radiance_blocks_into_a_fresh_renderer() {
    let size = 32;
    let scene = glossy_room();
    assert!(scene.plan().radiance_cache());
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let settings = |f| sequence_settings(size, 0.0, f);
    let mut first = IcRenderer::new(&ctx, &shaders, &gpu, &settings(1)).unwrap();
    first
        .render(&ctx, &scene, &mut gpu, &settings(1), &mut |_| {})
        .unwrap();
    let exported = first.export_cache(&ctx).unwrap();
    assert!(exported.records.len() > 50);
    assert_eq!(exported.radiance.len(), exported.records.len());

    let identity = CacheIdentity {
        scene_hash: scene.content_hash(),
        settings: CacheSettings {
            width: size,
            height: size,
            time_step_s: 0.0,
        },
        params: IcParams::draft(),
    };
    let path = temp_dir("radiance-cache-file").join("glossy.rcache");
    std::fs::write(&path, CacheFile::new(identity, exported.clone()).encode()).unwrap();
    let file = CacheFile::load(&path, &identity, settings(1).record_capacity).unwrap();
    assert!(file.header.radiance);
    assert!(file
        .header
        .describe()
        .contains("radiance coefficients: yes"));

    let mut loaded = IcRenderer::new(&ctx, &shaders, &gpu, &settings(1)).unwrap();
    loaded
        .import_cache(&ctx, &shaders, &gpu, &file.records)
        .unwrap();
    // Exported again, the blocks are the file's.
    let again = loaded.export_cache(&ctx).unwrap();
    assert!(
        bytemuck::cast_slice::<RadianceBlock, u8>(&again.radiance)
            == bytemuck::cast_slice::<RadianceBlock, u8>(&exported.radiance)
    );
    // The same records without their blocks: glossy lobes from per-pixel paths, and exported
    // without blocks (they are not the records' own).
    let mut stripped_records = file.records.clone();
    stripped_records.radiance.clear();
    let mut stripped = IcRenderer::new(&ctx, &shaders, &gpu, &settings(1)).unwrap();
    stripped
        .import_cache(&ctx, &shaders, &gpu, &stripped_records)
        .unwrap();
    assert!(stripped.export_cache(&ctx).unwrap().radiance.is_empty());
    // Blocks that do not match the records in number are refused.
    let mut short = file.records.clone();
    short.radiance.pop();
    let mut refused = IcRenderer::new(&ctx, &shaders, &gpu, &settings(1)).unwrap();
    let err = refused
        .import_cache(&ctx, &shaders, &gpu, &short)
        .unwrap_err();
    assert!(err.to_string().contains("radiance blocks"), "{err}");

    let mut next = |r: &mut IcRenderer| {
        let (o, _) = r
            .render(&ctx, &scene, &mut gpu, &settings(2), &mut |_| {})
            .unwrap();
        assert_eq!(o.nonfinite_pixels, 0);
        image(&o)
    };
    let kept = next(&mut first);
    let from_file = next(&mut loaded);
    let without = next(&mut stripped);
    let m_file = compare(&kept, &from_file).unwrap();
    let m_without = compare(&kept, &without).unwrap();
    eprintln!(
        "against the exporter's next frame: from the file {m_file}\nwithout the blocks {m_without}"
    );
    assert!(m_file.relmse <= 1e-6, "relMSE {}", m_file.relmse);
    assert!(
        m_file.relmse * 10.0 <= m_without.relmse,
        "{} vs {}",
        m_file.relmse,
        m_without.relmse
    );
    drop((first, loaded, stripped, refused, gpu));
    finish(ctx);
}
