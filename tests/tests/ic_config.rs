//! The cache renderer's settings between frames, on lavapipe: every field of `IcSettings` that
//! makes the renderer (`IcSettings::CONFIG_FIELDS`, generated from the struct's declaration)
//! refuses to change on a later frame, with an error naming it, and leaves the renderer usable;
//! every per-frame field (`IcSettings::FRAME_FIELDS`) may change.

use std::path::PathBuf;

use radcache_cache::IcParams;
use radcache_render::{
    AntiAliasing, EmitterLight, EmitterShadows, GlossyLight, GlossySpacing, GpuScene, IcRenderer,
    IcSettings, PathGridMode, SkyLight, SpecularPaths, SplatMode,
};
use radcache_scene::{LoadOptions, Scene};
use radcache_tests::{context, finish, shaders};

const SIZE: u32 = 16;

fn base() -> IcSettings {
    IcSettings {
        width: SIZE,
        height: SIZE,
        params: IcParams::draft(),
        sub_frames: 1,
        direct_samples: 4,
        record_capacity: 1 << 12,
        ..IcSettings::default()
    }
}

/// `base` with the field `name` set to another value. Every field of the generated lists must
/// have a case here: a field added to `IcSettings` fails this test until it has one.
fn varied(base: &IcSettings, name: &str) -> IcSettings {
    let mut s = base.clone();
    match name {
        "width" => s.width += 1,
        "height" => s.height += 1,
        "params" => s.params = IcParams::default(),
        "record_capacity" => s.record_capacity /= 2,
        "settle_records" => s.settle_records = !s.settle_records,
        "time_step_s" => s.time_step_s = 1.0 / 24.0,
        "sky" => s.sky = SkyLight::Direct,
        "emitters" => s.emitters = EmitterLight::Sampled,
        "emitter_shadows" => s.emitter_shadows = EmitterShadows::Fixed,
        "glossy" => s.glossy = GlossyLight::Paths,
        "glossy_spacing" => s.glossy_spacing = GlossySpacing::Irradiance,
        "anti_aliasing" => {
            s.anti_aliasing = Some(AntiAliasing::preset(radcache_cache::Preset::Draft))
        }
        "splat" => s.splat = SplatMode::PerSubFrame,
        "path_grid" => s.path_grid = PathGridMode::Off,
        "specular_paths" => s.specular_paths = SpecularPaths::PerPixel,
        "sub_frames" => s.sub_frames = 2,
        "direct_samples" => s.direct_samples = 8,
        "seed" => s.seed = 7,
        "frame" => s.frame = 2,
        "time" => s.time = 0.5,
        "debug_aovs" => s.debug_aovs = !s.debug_aovs,
        "evict_after_frames" => s.evict_after_frames = 5,
        other => panic!("no variation for the IcSettings field `{other}`: add one here"),
    }
    assert_ne!(&s, base, "the variation of `{name}` changes nothing");
    s
}

#[test]
fn the_field_lists_cover_distinct_fields() {
    let all: Vec<&str> = IcSettings::CONFIG_FIELDS
        .iter()
        .chain(IcSettings::FRAME_FIELDS)
        .copied()
        .collect();
    let mut unique = all.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), all.len(), "a field is listed twice: {all:?}");
    assert!(IcSettings::CONFIG_FIELDS.contains(&"emitters"));
    assert!(IcSettings::FRAME_FIELDS.contains(&"seed"));
    let b = base();
    for &name in IcSettings::CONFIG_FIELDS {
        let change = varied(&b, name).config_change(&b);
        assert_eq!(change.map(|c| c.field), Some(name));
    }
    for &name in IcSettings::FRAME_FIELDS {
        assert_eq!(varied(&b, name).config_change(&b), None, "{name}");
    }
    // A renderer made with adaptive anti-aliasing may shade a frame without it, or with another
    // target (its composite has the moments); one made without may not take it on.
    let with_aa = varied(&b, "anti_aliasing");
    let aa = with_aa.anti_aliasing.unwrap();
    let other_target = IcSettings {
        anti_aliasing: Some(AntiAliasing {
            target: aa.target * 2.0,
            ..aa
        }),
        ..with_aa.clone()
    };
    assert_eq!(b.config_change(&with_aa), None);
    assert_eq!(other_target.config_change(&with_aa), None);
    let refused = with_aa.config_change(&b).unwrap();
    assert_eq!(refused.field, "anti_aliasing");
}

#[test]
fn config_fields_refuse_to_change_between_frames_and_frame_fields_may() {
    let path = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/cornell/cornell.gltf"
    ));
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap().0;
    let (ctx, shaders) = (context(), shaders());
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let b = base();
    let mut r = IcRenderer::new(&ctx, &shaders, &gpu, &b).unwrap();
    let (first, _) = r.render(&ctx, &scene, &mut gpu, &b, &mut |_| {}).unwrap();
    for &name in IcSettings::CONFIG_FIELDS {
        let err = r
            .render(&ctx, &scene, &mut gpu, &varied(&b, name), &mut |_| {})
            .expect_err(name)
            .to_string();
        assert!(
            err.contains(&format!("`{name}` cannot change between frames")),
            "{name}: {err}"
        );
    }
    // The refusals changed nothing: the same frame again keeps its records and its image.
    let (again, stats) = r.render(&ctx, &scene, &mut gpu, &b, &mut |_| {}).unwrap();
    assert_eq!(stats.records_per_level.iter().sum::<u64>(), 0, "{stats:?}");
    assert_eq!(again.pixels.len(), first.pixels.len());
    for &name in IcSettings::FRAME_FIELDS {
        let s = varied(&b, name);
        let (out, _) = r
            .render(&ctx, &scene, &mut gpu, &s, &mut |_| {})
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(out.pixels.iter().flatten().all(|v| v.is_finite()), "{name}");
    }
    drop(r);
    drop(gpu);
    finish(ctx);
}
