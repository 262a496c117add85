//! The radiance grid at the gather vertices (`PathGridMode`, docs/cache-frame.md §4.1) on
//! lavapipe: on the Cornell box the cache renders as close to the reference with the grid as
//! with full gather paths, for fewer record rays, and the same frame twice gives the same image
//! (the grid's reads see final sums whatever order the invocations run in); the record pass
//! compiles the grid only where the settings ask for it.

use std::path::PathBuf;

use radcache_cache::IcParams;
use radcache_image::{compare, read_exr, Image, Metrics};
use radcache_render::{
    passes::record::RecordPass, passes::record::RecordVariant, GpuScene, IcRenderer, IcSettings,
    IcStats, PathGridMode, SkyLight,
};
use radcache_shared::consts::GPU_RECORD_R_ORIG_WORD;
use radcache_shared::gpu::GpuRecord;
use radcache_tests::ic_fixture::cornell;
use radcache_tests::scenes::load;
use radcache_tests::{context, finish, shaders};

const SIZE: u32 = 128;
/// The reference is rendered at 256²: each of our pixels is the mean of a 2×2 block of it
/// (both are box filters over the pixel).
const FACTOR: u32 = 2;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The Cornell box's 2048-spp reference, box-filtered down to `SIZE`².
fn reference() -> Image {
    let (full, _) = read_exr(root().join("tests/refs/cornell_256.exr")).unwrap();
    assert_eq!(
        (full.width(), full.height()),
        (SIZE * FACTOR, SIZE * FACTOR)
    );
    let mut pixels = vec![[0.0f32; 3]; (SIZE * SIZE) as usize];
    let wide = SIZE * FACTOR;
    for (i, p) in full.pixels().enumerate() {
        let (x, y) = (i as u32 % wide, i as u32 / wide);
        let q = &mut pixels[((y / FACTOR) * SIZE + x / FACTOR) as usize];
        for c in 0..3 {
            q[c] += p[c] / (FACTOR * FACTOR) as f32;
        }
    }
    Image::from_pixels(SIZE, SIZE, pixels).unwrap()
}

fn settings(grid: PathGridMode) -> IcSettings {
    IcSettings {
        width: SIZE,
        height: SIZE,
        params: IcParams::default(),
        sub_frames: 8,
        path_grid: grid,
        ..IcSettings::default()
    }
}

#[test]
fn the_radiance_grid_matches_full_paths_with_fewer_rays() {
    let scene = cornell();
    assert!(scene.plan().path_grid());
    let reference = reference();
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    // Each frame from a fresh renderer; returns its image, its figures and its records as bits,
    // sorted (the order of the requests within a level is the order of the atomics), less
    // `R_orig`: neighbour clamping reads radii that other invocations are lowering, so its
    // chains can end a bit apart (with or without the grid).
    let mut render = |grid: PathGridMode| -> (Vec<[f32; 3]>, IcStats, Metrics, Vec<[u32; 44]>) {
        let s = settings(grid);
        let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &s).unwrap();
        let (out, stats) = r.render(&ctx, &scene, &mut gpu, &s, &mut |_| {}).unwrap();
        assert!(stats.records > 0 && stats.holes_left == 0, "{stats:?}");
        let m = compare(
            &reference,
            &Image::from_pixels(SIZE, SIZE, out.pixels.clone()).unwrap(),
        )
        .unwrap();
        eprintln!(
            "{grid:?}: {m}\nrecords {}, record rays {}",
            stats.records, stats.record_rays
        );
        assert_eq!(m.nonfinite_candidate, 0, "{grid:?}");
        for (c, r) in m.mean_ratio.iter().enumerate() {
            assert!(
                (r - 1.0).abs() <= 0.02,
                "{grid:?}: channel {c} mean ratio {r}"
            );
        }
        let records: Vec<GpuRecord> = ctx
            .read_buffer(&r.state().records, stats.records as usize)
            .unwrap();
        let mut bits: Vec<[u32; 44]> = records
            .iter()
            .map(|r| {
                let mut b: [u32; 44] = bytemuck::cast(*r);
                b[GPU_RECORD_R_ORIG_WORD as usize] = 0;
                b
            })
            .collect();
        bits.sort_unstable();
        (out.pixels, stats, m, bits)
    };
    let (_, off_stats, off, _) = render(PathGridMode::Off);
    let (on_pixels, on_stats, on, on_records) = render(PathGridMode::On);
    assert!(
        on.relmse <= 1.1 * off.relmse,
        "relMSE {:e} with the grid, {:e} with full paths",
        on.relmse,
        off.relmse
    );
    assert!(
        on.block_rmse <= 1.1 * off.block_rmse,
        "8×8-block RMSE {:e} with the grid, {:e} with full paths",
        on.block_rmse,
        off.block_rmse
    );
    assert!(
        on_stats.record_rays * 10 <= off_stats.record_rays * 9,
        "record rays {} with the grid, {} with full paths",
        on_stats.record_rays,
        off_stats.record_rays
    );
    // The same frame again: the same records, bit for bit, whatever order the invocations ran
    // in (but `R_orig`); the image up to the order of the splat's float blending.
    let (again_pixels, again_stats, _, again_records) = render(PathGridMode::On);
    assert_eq!(again_stats.record_rays, on_stats.record_rays);
    assert!(
        again_records == on_records,
        "the grid's records are not reproducible"
    );
    for (a, b) in again_pixels.iter().zip(&on_pixels) {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-5 * (1.0 + b[c].abs()),
                "{a:?} against {b:?}"
            );
        }
    }
    drop(gpu);
    finish(ctx);
}

#[test]
fn the_grid_is_compiled_where_the_plan_and_the_settings_ask_for_it() {
    let (ctx, shaders) = (context(), shaders());
    let params = IcParams::draft();
    // metal_spheres: metals and Lambertian walls (the grid serves the Lambertian vertices).
    for name in ["cornell/cornell.gltf", "metal_spheres/metal_spheres.gltf"] {
        let scene = load(&root().join("assets").join(name));
        assert!(scene.plan().path_grid(), "{name}");
        let gpu = GpuScene::new(&ctx, &scene, None).unwrap();
        for (mode, on) in [(PathGridMode::On, true), (PathGridMode::Off, false)] {
            let variant = RecordVariant {
                path_grid: mode,
                ..RecordVariant::new(params, SkyLight::Records)
            };
            let pass = RecordPass::new(&ctx, &shaders, &gpu, &variant).unwrap();
            assert_eq!(pass.path_grid(), on, "{name}, {mode:?}");
        }
        drop(gpu);
    }
    finish(ctx);
}
