//! radcache-scene: glTF 2.0 scene loading for radcache (CPU side only: no GPU code).
//!
//! [`Scene::load`] reads a `.gltf`/`.glb` file into plain data: one merged triangle [`Mesh`] per
//! glTF mesh (per-triangle material ids), metallic-roughness [`Material`]s with sRGB textures,
//! KHR_lights_punctual lights, the selected perspective [`Camera`], the node hierarchy with TRS
//! [`Animation`]s, and the [`Environment`]. Time-dependent queries (`instance_transforms(t)`,
//! `camera_at(t)`, `lights_at(t)`, `emitters_at(t)`) evaluate the animation. [`ScenePlan`] tells
//! later passes what the scene needs; `Display` for [`Scene`] is the `radcache info` summary.
//!
//! Units: 1 glTF unit = 1 m; colours and radiometry are linear RGB; emission in W/(sr·m²); light
//! intensities in the KHR_lights_punctual units (cd, lx) used as radiometric values.
//!
//! **Delivery formats** (what gltfpack and gltf-transform write): `KHR_mesh_quantization`
//! (integer attributes, dequantized by the node's transform), `EXT_meshopt_compression` (each
//! compressed buffer view decoded on load, its fallback buffer never read; the KHR version's
//! vertex codec 1 is refused by name) and `EXT_mesh_gpu_instancing` (one [`Instance`] per
//! element, its transform under the node's).
//!
//! **For a GPU uploader.** Geometry: `scene.meshes[m]` holds `positions`, `normals`,
//! `texcoords` (one entry per vertex; `tangents` too where a material has a normal map, and
//! `texcoords1` where one samples TEXCOORD_1),
//! `indices` (3 per triangle, CCW front faces) and
//! `triangle_materials` (one per triangle), plus per-primitive [`PrimitiveRange`]s. Placement:
//! `scene.instances[i].mesh` with `scene.instance_transforms(t)[i]` (`world_from_object`; a negative
//! determinant makes the clockwise side the front, per the glTF spec); `Instance::dynamic` says
//! whether it moves. Materials: `scene.materials` (the last one is the default material when a
//! primitive had none), textures `scene.textures[k].image` → `scene.images[..]` as RGBA8 with an
//! `srgb` flag, or linear `f32` via [`Image::to_linear_f32`]. Emitters at time `t`:
//! `scene.emitters_at(t)` ([`EmitterTable`]: world-space triangles, power, alias table).
//! Punctual lights: `scene.lights_at(t)`. Camera: `scene.camera_at(t)` ([`CameraView`], with
//! `clip_from_world` and `ray_direction`). Environment: `scene.environment`. Plan: `scene.plan()`.
//!
//! **Bad input** never panics (a seeded mutation test checks this). It is one [`Error`] naming the
//! file and the element (buffer, accessor with its mesh/primitive/attribute user, node, camera,
//! animation channel/sampler, light, image): unreadable or invalid files, files that are not glTF
//! 2.x, missing or short buffers, missing or undecodable image files (named with their path),
//! accessors or buffer views out of range, vertex indices out of range, NaN/Inf vertex data or key
//! values, unsupported required extensions, orthographic cameras, broken hierarchies. Droppable
//! elements are dropped with a [`Warning`] that carries a count: degenerate triangles,
//! non-TRIANGLES primitives, primitives without POSITION. Features outside the renderer's model are
//! loaded with a documented fallback and a warning: skins and morph targets (rest pose), texCoord
//! sets above 1 (texture ignored), missing normals (flat), a negative `emissiveStrength` (not
//! emissive), KHR_materials_specular textures (factors used), material extensions other than
//! emissive strength, ior and specular (core model; named once each, with a count, in the
//! warnings and the summary), a normal map on a primitive without normals or without the
//! texture coordinates it samples (ignored), TEXCOORD_1 sampled where a primitive lacks it
//! (zero).
//!
//! The [`writer`] module builds valid glTF files (used by tests and by [`assets`], which generates
//! the bundled Cornell box, furnace and animated scenes).

mod accessor;
pub mod alias;
pub mod animation;
pub mod assets;
pub mod camera;
mod content_hash;
pub mod emissive;
pub mod environment;
mod error;
pub mod light;
mod load;
pub mod material;
pub mod math;
pub mod mesh;
mod meshopt;
pub mod node;
pub mod plan;
mod resources;
mod scene;
mod summary;
pub mod tangent;
pub mod texture;
pub mod texture_transform;
pub mod writer;

pub use alias::AliasTable;
pub use animation::{Animation, Channel, Interpolation, Property, Sampler};
pub use camera::{Camera, CameraView, Perspective};
pub use content_hash::Fnv1a;
pub use emissive::{EmissiveTriangle, EmitterTable};
pub use environment::{direction_to_equirect, equirect_to_direction, EnvOverride, Environment};
pub use error::{Error, Result, Warning, WarningKind};
pub use light::{LightInstance, LightKind, LightSample, PunctualLight, WorldLight};
pub use load::LoadOptions;
pub use material::{emitted_radiance, AlphaMode, Material, MaterialNotes, IOR_INFINITE};
pub use math::{luminance, Aabb, Trs};
pub use mesh::{Mesh, PrimitiveRange};
pub use node::{LocalTransform, Node};
pub use plan::{AnimationKind, AnimationPlan, EnvironmentKind, LightCounts, ScenePlan};
pub use scene::{Instance, Scene};
pub use texture::{Image, Texture, TextureRef, TextureTransform, WrapMode};
