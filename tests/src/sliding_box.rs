//! The sliding-box room of the temporal tests (`ic_lifespans`, `radiance_temporal`): a 4 × 2.5 ×
//! 6 m grey room lit by a ceiling panel, a red box sliding along the floor for half a second and
//! a static camera near one wall; optionally a rough metal plate on the floor (a glossy lobe wide
//! enough for the radiance records) that the box slides across.

use glam::{Quat, Vec3};
use radcache_cache::IcParams;
use radcache_image::{compare, Image, Metrics};
use radcache_render::{
    render_path, Budget, FrameOutput, GpuScene, IcRenderer, IcSettings, PathSettings,
};
use radcache_scene::writer::{ChannelDesc, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{AnimationKind, Interpolation, Property, Scene};
use radcache_vk::{Context, ShaderCompiler};

use crate::geometry::room;
use crate::scenes::{camera_node, cube, plane_y, temp_dir, write_and_load};

/// Frames per second of the sequence.
pub const FPS: f32 = 24.0;
/// The box's half-size (m).
pub const HALF: f32 = 0.25;
/// The z of the box's path.
pub const Z_BOX: f32 = -1.6;
/// Records this far from the box's path (m; the room is 4 m × 6 m) see it under a small solid
/// angle: their indirect light changes by well under 1 % per frame.
pub const FAR: f32 = 3.0;
/// Records this close to the box's path see it large (m).
pub const NEAR: f32 = 0.8;
/// Roughness of the floor plate of [`sliding_box_scene`] with `glossy_floor`.
pub const PLATE_ROUGHNESS: f32 = 0.7;

/// The box's centre at time `t`: x from −1.6 to −0.4 over 0.5 s (0.1 m per frame at 24 fps).
pub fn box_centre(t: f32) -> Vec3 {
    let s = (t / 0.5).clamp(0.0, 1.0);
    Vec3::new(-1.6 + 1.2 * s, HALF, Z_BOX)
}

/// Distance from `p` to the segment the box's centre sweeps.
pub fn distance_to_path(p: Vec3) -> f32 {
    let (a, b) = (box_centre(0.0), box_centre(1.0));
    let s = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    (p - (a + (b - a) * s)).length()
}

/// The room, written under the temporary folder `tag`; with `glossy_floor` a 3 × 4 m plate of
/// rough metal ([`PLATE_ROUGHNESS`]) lies 1 mm above the floor, under the box's path.
pub fn sliding_box_scene(tag: &str, glossy_floor: bool) -> Scene {
    let mut b = GltfBuilder::new();
    let grey = b.add_material(&MaterialDesc::diffuse("grey", [0.7; 3]));
    let red = b.add_material(&MaterialDesc::diffuse("red", [0.8, 0.15, 0.1]));
    let mut light = MaterialDesc::diffuse("light", [0.0; 3]);
    light.emissive = [6.0; 3];
    let light = b.add_material(&light);
    let walls = room(Vec3::new(-2.0, 0.0, -2.0), Vec3::new(2.0, 2.5, 4.0));
    let corners: Vec<[f32; 3]> = walls.positions.iter().map(|p| p.to_array()).collect();
    let room_mesh = b.add_mesh(
        "room",
        &[PrimitiveDesc::triangles(
            corners,
            None,
            walls.indices,
            Some(grey),
        )],
    );
    let boxy = b.add_mesh("box", &[cube(HALF, red)]);
    let panel = b.add_mesh("panel", &[plane_y([-0.5, 0.5], [-0.5, 0.5], 0.0, light)]);
    let room_node = b.add_node(&NodeDesc {
        mesh: Some(room_mesh),
        ..Default::default()
    });
    let box_node = b.add_node(&NodeDesc {
        name: Some("box".into()),
        mesh: Some(boxy),
        translation: Some(box_centre(0.0).to_array()),
        ..Default::default()
    });
    let panel_node = b.add_node(&NodeDesc {
        mesh: Some(panel),
        translation: Some([0.0, 2.45, 0.0]),
        rotation: Some(Quat::from_rotation_x(std::f32::consts::PI).to_array()),
        ..Default::default()
    });
    let camera = camera_node(
        &mut b,
        Vec3::new(0.0, 1.6, 3.9),
        Quat::from_rotation_x(-0.45),
        1.2,
    );
    let (a, e) = (box_centre(0.0), box_centre(0.5));
    b.add_animation(
        "slide",
        &[ChannelDesc {
            node: box_node,
            property: Property::Translation,
            interpolation: Interpolation::Linear,
            times: vec![0.0, 0.5],
            values: [a, e].iter().flat_map(|v| v.to_array()).collect(),
        }],
    );
    let mut nodes = vec![room_node, box_node, panel_node, camera];
    if glossy_floor {
        let metal = MaterialDesc::metal_rough("plate", [0.9, 0.85, 0.8], 1.0, PLATE_ROUGHNESS);
        let metal = b.add_material(&metal);
        let plate = b.add_mesh("plate", &[plane_y([-1.5, 1.5], [-2.0, 2.0], 0.001, metal)]);
        nodes.push(b.add_node(&NodeDesc {
            mesh: Some(plate),
            ..Default::default()
        }));
    }
    b.add_scene("slide", &nodes, None);
    let scene = write_and_load(&b, &temp_dir(tag), "slide");
    assert_eq!(scene.plan().animation.kind, AnimationKind::Geometry);
    assert!(scene.plan().needs_lifespans());
    assert_eq!(
        scene.plan().radiance_cache(),
        glossy_floor,
        "{}",
        scene.plan()
    );
    scene
}

/// Frame `frame` (from 1) of the sequence at `size`², draft parameters, 4 sub-frames, temporal
/// caching with lifespans.
pub fn settings(size: u32, frame: u32) -> IcSettings {
    IcSettings {
        width: size,
        height: size,
        params: IcParams::draft(),
        sub_frames: 4,
        direct_samples: 4,
        seed: 3,
        frame,
        time: (frame - 1) as f32 / FPS,
        record_capacity: 1 << 14,
        settle_records: true,
        time_step_s: 1.0 / FPS,
        ..IcSettings::default()
    }
}

/// Frame `last` of a sequence (`kept`, rendered with kept records at `size`²) and a fresh cache
/// of that frame, each against a 1024-spp path-traced reference: (kept, fresh), printed.
pub fn against_fresh_cache(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    size: u32,
    last: u32,
    kept: &FrameOutput,
) -> (Metrics, Metrics) {
    let fresh_settings = IcSettings {
        time_step_s: 0.0,
        ..settings(size, last)
    };
    let mut fresh = IcRenderer::new(ctx, shaders, gpu, &fresh_settings).unwrap();
    let (fresh_out, _) = fresh
        .render(ctx, scene, gpu, &fresh_settings, &mut |_| {})
        .unwrap();
    drop(fresh);
    let path = PathSettings {
        width: size,
        height: size,
        budget: Budget::Samples(1024),
        seed: 11,
        frame: last,
        time: settings(size, last).time,
        ..PathSettings::default()
    };
    let reference = render_path(ctx, shaders, scene, gpu, &path, &mut |_| {}).unwrap();
    let image = |o: &FrameOutput| Image::from_pixels(o.width, o.height, o.pixels.clone()).unwrap();
    let reference = image(&reference);
    let m_kept = compare(&reference, &image(kept)).unwrap();
    let m_fresh = compare(&reference, &image(&fresh_out)).unwrap();
    eprintln!("kept records: {m_kept}\nfresh cache: {m_fresh}");
    (m_kept, m_fresh)
}
