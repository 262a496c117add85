//! The Cornell box from the published Cornell Program of Computer Graphics data.
//!
//! Geometry: the published vertex lists (millimetres) converted to metres, kept in the published
//! frame (box corner at the origin, +Y up, the open side towards −Z). The light quad is moved 3 mm
//! below the ceiling (y = 545.8 mm instead of 548.8 mm) and faces down. Quads are re-oriented so
//! that walls face the inside and blocks face outward (normals are flat per quad).
//!
//! Camera: published position (278, 273, −800) mm looking along +Z with +Y up (a glTF camera node
//! rotated 180° about Y); focal length 0.035 m with a 0.025 m square film →
//! yfov = 2·atan(0.0125 / 0.035) ≈ 39.3°, aspect 1. Looking along +Z with +Y up in this
//! right-handed frame, image right is −X, so the red wall (x ≈ 0.55 m) is on the LEFT and the
//! green wall (x = 0) on the right, as in the reference photographs.
//!
//! Materials (RGB approximations of the published spectral reflectances): white (0.73, 0.73, 0.73),
//! red (0.63, 0.065, 0.05), green (0.14, 0.45, 0.091); the light has albedo 0.78 and emits
//! (17, 12, 4) W/(sr·m²) (emissiveFactor (1, 12/17, 4/17) × emissiveStrength 17).

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::{write_named, yaw, QuadSoup};
use crate::animation::{Interpolation, Property};
use crate::error::Result;
use crate::writer::{ChannelDesc, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};

/// Vertical field of view of the published camera: 2·atan(0.0125 / 0.035).
pub const CORNELL_YFOV: f32 = 0.686_047_9;

/// Published camera position in metres.
pub(crate) const CAMERA_POSITION: [f32; 3] = [0.278, 0.273, -0.8];

type Quad = [[f32; 3]; 4];

const FLOOR: Quad = [
    [552.8, 0.0, 0.0],
    [0.0, 0.0, 0.0],
    [0.0, 0.0, 559.2],
    [549.6, 0.0, 559.2],
];
const CEILING: Quad = [
    [556.0, 548.8, 0.0],
    [556.0, 548.8, 559.2],
    [0.0, 548.8, 559.2],
    [0.0, 548.8, 0.0],
];
const BACK_WALL: Quad = [
    [549.6, 0.0, 559.2],
    [0.0, 0.0, 559.2],
    [0.0, 548.8, 559.2],
    [556.0, 548.8, 559.2],
];
const GREEN_WALL: Quad = [
    [0.0, 0.0, 559.2],
    [0.0, 0.0, 0.0],
    [0.0, 548.8, 0.0],
    [0.0, 548.8, 559.2],
];
const RED_WALL: Quad = [
    [552.8, 0.0, 0.0],
    [549.6, 0.0, 559.2],
    [556.0, 548.8, 559.2],
    [556.0, 548.8, 0.0],
];
const LIGHT_Y: f32 = 545.8;
const LIGHT: Quad = [
    [343.0, LIGHT_Y, 227.0],
    [343.0, LIGHT_Y, 332.0],
    [213.0, LIGHT_Y, 332.0],
    [213.0, LIGHT_Y, 227.0],
];

const SHORT_BLOCK: [Quad; 5] = [
    [
        [130.0, 165.0, 65.0],
        [82.0, 165.0, 225.0],
        [240.0, 165.0, 272.0],
        [290.0, 165.0, 114.0],
    ],
    [
        [290.0, 0.0, 114.0],
        [290.0, 165.0, 114.0],
        [240.0, 165.0, 272.0],
        [240.0, 0.0, 272.0],
    ],
    [
        [130.0, 0.0, 65.0],
        [130.0, 165.0, 65.0],
        [290.0, 165.0, 114.0],
        [290.0, 0.0, 114.0],
    ],
    [
        [82.0, 0.0, 225.0],
        [82.0, 165.0, 225.0],
        [130.0, 165.0, 65.0],
        [130.0, 0.0, 65.0],
    ],
    [
        [240.0, 0.0, 272.0],
        [240.0, 165.0, 272.0],
        [82.0, 165.0, 225.0],
        [82.0, 0.0, 225.0],
    ],
];

