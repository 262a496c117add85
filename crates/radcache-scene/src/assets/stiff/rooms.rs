//! Rooms that are hard for a cache: light through a slit, a panel 1 mm above the floor, two
//! rooms sharing a zero-thickness wall, and a 15° wedge.

use glam::Vec3;
use serde_json::json;

use super::{camera, mesh_node, rect, StiffCheck, StiffScene};
use crate::assets::QuadSoup;
use crate::light::LightKind;
use crate::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc};

pub(super) fn scenes() -> Vec<StiffScene> {
    vec![
        StiffScene::new(
            "slit",
            "a room lit only through a 2 cm slit by a 10 cm light of radiance 1e4",
            StiffCheck::Reference(None),
            slit(),
        ),
        StiffScene::new(
            "panel",
            "a 1 m panel 1 mm above the floor, in the light",
            StiffCheck::Reference(None),
            panel(),
        ),
        StiffScene::new(
            "two_rooms",
            "a zero-thickness wall, light 5 cm from it on one side, the camera on the other",
            StiffCheck::Dark,
            two_rooms(),
        ),
        StiffScene::new(
            "wedge",
            "two plates meeting at 15° under a sky and a light",
            StiffCheck::Reference(None),
            wedge(),
        ),
    ]
}

/// A 4 m × 3 m × 4 m room (albedo 0.7) split at z = 1 by a zero-thickness wall with a slit
/// (y ∈ [1.49, 1.51], x ∈ [−0.5, 0.5]); behind it a 10 cm light of radiance 1e4 at z = 1.9,
/// facing the slit. The stripe it casts lands on the far wall; the camera looks at it.
fn slit() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.7; 3]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [1e4; 3]));
    let mut room = QuadSoup::default();
    room.cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 2.0), true);
    // The divider (normal axis z, spanning x then y), one-sided quads facing the room.
    for (x, y) in [
        ([-2.0, 2.0], [0.0, 1.49]),
        ([-2.0, 2.0], [1.51, 3.0]),
        ([-2.0, -0.5], [1.49, 1.51]),
        ([0.5, 2.0], [1.49, 1.51]),
    ] {
        room.quad(rect(2, 1.0, x, y), Vec3::NEG_Z);
    }
    let mut light = QuadSoup::default();
    light.quad(rect(2, 1.9, [-0.05, 0.05], [1.65, 1.75]), Vec3::NEG_Z);
    let room = b.add_mesh("room", &[room.primitive(wall)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let nodes = vec![
        mesh_node(&mut b, "room", room),
        mesh_node(&mut b, "lamp", light),
        camera(&mut b, Vec3::new(0.0, 1.5, 0.9), 0.0, -10.0, 80.0, 0.01),
    ];
    b.add_scene("slit", &nodes, None);
    b
}

/// A 4 m × 3 m × 4 m room (albedo 0.7) with a 1 m × 1 m panel (albedo 0.7, both faces) 1 mm
/// above the floor and a 0.5 m light of radiance 20 under the ceiling, off to the side.
fn panel() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.7; 3]));
    let board = b.add_material(&MaterialDesc::diffuse("panel", [0.6, 0.5, 0.4]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [20.0; 3]));
    let mut room = QuadSoup::default();
    room.cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 2.0), true);
    let mut top = QuadSoup::default();
    top.quad(rect(1, 0.001, [-0.5, 0.5], [-0.5, 0.5]), Vec3::Y);
    let mut light = QuadSoup::default();
    light.quad(rect(1, 2.99, [0.5, 1.0], [-0.25, 0.25]), Vec3::NEG_Y);
    let room = b.add_mesh("room", &[room.primitive(wall)]);
    let top = b.add_mesh("panel", &[top.primitive(board)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let nodes = vec![
        mesh_node(&mut b, "room", room),
        mesh_node(&mut b, "panel", top),
        mesh_node(&mut b, "lamp", light),
        camera(&mut b, Vec3::new(0.0, 1.2, 1.9), 0.0, -35.0, 60.0, 0.01),
    ];
    b.add_scene("panel", &nodes, None);
    b
}

/// Two 3 m × 2.5 m × 3 m rooms side by side (x < 0 dark, x > 0 lit) in one closed shell
/// (albedo 0.7), separated by a single one-sided quad at x = 0. The lit room has a ceiling light
/// (radiance 50) and a point light of 100 cd 5 cm from the wall; the camera stands in the dark
/// room looking at the wall. Every path from a light to the camera would have to cross the wall,
/// so the image must be black.
fn two_rooms() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.7; 3]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [50.0; 3]));
    let mut shell = QuadSoup::default();
    shell.cuboid(Vec3::new(0.0, 1.25, 0.0), Vec3::new(3.0, 1.25, 1.5), true);
    shell.quad(rect(0, 0.0, [0.0, 2.5], [-1.5, 1.5]), Vec3::NEG_X);
    let mut light = QuadSoup::default();
    light.quad(rect(1, 2.49, [-0.25, 0.25], [1.25, 1.75]), Vec3::NEG_Y);
    // rect(1, ..) spans z then x: the light sits at x ∈ [1.25, 1.75].
    let shell = b.add_mesh("shell", &[shell.primitive(wall)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let bulb = b.add_light(&LightDesc {
        name: Some("bulb".into()),
        kind: LightKind::Point,
        color: [1.0; 3],
        intensity: 100.0,
        range: None,
    });
    let bulb = b.add_node(&NodeDesc {
        name: Some("bulb".into()),
        translation: Some([0.05, 1.25, 0.0]),
        light: Some(bulb),
        ..NodeDesc::default()
    });
    let nodes = vec![
        mesh_node(&mut b, "shell", shell),
        mesh_node(&mut b, "lamp", light),
        bulb,
        camera(&mut b, Vec3::new(-2.8, 1.25, 0.0), -90.0, 0.0, 80.0, 0.01),
    ];
    b.add_scene("two_rooms", &nodes, None);
    b
}

/// A 2 m × 2 m floor plate and a plate hinged on its edge at x = 0, rising at 15° over it (both
/// albedo 0.7, seen from both sides), under a uniform sky of radiance 0.5 and a light of radiance
/// 10 above; the camera looks into the wedge's mouth.
fn wedge() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let grey = b.add_material(&MaterialDesc::diffuse("plates", [0.7; 3]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [10.0; 3]));
    let mut plates = QuadSoup::default();
    plates.quad(rect(1, 0.0, [-1.0, 1.0], [0.0, 2.0]), Vec3::Y);
    let (s, c) = 15f32.to_radians().sin_cos();
    let tip = Vec3::new(2.0 * c, 2.0 * s, 0.0);
    plates.quad(
        [
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, 1.0),
            tip + Vec3::Z,
            tip - Vec3::Z,
        ],
        Vec3::new(s, -c, 0.0),
    );
    let mut light = QuadSoup::default();
    light.quad(rect(1, 2.5, [-0.5, 0.5], [0.5, 1.5]), Vec3::NEG_Y);
    let plates = b.add_mesh("plates", &[plates.primitive(grey)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let nodes = vec![
        mesh_node(&mut b, "plates", plates),
        mesh_node(&mut b, "lamp", light),
        camera(&mut b, Vec3::new(2.9, 0.45, 0.0), 90.0, -8.0, 50.0, 0.01),
    ];
    b.add_scene(
        "wedge",
        &nodes,
        Some(json!({"environment": {"radiance": [0.5, 0.5, 0.5]}})),
    );
    b
}
