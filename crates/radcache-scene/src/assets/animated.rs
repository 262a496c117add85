//! The animated scene (5 s): the Cornell room (walls, tall block, ceiling light) with
//!
//! - a camera flying in from the published Cornell viewpoint (LINEAR translation and rotation),
//! - a "mover" box (0.16 m) sliding across the front of the room and turning 180° (LINEAR),
//! - a "bouncer" cube (0.08 m) rising and falling (CUBICSPLINE translation, non-zero tangents) and
//!   changing size at 2 s and 4 s (STEP scale),
//! - a static point light (0.5 cd, warm white) below the ceiling,
//! - a constant environment of (0.05, 0.05, 0.08) W/(sr·m²) through `scenes[0].extras`.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde_json::json;

use super::cornell::{add_camera, add_materials, add_room};
use super::{write_named, yaw, QuadSoup};
use crate::animation::{Interpolation, Property};
use crate::error::Result;
use crate::light::LightKind;
use crate::writer::{ChannelDesc, GltfBuilder, LightDesc, MaterialDesc, NodeDesc};

/// Duration of the animated scene in seconds.
pub const ANIMATED_DURATION: f32 = 5.0;

fn cube_node(
    b: &mut GltfBuilder,
    name: &str,
    half: f32,
    rgb: [f32; 3],
    translation: [f32; 3],
) -> usize {
    let mat = b.add_material(&MaterialDesc::diffuse(name, rgb));
    let mut soup = QuadSoup::default();
    soup.cuboid(Vec3::ZERO, Vec3::splat(half), false);
    let mesh = b.add_mesh(name, &[soup.primitive(mat)]);
    b.add_node(&NodeDesc {
        name: Some(name.into()),
        translation: Some(translation),
        mesh: Some(mesh),
        ..NodeDesc::default()
    })
}

fn linear(node: usize, property: Property, times: &[f32], values: &[f32]) -> ChannelDesc {
    ChannelDesc {
        node,
        property,
        interpolation: Interpolation::Linear,
        times: times.to_vec(),
        values: values.to_vec(),
    }
}

/// The animated scene document.
pub fn animated_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut roots = add_room(&mut b, m);
    let mover = cube_node(&mut b, "mover", 0.08, [0.2, 0.3, 0.7], [0.15, 0.08, 0.12]);
    let bouncer = cube_node(&mut b, "bouncer", 0.04, [0.8, 0.7, 0.2], [0.12, 0.04, 0.42]);
    let camera = add_camera(&mut b, "camera");
    let light = b.add_light(&LightDesc {
        name: Some("bulb".into()),
        kind: LightKind::Point,
        color: [1.0, 0.9, 0.8],
        intensity: 0.5,
        range: None,
    });
    let bulb = b.add_node(&NodeDesc {
        name: Some("bulb".into()),
        translation: Some([0.45, 0.45, 0.12]),
        light: Some(light),
        ..NodeDesc::default()
    });
    roots.extend([mover, bouncer, camera, bulb]);

    let keys = [0.0, 2.5, ANIMATED_DURATION];
    let flat = |vs: &[[f32; 4]], n: usize| -> Vec<f32> {
        vs.iter().flat_map(|v| v[..n].to_vec()).collect()
    };
    let cam_t = flat(
        &[
            [0.278, 0.273, -0.8, 0.0],
            [0.278, 0.3, -0.2, 0.0],
            [0.35, 0.3, 0.1, 0.0],
        ],
        3,
    );
    let cam_r = flat(&[yaw(180.0), yaw(180.0), yaw(195.0)], 4);
    let mover_t = flat(
        &[
            [0.15, 0.08, 0.12, 0.0],
            [0.40, 0.08, 0.12, 0.0],
            [0.15, 0.08, 0.12, 0.0],
        ],
        3,
    );
    let mover_r = flat(&[yaw(0.0), yaw(90.0), yaw(180.0)], 4);
    // CUBICSPLINE: per key (in-tangent, value, out-tangent).
    let bounce = [
        [0.0, 0.0, 0.0],
        [0.12, 0.04, 0.42],
        [0.0, 0.3, 0.0],
        [0.0, -0.1, 0.0],
        [0.12, 0.30, 0.42],
        [0.0, -0.1, 0.0],
        [0.0, -0.3, 0.0],
        [0.12, 0.04, 0.42],
        [0.0, 0.0, 0.0],
    ];
    let step_s = [[1.0f32; 3], [1.5; 3], [1.0; 3]];
    let channels = [
        linear(camera, Property::Translation, &keys, &cam_t),
        linear(camera, Property::Rotation, &keys, &cam_r),
        linear(mover, Property::Translation, &keys, &mover_t),
        linear(mover, Property::Rotation, &keys, &mover_r),
        ChannelDesc {
            node: bouncer,
            property: Property::Translation,
            interpolation: Interpolation::CubicSpline,
            times: keys.to_vec(),
            values: bounce.iter().flatten().copied().collect(),
        },
        ChannelDesc {
            node: bouncer,
            property: Property::Scale,
            interpolation: Interpolation::Step,
            times: vec![0.0, 2.0, 4.0],
            values: step_s.iter().flatten().copied().collect(),
        },
    ];
    b.add_animation("fly_through", &channels);
    let extras = json!({"environment": {"radiance": [0.05, 0.05, 0.08]}});
    b.add_scene("animated_room", &roots, Some(extras));
    b
}

/// Writes `dir/animated/animated.gltf` (+ `.bin`).
pub fn write_animated(dir: &Path) -> Result<PathBuf> {
    write_named(&animated_builder(), dir, "animated")
}