const TALL_BLOCK: [Quad; 5] = [
    [
        [423.0, 330.0, 247.0],
        [265.0, 330.0, 296.0],
        [314.0, 330.0, 456.0],
        [472.0, 330.0, 406.0],
    ],
    [
        [423.0, 0.0, 247.0],
        [423.0, 330.0, 247.0],
        [472.0, 330.0, 406.0],
        [472.0, 0.0, 406.0],
    ],
    [
        [472.0, 0.0, 406.0],
        [472.0, 330.0, 406.0],
        [314.0, 330.0, 456.0],
        [314.0, 0.0, 456.0],
    ],
    [
        [314.0, 0.0, 456.0],
        [314.0, 330.0, 456.0],
        [265.0, 330.0, 296.0],
        [265.0, 0.0, 296.0],
    ],
    [
        [265.0, 0.0, 296.0],
        [265.0, 330.0, 296.0],
        [423.0, 330.0, 247.0],
        [423.0, 0.0, 247.0],
    ],
];

/// Millimetres → metres.
fn metres(q: &Quad) -> [Vec3; 4] {
    q.map(|p| Vec3::from(p) * 0.001)
}

fn centroid(q: &[Vec3; 4]) -> Vec3 {
    (q[0] + q[1] + q[2] + q[3]) * 0.25
}

/// Material indices of the Cornell box.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CornellMaterials {
    pub(crate) white: usize,
    pub(crate) red: usize,
    pub(crate) green: usize,
    pub(crate) light: usize,
}

pub(crate) fn add_materials(b: &mut GltfBuilder) -> CornellMaterials {
    CornellMaterials {
        white: b.add_material(&MaterialDesc::diffuse("white", [0.73, 0.73, 0.73])),
        red: b.add_material(&MaterialDesc::diffuse("red", [0.63, 0.065, 0.05])),
        green: b.add_material(&MaterialDesc::diffuse("green", [0.14, 0.45, 0.091])),
        light: b.add_material(&MaterialDesc::emitter(
            "light",
            [0.78, 0.78, 0.78],
            [17.0, 12.0, 4.0],
        )),
    }
}

fn node(b: &mut GltfBuilder, name: &str, mesh: usize) -> usize {
    b.add_node(&NodeDesc {
        name: Some(name.into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    })
}

/// Adds the room (white floor/ceiling/back, red left wall, green right wall), the tall block and
/// the light, each as a mesh with its node; returns the node indices.
pub(crate) fn add_room(b: &mut GltfBuilder, m: CornellMaterials) -> Vec<usize> {
    let inside = Vec3::new(0.278, 0.274, 0.280);
    let wall = |soup: &mut QuadSoup, q: &Quad| {
        let q = metres(q);
        soup.quad(q, inside - centroid(&q));
    };
    let (mut white, mut red, mut green) = (
        QuadSoup::default(),
        QuadSoup::default(),
        QuadSoup::default(),
    );
    for q in [&FLOOR, &CEILING, &BACK_WALL] {
        wall(&mut white, q);
    }
    wall(&mut red, &RED_WALL);
    wall(&mut green, &GREEN_WALL);
    let room = b.add_mesh(
        "room",
        &[
            white.primitive(m.white),
            red.primitive(m.red),
            green.primitive(m.green),
        ],
    );
    let tall = add_block(b, "tall_block", &TALL_BLOCK, m.white);
    let mut light = QuadSoup::default();
    light.quad(metres(&LIGHT), -Vec3::Y);
    let light = b.add_mesh("light", &[light.primitive(m.light)]);
    vec![
        node(b, "room", room),
        node(b, "tall_block", tall),
        node(b, "light", light),
    ]
}

fn add_block(b: &mut GltfBuilder, name: &str, quads: &[Quad; 5], material: usize) -> usize {
    let qs: Vec<[Vec3; 4]> = quads.iter().map(metres).collect();
    let top = &qs[0];
    let center = Vec3::new(centroid(top).x, top[0].y * 0.5, centroid(top).z);
    let mut soup = QuadSoup::default();
    for q in &qs {
        soup.quad(*q, centroid(q) - center);
    }
    b.add_mesh(name, &[soup.primitive(material)])
}

/// Adds the published camera (looking along +Z) and returns its node.
pub(crate) fn add_camera(b: &mut GltfBuilder, name: &str) -> usize {
    let cam = b.add_perspective_camera(name, CORNELL_YFOV, Some(1.0), 0.01, Some(100.0));
    b.add_node(&NodeDesc {
        name: Some(name.into()),
        translation: Some(CAMERA_POSITION),
        rotation: Some(yaw(180.0)),
        camera: Some(cam),
        ..NodeDesc::default()
    })
}

/// The Cornell box document.
pub fn cornell_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut roots = add_room(&mut b, m);
    let short = add_block(&mut b, "short_block", &SHORT_BLOCK, m.white);
    roots.push(node(&mut b, "short_block", short));
    roots.push(add_camera(&mut b, "camera"));
    b.add_scene("cornell_box", &roots, None);
    b
}

