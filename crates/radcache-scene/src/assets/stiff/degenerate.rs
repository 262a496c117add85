//! Degenerate input: a lit room full of bad triangles, a camera inside a closed object, and
//! non-finite vertices (which must fail to load with a clear error).

use glam::Vec3;

use super::{camera, mesh_node, rect, StiffCheck, StiffScene};
use crate::assets::QuadSoup;
use crate::writer::{GltfBuilder, MaterialDesc, PrimitiveDesc};

/// Triangles the loader must drop in `degenerate` (each a `DegenerateTriangles` warning count):
/// 3 collinear, 2 with a repeated index, 2 with three equal positions (the `junk` primitive) and
/// the 2 of the zero-area emitter.
pub const DEGENERATE_DROPPED: usize = 9;
/// Primitives of `degenerate` given flat normals because theirs have zero length.
pub const DEGENERATE_GENERATED_NORMALS: usize = 1;

pub(super) fn scenes() -> Vec<StiffScene> {
    vec![
        StiffScene::new(
            "degenerate",
            "zero-area, repeated-index and needle triangles, duplicated vertices and faces, \
             inward and zero normals, a zero-area emitter",
            StiffCheck::Reference(None),
            degenerate(),
        ),
        StiffScene::new(
            "inside_object",
            "the camera inside a closed cube in a lit room",
            StiffCheck::Dark,
            inside_object(),
        ),
        StiffScene::new(
            "nan_vertex",
            "a NaN vertex coordinate",
            StiffCheck::LoadError("POSITION"),
            non_finite(f32::NAN),
        ),
        StiffScene::new(
            "inf_vertex",
            "an infinite vertex coordinate",
            StiffCheck::LoadError("POSITION"),
            non_finite(f32::INFINITY),
        ),
    ]
}

/// A lit 4 m room (albedo 0.7, ceiling light of radiance 10) holding a 1 m box whose primitive
/// also carries degenerate triangles, needles (aspect 1e-4, kept), duplicated vertices and a
/// duplicated face; a box with inward-facing vertex normals; a quad with zero-length normals;
/// and an emitter whose two triangles have zero area.
fn degenerate() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.7; 3]));
    let grey = b.add_material(&MaterialDesc::diffuse("junk", [0.6, 0.6, 0.5]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [10.0; 3]));
    let flat = b.add_material(&MaterialDesc::emitter("flat_lamp", [0.0; 3], [1e3; 3]));
    let mut room = QuadSoup::default();
    room.cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 2.0), true);
    room.quad(rect(1, 2.99, [-0.3, 0.3], [-0.3, 0.3]), Vec3::NEG_Y);
    let mut room = room.primitive(wall);
    // The light: the last two triangles of the room primitive, moved to their own primitive.
    let light_idx: Vec<u32> = room.indices.as_mut().unwrap().split_off(36);
    let light = PrimitiveDesc::triangles(
        room.positions.clone(),
        room.normals.clone(),
        light_idx,
        Some(lamp),
    );

    let mut junk = QuadSoup::default();
    junk.cuboid(Vec3::new(-0.6, 0.5, -0.5), Vec3::splat(0.5), false);
    // Duplicated face: the box's top again (same vertices, new indices).
    junk.quad(rect(1, 1.0, [-1.0, 0.0], [-1.1, -0.1]), Vec3::Y);
    let mut junk = junk.primitive(grey);
    let n = junk.positions.len() as u32;
    let up = [0.0, 1.0, 0.0];
    let extra: [[f32; 3]; 9] = [
        // collinear
        [0.5, 0.2, 0.0],
        [0.7, 0.2, 0.0],
        [0.9, 0.2, 0.0],
        // a point repeated three times
        [0.5, 0.4, 0.3],
        [0.5, 0.4, 0.3],
        [0.5, 0.4, 0.3],
        // needle: 1 m long, 0.1 mm wide, standing in the room
        [0.8, 0.0, 0.5],
        [0.8, 1.0, 0.5],
        [0.8001, 0.0, 0.5],
    ];
    junk.positions.extend(extra);
    junk.normals.as_mut().unwrap().extend([up; 9]);
    junk.indices.as_mut().unwrap().extend([
        n,
        n + 1,
        n + 2,
        n + 2,
        n + 1,
        n,
        n + 1,
        n + 2,
        n,
        n + 3,
        n + 4,
        n + 5,
        n + 5,
        n + 3,
        n + 4,
        n,
        n,
        n + 1,
        n + 3,
        n + 3,
        n + 5,
        n + 6,
        n + 7,
        n + 8,
        n + 8,
        n + 7,
        n + 6,
    ]);

    let mut inward = QuadSoup::default();
    inward.cuboid(Vec3::new(0.9, 0.3, -0.6), Vec3::splat(0.3), false);
    let mut inward = inward.primitive(grey);
    for v in inward.normals.as_mut().unwrap() {
        *v = v.map(|c| -c);
    }
    let mut zero_n = QuadSoup::default();
    zero_n.quad(rect(0, 1.99, [0.5, 1.5], [-1.0, 0.0]), Vec3::NEG_X);
    let mut zero_n = zero_n.primitive(grey);
    zero_n.normals = Some(vec![[0.0; 3]; 4]);
    let flat_lamp = PrimitiveDesc::triangles(
        vec![[0.0, 1.0, 1.0], [0.5, 1.0, 1.0], [1.0, 1.0, 1.0]],
        Some(vec![[0.0, -1.0, 0.0]; 3]),
        vec![0, 1, 2, 2, 1, 0],
        Some(flat),
    );

    let room = b.add_mesh("room", &[room, light]);
    let junk = b.add_mesh("junk", &[junk, inward, zero_n, flat_lamp]);
    let nodes = vec![
        mesh_node(&mut b, "room", room),
        mesh_node(&mut b, "junk", junk),
        camera(&mut b, Vec3::new(0.0, 1.4, 1.9), 0.0, -20.0, 75.0, 0.01),
    ];
    b.add_scene("degenerate", &nodes, None);
    b
}

