//! The documents the fuzzer mutates, besides the bundled assets: a small textured scene (image
//! decoding; valid per the Khronos validator) and a "kitchen sink" using every feature the loader
//! reads. The kitchen sink loads, but on purpose also contains what the loader tolerates and the
//! validator rejects: an animated matrix node (decomposed to TRS), a textured material on a
//! primitive without TEXCOORD_0, and sparse data sharing buffer views with vertex/index data.

use radcache_scene::animation::{Interpolation, Property};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{
    ChannelDesc, GltfBuilder, IndexFormat, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc,
};
use serde_json::{json, Value};

/// A small textured scene so that image decoding is exercised too.
pub fn textured() -> (Value, Vec<u8>) {
    let mut b = GltfBuilder::new();
    let pixels: Vec<u8> = (0..4 * 4 * 4).map(|i| (i * 37 % 256) as u8).collect();
    let tex = b.add_texture_rgba8(4, 4, &pixels, 10497).unwrap();
    let mut m = MaterialDesc::emitter("t", [1.0; 3], [2.0; 3]);
    m.base_color_texture = Some(tex);
    m.emissive_texture = Some(tex);
    let mat = b.add_material(&m);
    let mut prim = PrimitiveDesc::triangles(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        vec![0, 1, 2],
        Some(mat),
    );
    prim.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let mesh = b.add_mesh("m", &[prim]);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    b.to_json(Some("f.bin"))
}

