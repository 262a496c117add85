//! radcache-render: the frame's passes on the GPU, over `radcache-vk`.
//!
//! The crate is laid out by role; dependencies point downward (each folder uses only the ones
//! listed after it):
//! - [`frame`]: the frames, as named phases: the irradiance cache's ([`IcRenderer`],
//!   [`render_ic`]) and the path tracer's ([`render_path`]), with their settings, statistics and
//!   clocks. Its module doc is the one description of a frame's flow.
//! - [`state`]: GPU state that outlives a pass: the cache's records, requests and counters
//!   ([`IcState`]).
//! - [`passes`]: one file per pass, named as its shader.
//! - [`scene`]: the scene on the GPU ([`GpuScene`]): packed geometry and materials, lights,
//!   the environment map ([`EnvMap`]), the BLASes and TLAS at a time t, and the shader defines
//!   of its plan (only the light sources the scene has are compiled in).
//! - [`bindings`]: the binding tables shared with GLSL (the one owner of binding numbers).

pub mod bindings;
mod error;
pub mod frame;
pub mod passes;
pub mod scene;
pub mod state;

pub use error::{Error, Result};
pub use frame::clock::{Span, Track};
pub use frame::ic::{render_ic, IcRenderer};
pub use frame::path::{render_path, Budget, FrameOutput, PathSettings, Progress};
pub use frame::settings::{
    sub_frame_jitter, AntiAliasing, EmitterLight, EmitterShadows, GlossyLight, GlossySpacing,
    IcDebug, IcSettings, IcStats, PathGridMode, SkyLight, SpecularPaths, SplatMode,
};
pub use passes::aov::{render_aovs, AovPass, Aovs};
pub use passes::composite::{CentreSamples, CompositePass};
pub use passes::direct::{CompositeSubFrame, CompositeTargets, DirectPass};
pub use passes::emission::EmissionPass;
pub use passes::gbuffer::{GBuffer, GBufferPass, DEPTH_FORMAT, GBUFFER_BINDINGS, GBUFFER_FORMAT};
pub use passes::holes::{HolePass, HoleSelection};
pub use passes::neighbours::NeighbourPass;
pub use passes::path_trace::PathTracer;
pub use passes::record::{
    creation_seed, record_seed, DISPATCH_OFFSET, RECORD_BINDINGS_BASE, RECORD_FLAGS_MASK,
    RECORD_FLAG_CLAMPED_DOWN, RECORD_FLAG_CLAMPED_UP, RECORD_FLAG_FOLDED, RECORD_FLAG_GLOSSY,
    RECORD_FLAG_INVALID_IRRADIANCE, RECORD_FLAG_NO_SURFACE, RECORD_INSTANCE_SHIFT,
};
pub use passes::record::{RecordPass, MAX_STRATA, R_EPS_REL};
pub use passes::splat::{SplatOutput, SplatPass, SplatScope, SplatWeights};
pub use passes::splat_glossy::GlossySplatPass;
pub use passes::temporal::{expires_at, Lifespans, TemporalPass};
pub use scene::env_map::{gpu_alias, texel_solid_angle, EnvMap};
pub use scene::upload::vulkan_clip_from_view;
pub use scene::{GpuScene, UploadStats, REFITS_PER_REBUILD};
pub use state::{IcState, RadianceBlock, RADIANCE_BYTES_PER_RECORD};
