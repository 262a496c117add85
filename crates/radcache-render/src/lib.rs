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
//! The crate root declares the modules and re-exports what a user of the renderer needs: the
//! frames, their settings and statistics, the scene, the technique switches and the errors.
//! The passes, their variants and inputs are reached by their module path
//! (`radcache_render::passes::direct::DirectPass`), as the tests that drive a pass alone do.

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
    AntiAliasing, ConfigChange, IcDebug, IcSettings, IcStats, TechniqueHelp,
};
pub use passes::aov::{render_aovs, Aovs};
pub use scene::env_map::EnvMap;
pub use scene::upload::vulkan_clip_from_view;
pub use scene::{GpuScene, UploadStats};
pub use state::IcState;
pub use technique::{
    EmitterLight, EmitterShadows, GlossyLight, GlossySpacing, PathGridMode, SkyLight,
    SpecularPaths, SplatMode,
};
