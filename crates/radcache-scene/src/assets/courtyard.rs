//! The courtyard: a Sponza-class scene of our own (issue 16's benchmark asset), about 125,000
//! triangles in 60 meshes with 9 materials, lit by a directional sun and a constant sky, with a
//! 5 s camera fly-through (120 frames at 24 fps).
//!
//! A 24 × 12 m paved courtyard between two buildings, each with two storeys of arcades: a row of
//! columns (smooth cylinders with a base and a capital) carrying semicircular arches, a gallery
//! behind them (back wall, ceiling, upper floor slab), curtains hanging in the upper arches; bushes
//! of a few hundred small leaf triangles each in planters along the courtyard (fine geometry of
//! the kind that makes the cache's harmonic-mean radius collapse); a fountain (basin, pillar,
//! bowl) in the middle; end walls closing the court. The sun lights the court and part of the
//! galleries; the galleries' back walls see mostly indirect light.
//!
//! Everything is generated from closed-form shapes and a fixed-seed xorshift generator, so the
//! files are byte-identical on every run.

use std::f32::consts::{PI, TAU};
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde_json::json;

use super::{look, write_named, QuadSoup};
use crate::animation::{Interpolation, Property};
use crate::error::Result;
use crate::light::LightKind;
use crate::writer::{ChannelDesc, GltfBuilder, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc};

/// Duration of the courtyard's camera path in seconds (120 frames at 24 fps).
pub const COURTYARD_DURATION: f32 = 5.0;

/// Half the court's length (x) and width (z), m.
const HALF_X: f32 = 12.0;
const HALF_Z: f32 = 6.0;
/// Gallery depth behind the arcade, m; storey height, m.
const DEPTH: f32 = 3.0;
const STOREY: f32 = 4.0;
/// Columns per arcade row, their radius, and the segments of every round shape.
const COLUMNS: usize = 12;
const COLUMN_R: f32 = 0.28;
const SEGMENTS: usize = 48;

/// A smooth-shaded triangle mesh under construction.
#[derive(Default)]
struct Mesh {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
}

impl Mesh {
    fn vertex(&mut self, p: Vec3, n: Vec3) -> u32 {
        self.positions.push(p.to_array());
        self.normals.push(n.normalize_or_zero().to_array());
        (self.positions.len() - 1) as u32
    }

    /// A grid of `(u_steps + 1) × (v_steps + 1)` vertices from `f(u, v) -> (point, normal)`,
    /// u, v in [0, 1], two counter-clockwise triangles per cell seen from the normal's side.
    fn grid(&mut self, u_steps: usize, v_steps: usize, f: impl Fn(f32, f32) -> (Vec3, Vec3)) {
        let base = self.positions.len() as u32;
        for j in 0..=v_steps {
            for i in 0..=u_steps {
                let (p, n) = f(i as f32 / u_steps as f32, j as f32 / v_steps as f32);
                self.vertex(p, n);
            }
        }
        let row = (u_steps + 1) as u32;
        for j in 0..v_steps as u32 {
            for i in 0..u_steps as u32 {
                let a = base + j * row + i;
                let (b, c, d) = (a + 1, a + row + 1, a + row);
                // Orient by the first cell's geometry against the surface normal.
                let pa = Vec3::from(self.positions[a as usize]);
                let pb = Vec3::from(self.positions[b as usize]);
                let pd = Vec3::from(self.positions[d as usize]);
                let na = Vec3::from(self.normals[a as usize]);
                if (pb - pa).cross(pd - pa).dot(na) >= 0.0 {
                    self.indices.extend([a, b, c, a, c, d]);
                } else {
                    self.indices.extend([a, c, b, a, d, c]);
                }
            }
        }
    }

    /// A vertical cylinder (side only) of radius `r` from `y0` to `y1` around (x, z).
    fn cylinder(&mut self, x: f32, z: f32, r: f32, y0: f32, y1: f32, rings: usize) {
        self.grid(SEGMENTS, rings, |u, v| {
            let a = u * TAU;
            let n = Vec3::new(a.cos(), 0.0, a.sin());
            (Vec3::new(x, y0 + (y1 - y0) * v, z) + n * r, n)
        });
    }