/// The lit room of `degenerate` with a closed 0.6 m cube (outward normals) around the camera.
fn inside_object() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let wall = b.add_material(&MaterialDesc::diffuse("wall", [0.7; 3]));
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.0; 3], [10.0; 3]));
    let mut room = QuadSoup::default();
    room.cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 1.5, 2.0), true);
    room.cuboid(Vec3::new(0.0, 1.2, 0.0), Vec3::splat(0.3), false);
    let mut light = QuadSoup::default();
    light.quad(rect(1, 2.99, [-0.3, 0.3], [-0.3, 0.3]), Vec3::NEG_Y);
    let room = b.add_mesh("room", &[room.primitive(wall)]);
    let light = b.add_mesh("lamp", &[light.primitive(lamp)]);
    let nodes = vec![
        mesh_node(&mut b, "room", room),
        mesh_node(&mut b, "lamp", light),
        camera(&mut b, Vec3::new(0.0, 1.2, 0.1), 0.0, 0.0, 90.0, 0.01),
    ];
    b.add_scene("inside_object", &nodes, None);
    b
}

/// One lit quad with a non-finite coordinate in its second vertex.
fn non_finite(bad: f32) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let lamp = b.add_material(&MaterialDesc::emitter("lamp", [0.5; 3], [1.0; 3]));
    let mut q = QuadSoup::default();
    q.quad(rect(2, -1.0, [-1.0, 1.0], [-1.0, 1.0]), Vec3::Z);
    let mut p = q.primitive(lamp);
    p.positions[1][2] = bad;
    let mesh = b.add_mesh("quad", &[p]);
    let nodes = vec![
        mesh_node(&mut b, "quad", mesh),
        camera(&mut b, Vec3::ZERO, 0.0, 0.0, 60.0, 0.01),
    ];
    b.add_scene("non_finite", &nodes, None);
    b
}
