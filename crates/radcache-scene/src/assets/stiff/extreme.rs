//! Furnaces (analytic), the Cornell box at extreme scales, a tiny very bright emitter, a
//! grazing view with geometry through the near plane, and the glossy cases: a rough metal floor
//! under a small bright emitter and seen at grazing angles.

use glam::Vec3;
use serde_json::json;

use super::{camera, mesh_node, rect, StiffCheck, StiffScene};
use crate::assets::{cornell_scaled_builder, furnace_builder, QuadSoup};
use crate::writer::{GltfBuilder, MaterialDesc};

/// The furnaces: albedo 0.5, 0.9, 0.99 (analytic) and exactly 1 (unbounded), emission 1.
pub(super) fn furnaces() -> Vec<StiffScene> {
    let analytic = |name, albedo: f32| {
        StiffScene::new(
            name,
            "closed box, uniform albedo and emission 1: Le/(1-ρ)",
            StiffCheck::Analytic(1.0 / (1.0 - albedo)),
            furnace_builder(albedo, 1.0),
        )
    };
    vec![
        analytic("furnace_0.5", 0.5),
        analytic("furnace_0.9", 0.9),
        analytic("furnace_0.99", 0.99),
        StiffScene::new(
            "furnace_1.0",
            "closed box of albedo exactly 1: the radiance is infinite; output must stay finite",
            StiffCheck::Unbounded,
            furnace_builder(1.0, 1.0),
        ),
    ]
}

/// The scale cases, the tiny bright emitter and the grazing view.
pub(super) fn scenes() -> Vec<StiffScene> {
    vec![
        StiffScene::new(
            "cornell_1",
            "the Cornell box at scale 1 (the scale cases' reference)",
            StiffCheck::Reference(None),
            cornell_scaled_builder(1.0),
        ),
        StiffScene::new(
            "cornell_1e-3",
            "the Cornell box scaled by 1e-3 (0.55 mm)",
            StiffCheck::Reference(Some("cornell_1")),
            cornell_scaled_builder(1e-3),
        ),
        StiffScene::new(
            "cornell_1e4",
            "the Cornell box scaled by 1e4 (5.5 km)",
            StiffCheck::Reference(Some("cornell_1")),
            cornell_scaled_builder(1e4),
        ),
        StiffScene::new(
            "tiny_bright",
            "a 1 cm emitter of radiance 1e6 in a 4 m room",
            StiffCheck::Reference(None),
            tiny_bright(),
        ),
        StiffScene::new(
            "grazing",
            "a 200 m floor seen from 30 cm under a sky, boxes, a plank through the near plane",
            StiffCheck::Reference(None),
            grazing(),
        ),
        StiffScene::new(
            "glossy_bright",
            "a rough metal floor (roughness 0.65) under a 4 cm emitter of radiance 1e4",
            StiffCheck::Reference(None),
            glossy_bright(),
        ),
        StiffScene::new(
            "glossy_grazing",
            "a rough metal floor (roughness 0.7) under a sky, seen from 30 cm at grazing angles",
            StiffCheck::Reference(None),
            glossy_grazing(),
        ),
    ]
}