/// The Cornell box scaled by `scale` about the origin (`scale = 1` gives the same scene as
/// [`cornell_builder`]): the meshes hang under one node of uniform scale `scale`; the camera's
/// position, near and far planes are multiplied by `scale` (its view is the same). Used by the
/// stiff suite's scale-invariance cases.
pub fn cornell_scaled_builder(scale: f32) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut children = add_room(&mut b, m);
    let short = add_block(&mut b, "short_block", &SHORT_BLOCK, m.white);
    children.push(node(&mut b, "short_block", short));
    let world = b.add_node(&NodeDesc {
        name: Some("scaled".into()),
        scale: Some([scale; 3]),
        children,
        ..NodeDesc::default()
    });
    let cam = b.add_perspective_camera(
        "camera",
        CORNELL_YFOV,
        Some(1.0),
        0.01 * scale,
        Some(100.0 * scale),
    );
    let camera = b.add_node(&NodeDesc {
        name: Some("camera".into()),
        translation: Some(CAMERA_POSITION.map(|c| c * scale)),
        rotation: Some(yaw(180.0)),
        camera: Some(cam),
        ..NodeDesc::default()
    });
    b.add_scene("cornell_box", &[world, camera], None);
    b
}

/// Writes `dir/cornell/cornell.gltf` (+ `.bin`).
pub fn write_cornell(dir: &Path) -> Result<PathBuf> {
    write_named(&cornell_builder(), dir, "cornell")
}

/// Duration of the Cornell box fly-through in seconds.
pub const CORNELL_FLY_DURATION: f32 = 2.0;

/// The Cornell box with a camera path and nothing else moving (the prepass of `radcache cache
/// build`): from the published viewpoint the camera moves in to the left, turning right, then
/// to the right, turning left (LINEAR translation and rotation; keys at 0, 1, 2 s).
pub fn cornell_fly_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut roots = add_room(&mut b, m);
    let short = add_block(&mut b, "short_block", &SHORT_BLOCK, m.white);
    roots.push(node(&mut b, "short_block", short));
    let camera = add_camera(&mut b, "camera");
    roots.push(camera);
    let keys = [0.0, 1.0, CORNELL_FLY_DURATION];
    let translation = [CAMERA_POSITION, [0.36, 0.30, -0.50], [0.20, 0.26, -0.35]];
    let rotation = [yaw(180.0), yaw(172.0), yaw(190.0)];
    let channel = |property, values: Vec<f32>| ChannelDesc {
        node: camera,
        property,
        interpolation: Interpolation::Linear,
        times: keys.to_vec(),
        values,
    };
    b.add_animation(
        "fly_through",
        &[
            channel(Property::Translation, translation.concat()),
            channel(Property::Rotation, rotation.concat()),
        ],
    );
    b.add_scene("cornell_fly", &roots, None);
    b
}

/// Writes `dir/cornell_fly/cornell_fly.gltf` (+ `.bin`).
pub fn write_cornell_fly(dir: &Path) -> Result<PathBuf> {
    write_named(&cornell_fly_builder(), dir, "cornell_fly")
}

