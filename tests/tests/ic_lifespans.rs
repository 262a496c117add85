//! Temporal radiance caching (`TemporalPass`, docs/temporal.md §3.3) on lavapipe: in a room where a
//! box slides along the floor, records follow their instance, only records near the box are
//! refreshed, lifespans follow the CPU formula (`radcache_cache::temporal`), and a frame
//! rendered with kept records stays as close to a path-traced reference of that frame as a
//! fresh cache; a record no pixel used in the previous frame is dropped when its lifespan ends
//! instead of being evaluated again.

use glam::Vec3;
use radcache_cache::temporal::temporal_lifespan;
use radcache_render::{
    passes::temporal::expires_at, GpuScene, IcRenderer, IcSettings, IcStats, PathGridMode,
};
use radcache_scene::Scene;
use radcache_shared::consts::TEMPORAL_FLAG_ADOPTED;
use radcache_shared::gpu::{GpuRecord, GpuRecordTemporal};
use radcache_tests::sliding_box::{self, box_centre, distance_to_path, FAR, HALF, NEAR};
use radcache_tests::{context, finish, shaders};
use radcache_vk::Context;

const SIZE: u32 = 48;

/// The longest lifespan here: long enough that the rate of change decides who is refreshed
/// (draft's own 5 frames refresh every record at least every 5 frames, far from the box too).
const MAX_AGE: f32 = 20.0;

fn settings(frame: u32) -> IcSettings {
    let mut s = sliding_box::settings(SIZE, frame);
    s.params.max_age_frames = MAX_AGE;
    s
}

/// [`settings`] with full gather paths: an evaluation through the radiance grid kept over frames
/// differs from the record's previous one by the noise of the cells refilled in between, which
/// shortens lifespans where the light did not change (docs/temporal.md §3.8: here far records
/// were evaluated again 0.12 times a frame against 0.02 with full paths). The rate's rule is
/// tested on full paths, whose refresh reproduces a record under unchanged light.
fn settings_full_paths(frame: u32) -> IcSettings {
    IcSettings {
        path_grid: PathGridMode::Off,
        ..settings(frame)
    }
}

fn sliding_box_scene(tag: &str) -> Scene {
    sliding_box::sliding_box_scene(tag, false)
}

struct Cache {
    records: Vec<GpuRecord>,
    temporal: Vec<GpuRecordTemporal>,
}

fn read(ctx: &Context, r: &IcRenderer, stats: &IcStats) -> Cache {
    let n = stats.records as usize;
    Cache {
        records: ctx.read_buffer(&r.state().records, n).unwrap(),
        temporal: ctx.read_buffer(&r.state().temporal, n).unwrap(),
    }
}