/// A 4 m × 3 m × 4 m room (albedo 0.5, inward) whose floor is a rough gold metal (roughness
/// 0.65, above the radiance records' threshold), a 4 cm × 4 cm emitter of radiance 1e4 just
/// below the ceiling, facing down, and a white box beside it; the camera looks down across the
/// floor. The floor's glossy lobe sees the walls' light, sharply bright around the emitter's spot.
fn glossy_bright() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.5; 3]));
    let metal = b.add_material(&MaterialDesc::metal_rough(
        "floor",
        [1.0, 0.8, 0.4],
        1.0,
        0.65,
    ));
    let white = b.add_material(&MaterialDesc::diffuse("box", [0.8; 3]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [1e4; 3]));
    let mut room = QuadSoup::default();
    room.cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 2.0), true);
    let mut floor = QuadSoup::default();
    floor.quad(rect(1, 0.001, [-2.0, 2.0], [-2.0, 2.0]), Vec3::Y);
    let mut cube = QuadSoup::default();
    cube.cuboid(Vec3::new(0.8, 0.4, -0.6), Vec3::splat(0.4), false);
    let mut light = QuadSoup::default();
    light.quad(rect(1, 2.99, [-0.02, 0.02], [-0.02, 0.02]), Vec3::NEG_Y);
    let room = b.add_mesh("room", &[room.primitive(wall)]);
    let floor = b.add_mesh("floor", &[floor.primitive(metal)]);
    let cube = b.add_mesh("box", &[cube.primitive(white)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let nodes = vec![
        mesh_node(&mut b, "room", room),
        mesh_node(&mut b, "floor", floor),
        mesh_node(&mut b, "box", cube),
        mesh_node(&mut b, "lamp", light),
        camera(&mut b, Vec3::new(0.0, 1.4, 1.9), 0.0, -30.0, 75.0, 0.01),
    ];
    b.add_scene("glossy_bright", &nodes, None);
    b
}

/// A 4 m × 3 m × 4 m room (albedo 0.5, inward) with a 1 cm × 1 cm emitter of radiance 1e6 just
/// below the ceiling, facing down; the camera looks across the room.
fn tiny_bright() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.5; 3]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [1e6; 3]));
    let mut room = QuadSoup::default();
    room.cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 2.0), true);
    let mut light = QuadSoup::default();
    light.quad(rect(1, 2.99, [-0.005, 0.005], [-0.005, 0.005]), Vec3::NEG_Y);
    let room = b.add_mesh("room", &[room.primitive(wall)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let nodes = vec![
        mesh_node(&mut b, "room", room),
        mesh_node(&mut b, "lamp", light),
        camera(&mut b, Vec3::new(0.0, 1.6, 1.9), 0.0, -20.0, 75.0, 0.01),
    ];
    b.add_scene("tiny_bright", &nodes, None);
    b
}

/// A 200 m × 200 m floor (albedo 0.5) under a uniform sky of radiance 1, five 1 m boxes along
/// the view at 2–40 m, and a plank (0.18 m × 0.06 m × 2 m) from behind the camera into the view,
/// crossing the near plane (0.05 m). The camera sits 0.3 m above the floor, pitched 5° down.
fn grazing() -> GltfBuilder {
    grazing_floor("grazing", &MaterialDesc::diffuse("floor", [0.5; 3]), true)
}

/// [`grazing`]'s floor and boxes with the floor a rough white metal (roughness 0.7) and no
/// plank: the floor's lobes point towards the horizon, where the boxes stand.
fn glossy_grazing() -> GltfBuilder {
    let metal = MaterialDesc::metal_rough("floor", [0.9; 3], 1.0, 0.7);
    grazing_floor("glossy_grazing", &metal, false)
}

/// The grazing scenes: the floor of material `floor`, the boxes, the plank if asked, the sky.
fn grazing_floor(name: &str, floor_material: &MaterialDesc, plank: bool) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let grey = b.add_material(floor_material);
    let white = b.add_material(&MaterialDesc::diffuse("box", [0.8, 0.7, 0.6]));
    let mut floor = QuadSoup::default();
    floor.quad(rect(1, 0.0, [-100.0, 100.0], [-100.0, 100.0]), Vec3::Y);
    let mut boxes = QuadSoup::default();
    for (i, z) in [2.0f32, 5.0, 10.0, 20.0, 40.0].into_iter().enumerate() {
        let x = if i % 2 == 0 { -0.8 } else { 0.9 };
        boxes.cuboid(Vec3::new(x, 0.5, -z), Vec3::splat(0.5), false);
    }
    if plank {
        boxes.cuboid(
            Vec3::new(0.11, 0.23, -0.5),
            Vec3::new(0.09, 0.03, 1.0),
            false,
        );
    }
    let floor = b.add_mesh("floor", &[floor.primitive(grey)]);
    let boxes = b.add_mesh("boxes", &[boxes.primitive(white)]);
    let nodes = vec![
        mesh_node(&mut b, "floor", floor),
        mesh_node(&mut b, "boxes", boxes),
        camera(&mut b, Vec3::new(0.0, 0.3, 0.0), 0.0, -5.0, 60.0, 0.05),
    ];
    b.add_scene(
        name,
        &nodes,
        Some(json!({"environment": {"radiance": [1.0, 1.0, 1.0]}})),
    );
    b
}
