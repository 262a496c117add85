//! The stiff and extreme scenes (issue 8): small glTF documents built in memory, each with what it
//! is checked against. `cargo xtask stiff` and the `stiff` tests generate them on the fly into a
//! temporary folder ([`write_stiff`]); they are not bundled in `assets/`.
//!
//! | group | scenes | checked against |
//! |---|---|---|
//! | furnaces (`extreme.rs`) | `furnace_0.5`, `furnace_0.9`, `furnace_0.99`: closed box, albedo ρ, emission Le = 1 | Le / (1 − ρ) everywhere |
//! | | `furnace_1.0`: albedo exactly 1 | nothing converges (the answer is infinite): finite output, the run ends |
//! | light through a gap (`rooms.rs`) | `slit`: a room lit only through a 2 cm slit by a 10 cm light of radiance 1e4 | path tracer |
//! | thin geometry (`rooms.rs`) | `panel`: a panel 1 mm above the floor, in the light | path tracer |
//! | | `two_rooms`: a zero-thickness wall, a point light 5 cm from it on the lit side, the camera on the dark side | black (leak) |
//! | corners (`rooms.rs`) | `wedge`: two plates meeting at 15°, under a sky | path tracer |
//! | scale (`extreme.rs`) | `cornell_1e-3`, `cornell_1e4`: the Cornell box scaled | the path tracer on `cornell_1` |
//! | radiometry (`extreme.rs`) | `tiny_bright`: a 1 cm emitter of radiance 1e6 | path tracer |
//! | views (`extreme.rs`) | `grazing`: a 200 m floor seen from 30 cm, with a plank crossing the near plane | path tracer |
//! | glossy lobes (`extreme.rs`) | `glossy_bright`: a rough metal floor (0.65) under a 4 cm emitter of radiance 1e4; `glossy_grazing`: a rough metal floor (0.7) under a sky seen from 30 cm | path tracer |
//! | degenerate input (`degenerate.rs`) | `degenerate`: zero-area, repeated-index and needle triangles, duplicated vertices, inward normals, zero-length normals, a zero-area emitter | warnings with counts; path tracer |
//! | | `inside_object`: the camera inside a closed cube | black (leak) |
//! | | `nan_vertex`, `inf_vertex` | a load error naming the file and the accessor |

mod degenerate;
mod extreme;
mod rooms;

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use crate::error::Result;
use crate::writer::{BufferLayout, GltfBuilder, NodeDesc};

pub use degenerate::{DEGENERATE_DROPPED, DEGENERATE_GENERATED_NORMALS};

/// What a stiff scene's renders are compared with.
#[derive(Clone, Debug, PartialEq)]
pub enum StiffCheck {
    /// Every pixel's exact radiance (same in all channels).
    Analytic(f32),
    /// Every pixel must be black: the whole image is the dark region of the leak measure.
    Dark,
    /// A path-traced reference of this scene (or of the named scene, for the scale cases).
    Reference(Option<&'static str>),
    /// No finite answer exists (albedo 1): only finiteness and termination are checked.
    Unbounded,
    /// Loading must fail with an error that names the file and this element.
    LoadError(&'static str),
}

/// One scene of the suite.
#[derive(Clone, Debug)]
pub struct StiffScene {
    /// File stem and table label.
    pub name: &'static str,
    /// One line on what it exercises.
    pub about: &'static str,
    /// What its renders are checked against.
    pub check: StiffCheck,
    /// The document.
    pub builder: GltfBuilder,
}

impl StiffScene {
    fn new(
        name: &'static str,
        about: &'static str,
        check: StiffCheck,
        builder: GltfBuilder,
    ) -> Self {
        StiffScene {
            name,
            about,
            check,
            builder,
        }
    }
}

/// Every scene of the suite, in table order.
pub fn stiff_scenes() -> Vec<StiffScene> {
    let mut v = extreme::furnaces();
    v.extend(rooms::scenes());
    v.extend(extreme::scenes());
    v.extend(degenerate::scenes());
    v
}

/// The scene called `name` (panics if there is none: the names are fixed).
pub fn stiff_scene(name: &str) -> StiffScene {
    stiff_scenes()
        .into_iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("no stiff scene {name:?}"))
}

/// Writes `scene` as `dir/<name>.gltf` (buffer embedded) and returns the path.
pub fn write_stiff_scene(scene: &StiffScene, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|source| crate::Error::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let path = dir.join(format!("{}.gltf", scene.name));
    scene.builder.write(&path, BufferLayout::Embedded)?;
    Ok(path)
}

/// Writes every scene under `dir`; returns them with their paths.
pub fn write_stiff(dir: &Path) -> Result<Vec<(StiffScene, PathBuf)>> {
    stiff_scenes()
        .into_iter()
        .map(|s| {
            let p = write_stiff_scene(&s, dir)?;
            Ok((s, p))
        })
        .collect()
}

/// Adds a perspective camera (aspect left to the image) at `position`, turned by `yaw_deg` about
/// +Y (0: looking down −Z) and then `pitch_deg` about its x axis (positive: up); returns its node.
pub(crate) fn camera(
    b: &mut GltfBuilder,
    position: Vec3,
    yaw_deg: f32,
    pitch_deg: f32,
    yfov_deg: f32,
    znear: f32,
) -> usize {
    let cam = b.add_perspective_camera("camera", yfov_deg.to_radians(), None, znear, None);
    let q =
        Quat::from_rotation_y(yaw_deg.to_radians()) * Quat::from_rotation_x(pitch_deg.to_radians());
    b.add_node(&NodeDesc {
        name: Some("camera".into()),
        translation: Some(position.to_array()),
        rotation: Some(q.normalize().to_array()),
        camera: Some(cam),
        ..NodeDesc::default()
    })
}

/// Adds a node holding `mesh`; returns its index.
pub(crate) fn mesh_node(b: &mut GltfBuilder, name: &str, mesh: usize) -> usize {
    b.add_node(&NodeDesc {
        name: Some(name.into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    })
}

/// The four corners of an axis-aligned rectangle: `axis` is its normal axis (0 x, 1 y, 2 z) at
/// coordinate `at`, spanning `[a0, a1]` on the next axis and `[b0, b1]` on the one after.
pub(crate) fn rect(axis: usize, at: f32, a: [f32; 2], b: [f32; 2]) -> [Vec3; 4] {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let corner = |x: f32, y: f32| {
        let mut p = Vec3::ZERO;
        p[axis] = at;
        p[u] = x;
        p[v] = y;
        p
    };
    [
        corner(a[0], b[0]),
        corner(a[1], b[0]),
        corner(a[1], b[1]),
        corner(a[0], b[1]),
    ]
}
