//! radcache-scene: glTF 2.0 scene loading for radcache (CPU side; no GPU, no `unsafe`).
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
//! The [`writer`] module builds valid glTF files (used by tests and by [`assets`], which generates
//! the bundled Cornell box, furnace and animated scenes).

mod accessor;
pub mod alias;
pub mod animation;
pub mod assets;
mod base64;
pub mod camera;
pub mod emissive;
pub mod environment;
mod error;
pub mod light;
mod load;
pub mod material;
pub mod math;
pub mod mesh;
pub mod node;
pub mod plan;
mod resources;
mod scene;
mod summary;
pub mod texture;
pub mod writer;

pub use alias::AliasTable;
pub use animation::{Animation, Channel, Interpolation, Property, Sampler};
pub use camera::{Camera, CameraView, Perspective};
pub use emissive::{EmissiveTriangle, EmitterTable};
pub use environment::{direction_to_equirect, equirect_to_direction, EnvOverride, Environment};
pub use error::{Error, Result, Warning, WarningKind};
pub use light::{LightInstance, LightKind, LightSample, PunctualLight, WorldLight};
pub use load::LoadOptions;
pub use material::{emitted_radiance, Material};
pub use math::{luminance, Aabb, Trs};
pub use mesh::{Mesh, PrimitiveRange};
pub use node::{LocalTransform, Node};
pub use plan::{AnimationKind, AnimationPlan, EnvironmentKind, LightCounts, ScenePlan};
pub use scene::{Instance, Scene};
pub use texture::{Image, Texture, TextureRef, WrapMode};