    /// A torus around the vertical axis through `c`: major radius `big`, minor `small`.
    fn torus(&mut self, c: Vec3, big: f32, small: f32, rings: usize) {
        self.grid(SEGMENTS, rings, |u, v| {
            let (a, b) = (u * TAU, v * TAU);
            let out = Vec3::new(a.cos(), 0.0, a.sin());
            let n = out * b.cos() + Vec3::Y * b.sin();
            (c + out * big + n * small, n)
        });
    }

    /// A flat disc (facing +Y or −Y) of radius `r` at height `y` around (x, z): a fan of
    /// `SEGMENTS` triangles.
    fn disc(&mut self, x: f32, z: f32, r: f32, y: f32, up: bool) {
        let n = if up { Vec3::Y } else { Vec3::NEG_Y };
        let centre = self.vertex(Vec3::new(x, y, z), n);
        let ring: Vec<u32> = (0..SEGMENTS)
            .map(|k| {
                let a = k as f32 / SEGMENTS as f32 * TAU;
                self.vertex(Vec3::new(x + a.cos() * r, y, z + a.sin() * r), n)
            })
            .collect();
        for k in 0..SEGMENTS {
            let (a, b) = (ring[k], ring[(k + 1) % SEGMENTS]);
            // Counter-clockwise seen from +Y is (centre, b, a) for increasing angle in x–z.
            self.indices
                .extend(if up { [centre, b, a] } else { [centre, a, b] });
        }
    }

    /// A semicircular arch band in the plane z = `z` spanning x0..x1 above height `spring`: the
    /// intrados (underside) and the front face, `thick` deep toward `side` (±1 along z).
    fn arch(&mut self, x0: f32, x1: f32, spring: f32, z: f32, thick: f32, side: f32) {
        let (cx, r) = ((x0 + x1) / 2.0, (x1 - x0) / 2.0);
        let top = spring + r + 0.4;
        self.grid(24, 2, |u, v| {
            let a = PI * (1.0 - u);
            let n = -Vec3::new(a.cos(), a.sin(), 0.0);
            let p = Vec3::new(cx + a.cos() * r, spring + a.sin() * r, z + side * thick * v);
            (p, n)
        });
        let front = Vec3::new(0.0, 0.0, -side);
        self.grid(24, 1, |u, v| {
            let a = PI * (1.0 - u);
            let inner = Vec3::new(cx + a.cos() * r, spring + a.sin() * r, z);
            let outer = Vec3::new(cx + a.cos() * r * 1.02 + (a.cos() * 0.6), top, z);
            (inner.lerp(outer, v), front)
        });
    }

    fn primitive(self, material: usize) -> PrimitiveDesc {
        PrimitiveDesc::triangles(
            self.positions,
            Some(self.normals),
            self.indices,
            Some(material),
        )
    }
}

/// xorshift32 with a fixed seed: the same leaves on every run.
struct Rng(u32);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }

    fn signed(&mut self) -> f32 {
        2.0 * self.next() - 1.0
    }
}

struct Materials {
    stone: usize,
    paving_a: usize,
    paving_b: usize,
    plaster: usize,
    curtains: [usize; 3],
    leaves: usize,
    water: usize,
}

fn add_materials(b: &mut GltfBuilder) -> Materials {
    let mut m = |name: &str, rgb: [f32; 3]| b.add_material(&MaterialDesc::diffuse(name, rgb));
    Materials {
        stone: m("stone", [0.58, 0.52, 0.43]),
        paving_a: m("paving_light", [0.62, 0.6, 0.55]),
        paving_b: m("paving_dark", [0.35, 0.33, 0.3]),
        plaster: m("plaster", [0.72, 0.66, 0.58]),
        curtains: [
            m("curtain_red", [0.6, 0.08, 0.06]),
            m("curtain_green", [0.1, 0.45, 0.15]),
            m("curtain_blue", [0.08, 0.15, 0.55]),
        ],
        leaves: m("leaves", [0.12, 0.32, 0.08]),
        water: m("water", [0.15, 0.3, 0.35]),
    }
}

