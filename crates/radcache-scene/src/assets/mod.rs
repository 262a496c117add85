//! Generators of the bundled assets (`cargo xtask assets` calls [`write_bundled_assets`]):
//!
//! - `cornell/cornell.gltf`: the Cornell box from the published Cornell data (see `cornell.rs`);
//! - `furnace/furnace.gltf`: a closed box, camera inside, every face of albedo ρ emitting Le
//!   (defaults ρ = 0.5, Le = 1 → the converged radiance everywhere is Le / (1 − ρ) = 2);
//! - `animated/animated.gltf`: a 5 s Cornell-like room with a camera fly-through, a box moving
//!   and turning (LINEAR), a cube bouncing (CUBICSPLINE translation, STEP scale) and a point light;
//! - `courtyard/courtyard.gltf`: a Sponza-class courtyard (about 125,000 triangles in 54 meshes,
//!   9 materials, foliage, a sun and a sky, a 5 s camera fly-through; see `courtyard.rs`).
//! - `cornell_fly/cornell_fly.gltf`: the Cornell box with a 2 s camera path and nothing else
//!   moving (the static fly-through of `radcache cache build`).
//! - `glossy_room/glossy_room.gltf`: the Cornell room with rough metal and plastic spheres and a
//!   glossy metal floor plate (radiance caching, docs/radiance-caching.md).
//! - `metal_spheres/metal_spheres.gltf`: the Cornell room with two white GGX metal spheres
//!   (roughness 0.3 and 0.6), the metallic-roughness BRDF's scene for `bench peer`.
//!
//! All are written with [`GltfBuilder`] (`.gltf` + `.bin`), so they are reproducible.

mod animated;
mod cornell;
mod courtyard;
pub mod stiff;

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use crate::error::{Error, Result};
use crate::writer::{BufferLayout, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};

pub use animated::{animated_builder, write_animated, ANIMATED_DURATION};
pub use cornell::{
    cornell_builder, cornell_fly_builder, cornell_scaled_builder, glossy_room_builder,
    metal_spheres_builder, write_cornell, write_cornell_fly, write_glossy_room,
    write_metal_spheres, CORNELL_FLY_DURATION, CORNELL_YFOV,
};
pub use courtyard::{courtyard_builder, write_courtyard, COURTYARD_DURATION};

/// Default furnace albedo.
pub const FURNACE_ALBEDO: f32 = 0.5;
/// Default furnace emitted radiance.
pub const FURNACE_EMISSION: f32 = 1.0;

/// Accumulates quads into one triangle primitive with flat, outward-chosen normals.
#[derive(Debug, Default)]
pub(crate) struct QuadSoup {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
}

impl QuadSoup {
    /// Adds a planar-ish quad (vertices in order around it), oriented so that its normal points
    /// along `toward`; its two triangles are counter-clockwise seen from that side.
    pub(crate) fn quad(&mut self, q: [Vec3; 4], toward: Vec3) {
        let mut n = (q[2] - q[0]).cross(q[3] - q[1]).normalize_or_zero();
        let q = if n.dot(toward) < 0.0 {
            n = -n;
            [q[0], q[3], q[2], q[1]]
        } else {
            q
        };
        let base = self.positions.len() as u32;
        for p in q {
            self.positions.push(p.to_array());
            self.normals.push(n.to_array());
        }
        self.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }

    /// Adds the six faces of an axis-aligned box, normals outward (`inward = false`) or inward.
    pub(crate) fn cuboid(&mut self, center: Vec3, half: Vec3, inward: bool) {
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut n = Vec3::ZERO;
                n[axis] = sign;
                let (u, v) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
                let c = center + n * half;
                let (hu, hv) = (u * half, v * half);
                let q = [c - hu - hv, c + hu - hv, c + hu + hv, c - hu + hv];
                self.quad(q, if inward { -n } else { n });
            }
        }
    }

    /// The primitive with `material`.
    pub(crate) fn primitive(self, material: usize) -> PrimitiveDesc {
        PrimitiveDesc::triangles(
            self.positions,
            Some(self.normals),
            self.indices,
            Some(material),
        )
    }
}

/// A unit quaternion (x, y, z, w) for a rotation of `degrees` about +Y.
/// Components below 1e-7 in magnitude are snapped to zero (keeps the JSON tidy).
/// A node rotation that turns its −Z (where a camera looks and a directional light shines)
/// toward `dir`, keeping +Y up.
pub fn look(dir: Vec3) -> [f32; 4] {
    let yaw = (-dir.x).atan2(-dir.z);
    let pitch = dir.y.atan2(dir.x.hypot(dir.z));
    (Quat::from_rotation_y(yaw) * Quat::from_rotation_x(pitch)).to_array()
}

pub(crate) fn yaw(degrees: f32) -> [f32; 4] {
    Quat::from_rotation_y(degrees.to_radians())
        .to_array()
        .map(|c| if c.abs() < 1e-7 { 0.0 } else { c })
}

fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Write {
        path: dir.to_path_buf(),
        source,
    })
}

/// Writes `builder` to `dir/<name>/<name>.gltf` (+ `.bin`) and returns the `.gltf` path.
pub(crate) fn write_named(builder: &GltfBuilder, dir: &Path, name: &str) -> Result<PathBuf> {
    let sub = dir.join(name);
    create_dir(&sub)?;
    let path = sub.join(format!("{name}.gltf"));
    builder.write(&path, BufferLayout::External)?;
    Ok(path)
}

/// The furnace: a 2 m closed box centred at the origin, normals inward, every face of albedo
/// `albedo` emitting `emission` W/(sr·m²); a 90° camera at the centre looks down −Z.
pub fn furnace_builder(albedo: f32, emission: f32) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::emitter(
        "furnace",
        [albedo; 3],
        [emission; 3],
    ));
    let mut soup = QuadSoup::default();
    soup.cuboid(Vec3::ZERO, Vec3::ONE, true);
    let mesh = b.add_mesh("furnace_box", &[soup.primitive(mat)]);
    let box_node = b.add_node(&NodeDesc {
        name: Some("furnace_box".into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let cam = b.add_perspective_camera("camera", 90f32.to_radians(), Some(1.0), 0.01, Some(10.0));
    let cam_node = b.add_node(&NodeDesc {
        name: Some("camera".into()),
        camera: Some(cam),
        ..NodeDesc::default()
    });
    b.add_scene("furnace", &[box_node, cam_node], None);
    b
}

/// Writes `dir/furnace/furnace.gltf` with the given albedo and emission.
pub fn write_furnace(dir: &Path, albedo: f32, emission: f32) -> Result<PathBuf> {
    write_named(&furnace_builder(albedo, emission), dir, "furnace")
}

/// Writes the bundled assets under `dir` and returns their `.gltf` paths
/// (cornell, furnace, animated, cornell_fly, courtyard, metal_spheres, glossy_room).
pub fn write_bundled_assets(dir: &Path) -> Result<Vec<PathBuf>> {
    Ok(vec![
        write_cornell(dir)?,
        write_furnace(dir, FURNACE_ALBEDO, FURNACE_EMISSION)?,
        write_animated(dir)?,
        write_cornell_fly(dir)?,
        write_courtyard(dir)?,
        write_metal_spheres(dir)?,
        write_glossy_room(dir)?,
    ])
}
