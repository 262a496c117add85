//! radcache-render: the frame's passes on the GPU, over `radcache-vk`.
//!
//! - [`GpuScene`]: the scene's buffers, BLASes and TLAS at a time t, and the shader defines of its
//!   plan (only the light sources the scene has are compiled in).
//! - [`PathTracer`] and [`render_path`]: the unbiased reference path tracer.
//! - [`AovPass`]: first-hit albedo, normal and depth.
//! - [`EnvMap`]: an equirectangular environment map with its importance-sampling table.
//! - [`bindings`]: the binding numbers shared with GLSL.

mod aov;
pub mod bindings;
mod env_map;
mod error;
mod gbuffer;
mod gpu_scene;
mod holes;
mod ic_state;
mod neighbours;
mod path_trace;
mod render;
mod scene_lights;
mod scene_pack;
mod splat;
mod upload;

pub use aov::{AovPass, Aovs};
pub use env_map::{gpu_alias, texel_solid_angle, EnvMap};
pub use error::{Error, Result};
pub use gbuffer::{GBuffer, DEPTH_FORMAT, GBUFFER_BINDINGS, GBUFFER_FORMAT};
pub use gpu_scene::{GpuScene, UploadStats, REFITS_PER_REBUILD};
pub use holes::HolePass;
pub use ic_state::IcState;
pub use neighbours::NeighbourPass;
pub use path_trace::PathTracer;
pub use render::{render_path, Budget, FrameOutput, PathSettings, Progress};
pub use splat::{SplatPass, SplatWeights};
pub use upload::vulkan_clip_from_view;