/// One building's arcades on the side `side` (±1 along z): per storey a mesh of columns, one of
/// arches, the gallery (back wall, ceiling, slab) and, upstairs, curtains in every other arch.
fn add_building(b: &mut GltfBuilder, m: &Materials, side: f32, nodes: &mut Vec<usize>) {
    let z = side * HALF_Z;
    let pitch = 2.0 * HALF_X / COLUMNS as f32;
    for storey in 0..2 {
        let y0 = storey as f32 * STOREY;
        let spring = y0 + STOREY - 1.4;
        let mut columns = Mesh::default();
        let mut caps = QuadSoup::default();
        for c in 0..=COLUMNS {
            let x = -HALF_X + c as f32 * pitch;
            columns.cylinder(x, z, COLUMN_R, y0 + 0.3, spring - 0.25, 16);
            caps.cuboid(
                Vec3::new(x, y0 + 0.15, z),
                Vec3::new(0.38, 0.15, 0.38),
                false,
            );
            caps.cuboid(
                Vec3::new(x, spring - 0.12, z),
                Vec3::new(0.4, 0.13, 0.4),
                false,
            );
        }
        let mut arches = Mesh::default();
        for c in 0..COLUMNS {
            let x0 = -HALF_X + c as f32 * pitch + COLUMN_R;
            arches.arch(x0, x0 + pitch - 2.0 * COLUMN_R, spring, z, 0.6, side);
        }
        let mut gallery = QuadSoup::default();
        let back = z + side * DEPTH;
        let (ceiling, x0, x1) = (y0 + STOREY, -HALF_X, HALF_X);
        gallery.quad(
            [
                Vec3::new(x0, y0, back),
                Vec3::new(x1, y0, back),
                Vec3::new(x1, ceiling, back),
                Vec3::new(x0, ceiling, back),
            ],
            Vec3::new(0.0, 0.0, -side),
        );
        gallery.quad(
            [
                Vec3::new(x0, ceiling, z),
                Vec3::new(x1, ceiling, z),
                Vec3::new(x1, ceiling, back),
                Vec3::new(x0, ceiling, back),
            ],
            Vec3::NEG_Y,
        );
        gallery.cuboid(
            Vec3::new(0.0, ceiling + 0.15, z + side * DEPTH / 2.0),
            Vec3::new(HALF_X, 0.15, DEPTH / 2.0 + 0.3),
            false,
        );
        let tag = format!("{}_{storey}", if side > 0.0 { "north" } else { "south" });
        let meshes = [
            (format!("columns_{tag}"), columns.primitive(m.stone)),
            (format!("arches_{tag}"), arches.primitive(m.stone)),
            (format!("capitals_{tag}"), caps.primitive(m.stone)),
            (format!("gallery_{tag}"), gallery.primitive(m.plaster)),
        ];
        for (name, prim) in meshes {
            let mesh = b.add_mesh(&name, &[prim]);
            nodes.push(b.add_node(&NodeDesc {
                name: Some(name),
                mesh: Some(mesh),
                ..NodeDesc::default()
            }));
        }
        if storey == 1 {
            for c in (0..COLUMNS).step_by(2) {
                let x0 = -HALF_X + c as f32 * pitch + COLUMN_R + 0.1;
                let width = pitch - 2.0 * COLUMN_R - 0.2;
                let name = format!("curtain_{tag}_{c}");
                let cloth = curtain(x0, width, spring - 0.2, y0 + 0.6, z + side * 0.5, c);
                let mesh = b.add_mesh(&name, &[cloth.primitive(m.curtains[c / 2 % 3])]);
                nodes.push(b.add_node(&NodeDesc {
                    name: Some(name),
                    mesh: Some(mesh),
                    ..NodeDesc::default()
                }));
            }
        }
    }
}