fn xyz(v: [f32; 4]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

#[test]
fn records_follow_their_instance_and_only_records_near_the_box_are_refreshed() {
    let scene = sliding_box_scene("ic-lifespans-follow");
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &settings_full_paths(1)).unwrap();
    let params = settings_full_paths(1).params;
    let (mut near, mut far, mut on_box) = (0usize, 0usize, 0usize);
    let (mut near_kept, mut far_kept) = (0usize, 0usize);
    let mut refreshed_total = 0u64;
    for frame in 1..=8u32 {
        let s = settings_full_paths(frame);
        let (out, stats) = r.render(&ctx, &scene, &mut gpu, &s, &mut |_| {}).unwrap();
        assert_eq!(out.nonfinite_pixels, 0);
        let c = read(&ctx, &r, &stats);
        let centre = box_centre(s.time);
        for (i, (rec, tr)) in c.records.iter().zip(&c.temporal).enumerate() {
            if tr.info[2] & 1 == 0 {
                continue; // rejected
            }
            let p = xyz(rec.position_radius);
            let d = distance_to_path(p);
            if frame > 1 && (i as u64) < stats.records_kept {
                // Kept from the frame before: may be refreshed this frame.
                near_kept += usize::from(d <= NEAR);
                far_kept += usize::from(d >= FAR);
            }
            // Records on the box (which only translates) keep their offset from its centre.
            let local = xyz(tr.object_position);
            if local.abs().max_element() <= HALF * 1.001 && (p - centre).length() < 2.0 * HALF {
                on_box += 1;
                let moved = (p - (centre + local)).length();
                assert!(
                    moved <= 1e-4,
                    "record {i} on the box is {moved} m off its point"
                );
            }
            // A record evaluated this frame (new, or expired and evaluated again) now knows its
            // value at the next frame, E_k, and has the CPU formula's lifespan over the span since
            // its previous known value (stagger ±20 %).
            if tr.info[1] == frame + 1 {
                let (ek, rate, span) = (xyz(tr.birth_irradiance), xyz(tr.gradient), tr.gradient[3]);
                let life = tr.object_position[3];
                let max_age = params.max_age_frames;
                let e_prev = ek - rate * span;
                let formula = span * temporal_lifespan(e_prev, ek, params.temporal_accuracy, 1e30);
                assert!(span >= 1.0, "record {i}: span {span}");
                assert!(life <= 1.2 * max_age + 1e-3, "record {i}: lifespan {life}");
                if life < 0.8 * max_age - 1e-3 {
                    let tol = 1e-3 * formula.max(1.0);
                    assert!((life - formula).abs() <= tol, "{i}: {life} vs {formula}");
                } else {
                    assert!(formula >= 0.8 * max_age * 0.999, "{i}: {life} vs {formula}");
                }
                if (i as u64) < stats.records_kept {
                    // Expired this frame and evaluated again.
                    near += usize::from(d <= NEAR);
                    far += usize::from(d >= FAR);
                }
            }
        }
        refreshed_total += stats.records_refreshed;
        if frame == 1 {
            assert_eq!(stats.records_refreshed, 0);
            assert!(stats.lookahead_rays > 0, "{stats:?}");
        }
    }
    // Refreshes per kept record and frame, near the box and far from it.
    let near_rate = near as f64 / near_kept.max(1) as f64;
    let far_rate = far as f64 / far_kept.max(1) as f64;
    eprintln!(
        "refreshed {refreshed_total}: near the box {near} of {near_kept} ({near_rate:.3}), \
         far {far} of {far_kept} ({far_rate:.3}); {on_box} records on the box"
    );
    assert!(on_box > 0, "no record on the box");
    assert!(
        near_kept >= 50 && far_kept >= 100,
        "{near_kept} near, {far_kept} far"
    );
    // Near the box irradiance changes by several % per frame: lifespans of a few frames.
    assert!(near_rate >= 0.06, "near rate {near_rate}");
    // Far away only the look-ahead's noise (paths that touch the box diverge) can shorten a
    // lifespan: rare.
    assert!(far_rate <= 0.02, "far rate {far_rate}");
    assert!(far_rate * 8.0 <= near_rate, "{far_rate} vs {near_rate}");
    drop((r, gpu));
    finish(ctx);
}

#[test]
fn a_frame_with_kept_records_is_as_close_to_the_reference_as_a_fresh_cache() {
    let scene = sliding_box_scene("ic-lifespans-reference");
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let last = 8u32;
    let mut kept = IcRenderer::new(&ctx, &shaders, &gpu, &settings(1)).unwrap();
    let mut out = None;
    let mut refreshed = 0;
    for frame in 1..=last {
        let (o, stats) = kept
            .render(&ctx, &scene, &mut gpu, &settings(frame), &mut |_| {})
            .unwrap();
        refreshed += stats.records_refreshed;
        out = Some(o);
    }
    assert!(refreshed > 0);
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
    for (c, r) in m_kept.mean_ratio.iter().enumerate() {
        assert!((r - 1.0).abs() <= 0.03, "channel {c} mean ratio {r}");
    }
    drop((kept, gpu));
    finish(ctx);
}

