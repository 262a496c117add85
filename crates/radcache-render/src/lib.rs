//! radcache-render: the frame's passes on the GPU, over `radcache-vk`.
//!
//! - [`GpuScene`]: the scene's buffers, BLASes and TLAS at a time t, and the shader defines of its
//!   plan (only the light sources the scene has are compiled in).
//! - [`PathTracer`] and [`render_path`]: the unbiased reference path tracer.
//! - [`render_ic`]: a frame with the irradiance cache (G-buffer, direct light, hole filling with
//!   records and splats, composite), one file per pass.
//! - [`AovPass`]: first-hit albedo, normal and depth.
//! - [`EnvMap`]: an equirectangular environment map with its importance-sampling table.
//! - [`bindings`]: the binding numbers shared with GLSL.

mod aov;
pub mod bindings;
mod clock;
mod composite;
mod direct;
mod emission;
mod env_map;
mod error;
mod gbuffer;
mod gbuffer_pass;
mod gpu_scene;
mod holes;
mod ic;
mod ic_renderer;
mod ic_state;
mod neighbours;
mod path_trace;
mod records;
mod render;
mod scene_lights;
mod scene_pack;
mod splat;
mod temporal;
mod upload;

pub use aov::{render_aovs, AovPass, Aovs};
pub use clock::{Span, Track};
pub use composite::CompositePass;
pub use direct::DirectPass;
pub use emission::EmissionPass;
pub use env_map::{gpu_alias, texel_solid_angle, EnvMap};
pub use error::{Error, Result};
pub use gbuffer::{GBuffer, DEPTH_FORMAT, GBUFFER_BINDINGS, GBUFFER_FORMAT};
pub use gbuffer_pass::GBufferPass;
pub use gpu_scene::{GpuScene, UploadStats, REFITS_PER_REBUILD};
pub use holes::HolePass;
pub use ic::{render_ic, sub_frame_jitter, IcDebug, IcSettings, IcStats};
pub use ic_renderer::IcRenderer;
pub use ic_state::IcState;
pub use neighbours::NeighbourPass;
pub use path_trace::PathTracer;
pub use records::{
    creation_seed, record_seed, DISPATCH_OFFSET, RECORD_BINDINGS_BASE, RECORD_FLAGS_MASK,
    RECORD_FLAG_CLAMPED_DOWN, RECORD_FLAG_CLAMPED_UP, RECORD_FLAG_FOLDED,
    RECORD_FLAG_INVALID_IRRADIANCE, RECORD_FLAG_NO_SURFACE, RECORD_INSTANCE_SHIFT,
};
pub use records::{RecordPass, MAX_STRATA, R_EPS_REL};
pub use render::{render_path, Budget, FrameOutput, PathSettings, Progress};
pub use splat::{SplatPass, SplatScope, SplatWeights};
pub use temporal::{Lifespans, TemporalPass};
pub use upload::vulkan_clip_from_view;
