//! radcache-render: the frame's passes on the GPU, over `radcache-vk`.
//!
//! The crate is laid out by role in layers; a module uses only the layers below its own (the
//! test `layering` in `tests/layering.rs` fails on any `crate::` path that points up):
//! - [`frame`]: the frames, as named phases: the irradiance cache's ([`IcRenderer`],
//!   [`render_ic`]) and the path tracer's ([`render_path`]), with their settings, statistics and
//!   clocks. Its module doc is the one description of a frame's flow.
//! - [`passes`]: one file per pass, named as its shader.
//! - [`state`]: GPU state that outlives a pass: the cache's records, requests and counters
//!   ([`IcState`]), with the bookkeeping pass that keeps the counters ([`state::ic_counters`]).
//! - [`scene`]: the scene on the GPU ([`GpuScene`]): packed geometry and materials, lights,
//!   the environment map ([`EnvMap`]), the BLASes and TLAS at a time t, and the shader defines
//!   of its plan (only the light sources the scene has are compiled in).
//! - [`bindings`]: the binding tables shared with GLSL (the one owner of binding numbers).
//! - [`technique`] and the errors: the technique switches that the frame chooses and the passes
//!   compile in ([`SkyLight`], [`EmitterLight`], ...), and [`Error`].
//!
//! The crate root only declares the modules and re-exports the public API.

pub mod bindings;
mod error;
pub mod frame;
pub mod passes;
pub mod scene;
pub mod state;
pub mod technique;

pub use error::{Error, Result};
pub use frame::clock::{Span, Track};
pub use frame::ic::{render_ic, IcRenderer};
pub use frame::path::{render_path, Budget, FrameOutput, PathSettings, Progress};
pub use frame::settings::{
    sub_frame_jitter, AntiAliasing, ConfigChange, IcDebug, IcSettings, IcStats, TechniqueHelp,
};
pub use passes::aov::{render_aovs, AovPass, Aovs};
pub use passes::composite::{CentreSamples, CompositeInputs, CompositePass, CompositeVariant};
pub use passes::direct::{
    CompositeSubFrame, CompositeTargets, DirectCompositing, DirectInputs, DirectOutputs,
    DirectPass, DirectShadows, DirectVariant,
};
pub use passes::emission::EmissionPass;
pub use passes::gbuffer::{GBuffer, GBufferPass, DEPTH_FORMAT, GBUFFER_BINDINGS, GBUFFER_FORMAT};
pub use passes::holes::{HolePass, HoleSelection};
pub use passes::neighbours::NeighbourPass;
pub use passes::path_trace::PathTracer;
pub use passes::record::{
    creation_seed, record_seed, DISPATCH_OFFSET, RECORD_FLAGS_MASK, RECORD_FLAG_CLAMPED_DOWN,
    RECORD_FLAG_CLAMPED_UP, RECORD_FLAG_FOLDED, RECORD_FLAG_GLOSSY, RECORD_FLAG_INVALID_IRRADIANCE,
    RECORD_FLAG_NO_SURFACE, RECORD_INSTANCE_SHIFT,
};
pub use passes::record::{
    RecordInputs, RecordJob, RecordOutputs, RecordPass, RecordVariant, MAX_STRATA, R_EPS_REL,
};
pub use passes::splat::{SplatDraw, SplatInputs, SplatOutput, SplatPass, SplatScope, SplatWeights};
pub use passes::splat_glossy::GlossySplatPass;
pub use passes::temporal::{
    expires_at, Lifespans, TemporalInputs, TemporalJob, TemporalPass, TemporalVariant,
};
pub use scene::env_map::{gpu_alias, texel_solid_angle, EnvMap};
pub use scene::upload::vulkan_clip_from_view;
pub use scene::{GpuScene, UploadStats, REFITS_PER_REBUILD};
pub use state::{IcState, RadianceBlock, RADIANCE_BYTES_PER_RECORD};
pub use technique::{
    EmitterLight, EmitterShadows, GlossyLight, GlossySpacing, PathGridMode, SkyLight,
    SpecularPaths, SplatMode,
};