#[test]
fn records_unseen_when_their_lifespan_ends_are_dropped_not_refreshed() {
    let scene = sliding_box_scene("ic-lifespans-unseen");
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    // Draft's own lifespans (at most 5 frames ± 20 %): records expire every few frames.
    let s = |frame| sliding_box::settings(SIZE, frame);
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &s(1)).unwrap();
    // Every third record is made unseen in the last frame rendered (it last weighed on a pixel
    // the frame before); the first frame after which enough of them expire, and enough stay
    // valid, and enough seen ones expire, is the one the test renders next.
    let adopted = |t: &GpuRecordTemporal| t.info[2] & TEMPORAL_FLAG_ADOPTED != 0;
    let unseen = |i: usize, t: &GpuRecordTemporal| i.is_multiple_of(3) && adopted(t);
    let mut found = None;
    for last in 1..=16u32 {
        r.render(&ctx, &scene, &mut gpu, &s(last), &mut |_| {})
            .unwrap();
        let (records, temporal, marks) = r.state().download(&ctx).unwrap();
        let next = last + 1;
        let count = |f: &dyn Fn(usize, &GpuRecordTemporal) -> bool| {
            temporal
                .iter()
                .enumerate()
                .filter(|(i, t)| f(*i, t))
                .count()
        };
        let dropping = count(&|i, t| unseen(i, t) && expires_at(t, next));
        let staying = count(&|i, t| unseen(i, t) && !expires_at(t, next));
        let refreshing = count(&|i, t| !unseen(i, t) && expires_at(t, next));
        eprintln!(
            "after frame {last}: {} records, {dropping} unseen and expiring, {staying} unseen \
             and valid, {refreshing} seen and expiring",
            records.len()
        );
        if last >= 2 && dropping >= 10 && staying >= 10 && refreshing >= 10 {
            found = Some((last, records, temporal, marks));
            break;
        }
    }
    let (last, records, temporal, mut marks) =
        found.expect("no frame with enough expiring records");
    for (i, m) in marks.iter_mut().enumerate() {
        if unseen(i, &temporal[i]) {
            assert_eq!(*m, last, "record {i} was not used in frame {last}");
            *m = last - 1;
        }
    }
    r.state().upload(&ctx, &records, &temporal, &marks).unwrap();
    let next = last + 1;
    // Dropped: unseen in the frame before and expiring, or out of use for too long (eviction).
    let limit = s(next).evict_after_frames;
    let dropped: Vec<bool> = (0..records.len())
        .map(|i| {
            let (m, t) = (marks[i], &temporal[i]);
            m == 0 || next - m > limit || (next - m > 1 && expires_at(t, next))
        })
        .collect();
    let made_unseen = (0..records.len())
        .filter(|&i| dropped[i] && unseen(i, &temporal[i]))
        .count();
    assert!(
        made_unseen >= 10,
        "{made_unseen} of the records made unseen dropped"
    );
    let (_, stats) = r
        .render(&ctx, &scene, &mut gpu, &s(next), &mut |_| {})
        .unwrap();
    let n_dropped = dropped.iter().filter(|&&d| d).count();
    assert_eq!(stats.records_evicted, n_dropped as u64, "{stats:?}");
    // The kept records, in their order, are the others; every expiring one was evaluated again
    // for the frame after (the CPU twin of the advance's lifespan test agrees with the GPU's).
    let (_, after, _) = r.state().download(&ctx).unwrap();
    let survivors: Vec<usize> = (0..records.len()).filter(|&i| !dropped[i]).collect();
    assert_eq!(stats.records_kept as usize, survivors.len());
    for (k, &i) in survivors.iter().enumerate() {
        let (old, new) = (&temporal[i], &after[k]);
        assert_eq!(
            (xyz(old.object_position), old.info[0]),
            (xyz(new.object_position), new.info[0]),
            "kept record {k} is not record {i}"
        );
        if expires_at(old, next) {
            assert_eq!(
                new.info[1],
                next + 1,
                "record {i} expired and was not evaluated again"
            );
        }
    }
    drop((r, gpu));
    finish(ctx);
}