/// A curtain hanging from `top` to `bottom` at depth `z`, pleated (a sine of the width) and
/// swinging out toward the bottom; `seed` varies the pleats.
fn curtain(x0: f32, width: f32, top: f32, bottom: f32, z: f32, seed: usize) -> Mesh {
    let mut mesh = Mesh::default();
    let folds = 5.0 + (seed % 3) as f32;
    mesh.grid(32, 24, |u, v| {
        let phase = u * folds * TAU;
        let depth = 0.06 * phase.sin() * (0.6 + 0.4 * v);
        let swing = 0.25 * v * v;
        let p = Vec3::new(x0 + u * width, top + (bottom - top) * v, z + depth + swing);
        let n = Vec3::new(-0.06 * folds * TAU / width * phase.cos(), 0.0, 1.0);
        (p, n)
    });
    mesh
}

/// A bush: `leaves` small triangles scattered in an ellipsoid around `c`, each facing out.
fn bush(c: Vec3, radius: f32, leaves: usize, rng: &mut Rng) -> Mesh {
    let mut mesh = Mesh::default();
    for _ in 0..leaves {
        let d = Vec3::new(rng.signed(), rng.signed(), rng.signed());
        if d.length_squared() > 1.0 {
            continue;
        }
        let p = c + d * Vec3::new(radius, radius * 0.8, radius);
        let n =
            (d + 0.3 * Vec3::new(rng.signed(), rng.signed(), rng.signed())).normalize_or(Vec3::Y);
        let t = n.any_orthonormal_vector();
        let s = n.cross(t);
        let size = 0.05 + 0.05 * rng.next();
        let a = mesh.vertex(p - t * size, n);
        let b = mesh.vertex(p + t * size, n);
        let c = mesh.vertex(p + s * size * 1.6, n);
        mesh.indices.extend([a, b, c]);
    }
    mesh
}

/// The court: paving in two tones (alternating strips), planters with bushes along both long
/// sides, the fountain, and the end walls.
fn add_court(b: &mut GltfBuilder, m: &Materials, nodes: &mut Vec<usize>) {
    let mut light = QuadSoup::default();
    let mut dark = QuadSoup::default();
    let (strips, tiles) = (24, 12);
    for i in 0..strips {
        for j in 0..tiles {
            let x = -HALF_X + i as f32 * 2.0 * HALF_X / strips as f32;
            let z = -HALF_Z - DEPTH + j as f32 * 2.0 * (HALF_Z + DEPTH) / tiles as f32;
            let (dx, dz) = (
                2.0 * HALF_X / strips as f32,
                2.0 * (HALF_Z + DEPTH) / tiles as f32,
            );
            let q = [
                Vec3::new(x, 0.0, z),
                Vec3::new(x + dx, 0.0, z),
                Vec3::new(x + dx, 0.0, z + dz),
                Vec3::new(x, 0.0, z + dz),
            ];
            if (i + j) % 2 == 0 {
                &mut light
            } else {
                &mut dark
            }
            .quad(q, Vec3::Y);
        }
    }
    let mut walls = QuadSoup::default();
    for sx in [-1.0f32, 1.0] {
        let x = sx * HALF_X;
        let (z0, z1, top) = (-HALF_Z - DEPTH, HALF_Z + DEPTH, 2.0 * STOREY + 0.3);
        walls.quad(
            [
                Vec3::new(x, 0.0, z0),
                Vec3::new(x, 0.0, z1),
                Vec3::new(x, top, z1),
                Vec3::new(x, top, z0),
            ],
            Vec3::new(-sx, 0.0, 0.0),
        );
    }
    let mut rng = Rng(0x2545_f491);
    let mut planters = QuadSoup::default();
    let mut parts: Vec<(String, PrimitiveDesc)> = Vec::new();
    for (k, side) in [-1.0f32, 1.0].into_iter().enumerate() {
        let z = side * (HALF_Z - 1.2);
        for i in 0..10 {
            let x = -HALF_X + 1.8 + i as f32 * 2.3;
            planters.cuboid(Vec3::new(x, 0.25, z), Vec3::new(0.55, 0.25, 0.55), false);
            let c = Vec3::new(x, 1.0, z);
            let leaves = bush(c, 0.65, 900, &mut rng);
            parts.push((format!("bush_{}_{i}", k), leaves.primitive(m.leaves)));
        }
    }
    let mut fountain = Mesh::default();
    fountain.torus(Vec3::new(0.0, 0.45, 0.0), 2.2, 0.3, 24);
    fountain.cylinder(0.0, 0.0, 0.35, 0.0, 1.8, 12);
    fountain.torus(Vec3::new(0.0, 1.8, 0.0), 0.9, 0.12, 16);
    fountain.disc(0.0, 0.0, 0.9, 1.75, true);
    let mut water = Mesh::default();
    water.disc(0.0, 0.0, 2.0, 0.55, true);
    parts.extend([
        ("paving_light".to_string(), light.primitive(m.paving_a)),
        ("paving_dark".to_string(), dark.primitive(m.paving_b)),
        ("end_walls".to_string(), walls.primitive(m.plaster)),
        ("planters".to_string(), planters.primitive(m.stone)),
        ("fountain".to_string(), fountain.primitive(m.stone)),
        ("fountain_water".to_string(), water.primitive(m.water)),
    ]);
    for (name, prim) in parts {
        let mesh = b.add_mesh(&name, &[prim]);
        nodes.push(b.add_node(&NodeDesc {
            name: Some(name),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }));
    }
}