/// The Cornell room (its tall block, no short block) with two white metal spheres in front:
/// GGX roughness 0.3 on the left and 0.6 on the right, radius 0.1 m, resting on the floor. The
/// test scene of the metallic-roughness BRDF against an independent renderer (`cargo xtask bench
/// peer --scenes metal_spheres`: a white glTF metal is Mitsuba's GGX `roughconductor` with
/// `material="none"`, up to the shadowing term).
pub fn metal_spheres_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut roots = add_room(&mut b, m);
    for (name, roughness, centre) in [
        ("sphere_rough_0.3", 0.3f32, Vec3::new(0.40, 0.1, 0.16)),
        ("sphere_rough_0.6", 0.6, Vec3::new(0.17, 0.1, 0.14)),
    ] {
        let material = b.add_material(&MaterialDesc::metal_rough(
            name,
            [1.0, 1.0, 1.0],
            1.0,
            roughness,
        ));
        let mesh = b.add_mesh(name, &[uv_sphere(centre, 0.1, 32, 64, material)]);
        roots.push(node(&mut b, name, mesh));
    }
    roots.push(add_camera(&mut b, "camera"));
    b.add_scene("metal_spheres", &roots, None);
    b
}

/// Writes `dir/metal_spheres/metal_spheres.gltf` (+ `.bin`).
pub fn write_metal_spheres(dir: &Path) -> Result<PathBuf> {
    write_named(&metal_spheres_builder(), dir, "metal_spheres")
}

/// A UV sphere of `rings` × `segments` quads (triangle fans at the poles) with smooth normals,
/// counter-clockwise seen from outside.
/// The Cornell room (its tall block, no short block) with glossy objects for radiance caching
/// (docs/radiance-caching.md): a rough gold-coloured metal sphere (roughness 0.7) on the right,
/// a rough blue plastic sphere (a dielectric, 0.8) on the left, a smaller white metal sphere
/// sharper than the records' threshold (0.4: its specular light stays path traced per pixel)
/// between them, and a glossy grey metal plate (0.65) over the floor, 1 mm above it.
pub fn glossy_room_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut roots = add_room(&mut b, m);
    let plate = b.add_material(&MaterialDesc::metal_rough(
        "floor_metal_0.65",
        [0.8, 0.8, 0.8],
        1.0,
        0.65,
    ));
    let mut soup = QuadSoup::default();
    let y = 0.001;
    soup.quad(
        [
            Vec3::new(0.005, y, 0.005),
            Vec3::new(0.55, y, 0.005),
            Vec3::new(0.55, y, 0.554),
            Vec3::new(0.005, y, 0.554),
        ],
        Vec3::Y,
    );
    let mesh = b.add_mesh("floor_plate", &[soup.primitive(plate)]);
    roots.push(node(&mut b, "floor_plate", mesh));
    for (name, base, metallic, roughness, centre, r) in [
        (
            "gold_0.7",
            [0.95, 0.7, 0.35],
            1.0f32,
            0.7f32,
            Vec3::new(0.17, 0.101, 0.14),
            0.1f32,
        ),
        (
            "plastic_0.8",
            [0.15, 0.3, 0.7],
            0.0,
            0.8,
            Vec3::new(0.40, 0.101, 0.16),
            0.1,
        ),
        (
            "metal_0.4",
            [1.0, 1.0, 1.0],
            1.0,
            0.4,
            Vec3::new(0.29, 0.061, 0.30),
            0.06,
        ),
    ] {
        let material = b.add_material(&MaterialDesc::metal_rough(name, base, metallic, roughness));
        let mesh = b.add_mesh(name, &[uv_sphere(centre, r, 32, 64, material)]);
        roots.push(node(&mut b, name, mesh));
    }
    roots.push(add_camera(&mut b, "camera"));
    b.add_scene("glossy_room", &roots, None);
    b
}

/// Writes `dir/glossy_room/glossy_room.gltf` (+ `.bin`).
pub fn write_glossy_room(dir: &Path) -> Result<PathBuf> {
    write_named(&glossy_room_builder(), dir, "glossy_room")
}

fn uv_sphere(centre: Vec3, r: f32, rings: u32, segments: u32, material: usize) -> PrimitiveDesc {
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            positions.push((centre + r * n).to_array());
            normals.push(n.to_array());
        }
    }
    let row = segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (
                i * row + j,
                i * row + j + 1,
                (i + 1) * row + j,
                (i + 1) * row + j + 1,
            );
            if i != 0 {
                indices.extend([a, b, c]);
            }
            if i != rings - 1 {
                indices.extend([b, d, c]);
            }
        }
    }
    PrimitiveDesc::triangles(positions, Some(normals), indices, Some(material))
}
