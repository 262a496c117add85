//! The radiance grid kept over frames with the records (docs/temporal.md §3.8) on lavapipe, in
//! the sliding-box room: with the grid, the look-ahead's refreshes read cells that earlier frames
//! filled and cast far fewer rays per evaluated record than full paths; the last frame is as close
//! to a path-traced reference as with full paths, and unbiased.

use radcache_image::{compare, Image, Metrics};
use radcache_render::{
    render_path, Budget, FrameOutput, GpuScene, IcRenderer, IcSettings, PathGridMode, PathSettings,
};
use radcache_scene::Scene;
use radcache_tests::sliding_box;
use radcache_tests::{context, finish, shaders};
use radcache_vk::{Context, ShaderCompiler};

const SIZE: u32 = 48;
const LAST: u32 = 10;

fn settings(frame: u32, grid: PathGridMode) -> IcSettings {
    IcSettings {
        path_grid: grid,
        ..sliding_box::settings(SIZE, frame)
    }
}

/// What a kept sequence of frames 1..=LAST gave.
struct Run {
    last: FrameOutput,
    /// Records the look-ahead evaluated after frame 1 (expired and new).
    evaluated: u64,
    lookahead_rays: u64,
}

fn run(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    grid: PathGridMode,
) -> Run {
    let mut r = IcRenderer::new(ctx, shaders, gpu, &settings(1, grid)).unwrap();
    let (mut evaluated, mut lookahead_rays, mut last) = (0, 0, None);
    for frame in 1..=LAST {
        let (out, stats) = r
            .render(ctx, scene, gpu, &settings(frame, grid), &mut |_| {})
            .unwrap();
        assert_eq!(out.nonfinite_pixels, 0, "frame {frame}");
        // Frame 1's look-ahead evaluates every new record; later ones evaluate the frame's few
        // new records and the expired ones, which the kept grid serves.
        if frame > 1 {
            evaluated += stats.records_refreshed + (stats.records - stats.records_kept);
            lookahead_rays += stats.lookahead_rays;
        }
        last = Some(out);
    }
    Run {
        last: last.unwrap(),
        evaluated,
        lookahead_rays,
    }
}

fn image(o: &FrameOutput) -> Image {
    Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap()
}

#[test]
fn the_grid_kept_over_frames_serves_refreshes_without_bias() {
    let scene = sliding_box::sliding_box_scene("ic-path-grid-frames", false);
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let on = run(&ctx, &shaders, &scene, &mut gpu, PathGridMode::On);
    let off = run(&ctx, &shaders, &scene, &mut gpu, PathGridMode::Off);
    assert!(on.evaluated > 0 && off.evaluated > 0);
    let per = |r: &Run| r.lookahead_rays as f64 / r.evaluated as f64;
    eprintln!(
        "look-ahead rays per evaluated record: grid {:.0} ({} evaluated), full paths {:.0} ({})",
        per(&on),
        on.evaluated,
        per(&off),
        off.evaluated
    );
    assert!(
        per(&on) < 0.8 * per(&off),
        "the refreshes did not read the kept grid: {:.0} against {:.0} rays per record",
        per(&on),
        per(&off)
    );

    let path = PathSettings {
        width: SIZE,
        height: SIZE,
        budget: Budget::Samples(1024),
        seed: 11,
        frame: LAST,
        time: settings(LAST, PathGridMode::On).time,
        ..PathSettings::default()
    };
    let reference = render_path(&ctx, &shaders, &scene, &mut gpu, &path, &mut |_| {}).unwrap();
    let reference = image(&reference);
    let m_on: Metrics = compare(&reference, &image(&on.last)).unwrap();
    let m_off: Metrics = compare(&reference, &image(&off.last)).unwrap();
    eprintln!("grid kept over frames: {m_on}\nfull paths: {m_off}");
    assert!(
        m_on.relmse <= 1.2 * m_off.relmse,
        "grid {} against full paths {}",
        m_on.relmse,
        m_off.relmse
    );
    for (c, r) in m_on.mean_ratio.iter().enumerate() {
        assert!((r - 1.0).abs() <= 0.03, "channel {c} mean ratio {r}");
    }

    drop(gpu);
    finish(ctx);
}