/// The courtyard document.
pub fn courtyard_builder() -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let m = add_materials(&mut b);
    let mut nodes = Vec::new();
    add_building(&mut b, &m, -1.0, &mut nodes);
    add_building(&mut b, &m, 1.0, &mut nodes);
    add_court(&mut b, &m, &mut nodes);
    let sun = b.add_light(&LightDesc {
        name: Some("sun".into()),
        kind: LightKind::Directional,
        color: [1.0, 0.93, 0.82],
        intensity: 6.0,
        range: None,
    });
    // Sun from the south-east, 50° high: the court and the north gallery's front are lit.
    let sun_dir = Vec3::new(-0.45, -0.77, 0.45).normalize();
    nodes.push(b.add_node(&NodeDesc {
        name: Some("sun".into()),
        rotation: Some(look(sun_dir)),
        light: Some(sun),
        ..NodeDesc::default()
    }));
    let cam = b.add_perspective_camera("camera", 60f32.to_radians(), Some(1.0), 0.05, Some(100.0));
    let keys = [0.0, 2.5, COURTYARD_DURATION];
    let path = [
        Vec3::new(-10.5, 1.7, -3.0),
        Vec3::new(-1.0, 2.2, -3.5),
        Vec3::new(9.5, 5.5, 4.0),
    ];
    let targets = [
        Vec3::new(0.0, 2.0, 2.0),
        Vec3::new(6.0, 3.0, 6.0),
        Vec3::new(-2.0, 1.0, -4.0),
    ];
    let camera = b.add_node(&NodeDesc {
        name: Some("camera".into()),
        translation: Some(path[0].to_array()),
        rotation: Some(look(targets[0] - path[0])),
        camera: Some(cam),
        ..NodeDesc::default()
    });
    nodes.push(camera);
    let translation: Vec<f32> = path.iter().flat_map(|p| p.to_array()).collect();
    let rotation: Vec<f32> = (0..3).flat_map(|k| look(targets[k] - path[k])).collect();
    let channel = |property, values| ChannelDesc {
        node: camera,
        property,
        interpolation: Interpolation::Linear,
        times: keys.to_vec(),
        values,
    };
    b.add_animation(
        "fly_through",
        &[
            channel(Property::Translation, translation),
            channel(Property::Rotation, rotation),
        ],
    );
    let extras = json!({"environment": {"radiance": [0.35, 0.45, 0.65]}});
    b.add_scene("courtyard", &nodes, Some(extras));
    b
}

/// Writes `dir/courtyard/courtyard.gltf` (+ `.bin`).
pub fn write_courtyard(dir: &Path) -> Result<PathBuf> {
    write_named(&courtyard_builder(), dir, "courtyard")
}