/// Every feature the loader reads: u8 indices, non-indexed and LINES primitives, missing normals,
/// texcoords, base-colour and emissive textures, BLEND alpha, double-sided emission, point, spot
/// and directional lights, a matrix node with children, two cameras, STEP/LINEAR/CUBICSPLINE
/// channels, a constant environment, and (added to the JSON) a sparse POSITION accessor.
pub fn kitchen_sink() -> (Value, Vec<u8>) {
    let mut b = GltfBuilder::new();
    let pixels: Vec<u8> = (0..2 * 2 * 4).map(|i| (i * 53 % 256) as u8).collect();
    let tex = b.add_texture_rgba8(2, 2, &pixels, 33071).unwrap();
    let mut lamp = MaterialDesc::emitter("lamp", [0.5; 3], [4.0, 3.0, 2.0]);
    lamp.double_sided = true;
    lamp.emissive_texture = Some(tex);
    let lamp = b.add_material(&lamp);
    let mut glass = MaterialDesc::diffuse("glass", [0.9, 0.9, 1.0]);
    glass.alpha_mode = Some("BLEND".into());
    glass.base_color_texture = Some(tex);
    glass.metallic = 0.5;
    let glass = b.add_material(&glass);
    let quad = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let mut a = PrimitiveDesc::triangles(
        quad.clone(),
        Some(vec![[0.0, 0.0, 1.0]; 4]),
        vec![0, 1, 2, 0, 2, 3],
        Some(lamp),
    );
    a.index_format = IndexFormat::U8;
    a.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let mut c = PrimitiveDesc::triangles(
        vec![[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 0.0, 1.0]],
        None,
        vec![],
        Some(glass),
    );
    c.indices = None;
    let mut lines = PrimitiveDesc::triangles(quad, None, vec![0, 1, 1, 2], None);
    lines.mode = 1;
    let mesh = b.add_mesh("sink", &[a, c, lines]);
    let lights = [
        (LightKind::Point, Some(5.0)),
        (
            LightKind::Spot {
                inner_cone_angle: 0.2,
                outer_cone_angle: 0.6,
            },
            None,
        ),
        (LightKind::Directional, None),
    ]
    .map(|(kind, range)| {
        b.add_light(&LightDesc {
            name: None,
            kind,
            color: [1.0, 0.8, 0.6],
            intensity: 3.0,
            range,
        })
    });
    let cam = b.add_perspective_camera("cam", 0.9, Some(1.5), 0.05, None);
    let cam2 = b.add_perspective_camera("cam2", 0.5, None, 0.1, Some(30.0));
    let geo = b.add_node(&NodeDesc {
        name: Some("geo".into()),
        mesh: Some(mesh),
        scale: Some([1.0, -1.0, 1.0]),
        ..NodeDesc::default()
    });
    let spot = b.add_node(&NodeDesc {
        light: Some(lights[1]),
        translation: Some([0.0, 3.0, 0.0]),
        ..NodeDesc::default()
    });
    let parent = b.add_node(&NodeDesc {
        name: Some("parent".into()),
        matrix: Some([
            1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.5, 0.0, 0.0, 1.0,
        ]),
        children: vec![geo, spot],
        ..NodeDesc::default()
    });
    let point = b.add_node(&NodeDesc {
        light: Some(lights[0]),
        translation: Some([1.0, 2.0, 1.0]),
        ..NodeDesc::default()
    });
    let sun = b.add_node(&NodeDesc {
        light: Some(lights[2]),
        rotation: Some([-0.5, 0.0, 0.0, 0.8660254]),
        ..NodeDesc::default()
    });
    let cam_node = b.add_node(&NodeDesc {
        name: Some("cam".into()),
        camera: Some(cam),
        translation: Some([0.5, 0.5, 4.0]),
        ..NodeDesc::default()
    });
    let cam2_node = b.add_node(&NodeDesc {
        camera: Some(cam2),
        translation: Some([0.0, 5.0, 0.0]),
        ..NodeDesc::default()
    });
    let channels = [
        ChannelDesc {
            node: cam_node,
            property: Property::Rotation,
            interpolation: Interpolation::CubicSpline,
            times: vec![0.0, 1.0],
            values: vec![
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                0.0, 0.3826834, 0.0, 0.9238795, 0.0, 0.0, 0.0, 0.0,
            ],
        },
        ChannelDesc {
            node: parent,
            property: Property::Translation,
            interpolation: Interpolation::Step,
            times: vec![0.0, 0.5, 1.5],
            values: vec![0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0],
        },
        ChannelDesc {
            node: point,
            property: Property::Scale,
            interpolation: Interpolation::Linear,
            times: vec![0.25, 2.0],
            values: vec![1.0, 1.0, 1.0, 2.0, 2.0, 2.0],
        },
    ];
    b.add_animation("anim", &channels);
    let env = json!({"environment": {"radiance": [0.1, 0.2, 0.3]}});
    b.add_scene(
        "sink",
        &[parent, point, sun, cam_node, cam2_node],
        Some(env),
    );
    let (mut root, bin) = b.to_json(Some("f.bin"));
    // Sparse: vertex 0 of the first primitive's POSITION takes the first NORMAL value.
    let prim = root["meshes"][0]["primitives"][0].clone();
    let index_view =
        root["accessors"][prim["indices"].as_u64().unwrap() as usize]["bufferView"].clone();
    let normal_view = root["accessors"][prim["attributes"]["NORMAL"].as_u64().unwrap() as usize]
        ["bufferView"]
        .clone();
    let pos = prim["attributes"]["POSITION"].as_u64().unwrap() as usize;
    root["accessors"][pos]["sparse"] = json!({
        "count": 1,
        "indices": {"bufferView": index_view, "componentType": 5121},
        "values": {"bufferView": normal_view}
    });
    (root, bin)
}

/// A GLB file of `tests/data/` (gltfpack output) as its JSON and BIN chunks, buffer 0 given the
/// URI `f.bin` so that it can be written as `.gltf` too.
pub fn glb(name: &str) -> (Value, Vec<u8>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    let bytes = std::fs::read(&path).unwrap();
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_len = word(12);
    let mut root: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin = bytes[bin_at + 8..bin_at + 8 + word(bin_at)].to_vec();
    root["buffers"][0]["uri"] = json!("f.bin");
    (root, bin)
}
