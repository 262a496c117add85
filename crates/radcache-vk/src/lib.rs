//! radcache's Vulkan backend: the one crate that talks to Vulkan, and the only one with `unsafe`.
//!
//! A headless [`Context`] (validation layer routed into `log`, device choice with a clear refusal
//! report), RAII GPU objects with deferred destruction ([`Buffer`], [`Image`], [`Pipeline`],
//! [`Blas`], [`Tlas`]), command recording with named, timed pass scopes ([`Recorder::pass`]),
//! synchronization2 barriers and image layouts derived from what each command reads and writes
//! (no caller places a barrier: `hazard.rs`) and run-time GLSL compilation
//! ([`ShaderCompiler`]). Every unsafe block carries a `SAFETY:` note; the public API is safe:
//! each recording function checks its preconditions against the recording's state (a pipeline of
//! the right kind bound, every declared binding pushed, a rendering open for draws, the usage and
//! range of indirect arguments) and panics on a violation, which is a programming error; a host
//! write into a buffer that a submitted, unwaited recording uses is refused ([`Buffer::write`]).
//! What no host check can see (values the GPU writes into indirect arguments) is written down on
//! the function that reads them.

mod accel;
mod bind;
mod buffer;
mod commands;
mod context;
mod device;
mod draw;
mod error;
mod hazard;
mod image;
mod instance;
mod options;
mod pcache;
mod pcache_file;
mod pipeline;
mod profiler;
mod reflect;
pub mod select;
mod shader;
mod spirv_cache;
mod state;
mod sync;
mod tlas;
mod transfer;

pub use accel::{Blas, BlasBuildStats, BlasGeometry, BlasShape, BuildSizes};
pub use ash::vk;
pub use bind::Resource;
pub use buffer::{Buffer, BufferDesc, MemoryLocation};
pub use commands::{Recorder, Submission};
pub use context::{Context, ShutdownReport};
pub use device::DeviceInfo;
pub use draw::{ColorTarget, DepthTarget, RenderTargets};
pub use error::{Error, Result};
pub use image::{Image, ImageDesc, Sampler};
pub use options::{
    parse_size, pipeline_cache_dir_from_env, ContextOptions, DEVICE_MEMORY_ENV, PIPELINE_CACHE_ENV,
};
pub use pcache::PipelineStats;
pub use pipeline::{BindingKind, BindingLayout, Blend, DepthState, GraphicsDesc, Pipeline};
pub use profiler::PassTiming;
pub use select::DeviceKind;
pub use shader::{ShaderCompiler, ShaderStage, ShaderStats};
pub use tlas::{Tlas, TlasInstance, TlasUpdate};
