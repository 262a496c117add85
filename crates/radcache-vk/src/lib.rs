//! radcache's Vulkan backend: the one crate that talks to Vulkan, and the only one with `unsafe`.
//!
//! A headless [`Context`] (validation layer routed into `log`, device choice with a clear refusal
//! report), RAII GPU objects with deferred destruction ([`Buffer`], [`Image`], [`Pipeline`],
//! [`Blas`], [`Tlas`]), command recording with named, timed pass scopes ([`Recorder::pass`]),
//! synchronization2 barriers ([`Access`], [`ImageUse`]) and run-time GLSL compilation
//! ([`ShaderCompiler`]). Every unsafe block carries a `SAFETY:` note; the public API is safe.

mod accel;
mod bind;
mod buffer;
mod commands;
mod context;
mod device;
mod error;
mod image;
mod instance;
mod pipeline;
mod profiler;
pub mod select;
mod shader;
mod sync;
mod tlas;
mod transfer;

pub use accel::{Blas, BlasBuildStats, BlasGeometry};
pub use ash::vk;
pub use bind::{ColorTarget, DepthTarget, Resource};
pub use buffer::{Buffer, BufferDesc, MemoryLocation};
pub use commands::{Recorder, Submission};
pub use context::{Context, ContextOptions, ShutdownReport};
pub use device::DeviceInfo;
pub use error::{Error, Result};
pub use image::{Image, ImageDesc, Sampler};
pub use pipeline::{BindingKind, BindingLayout, Blend, DepthState, GraphicsDesc, Pipeline};
pub use profiler::PassTiming;
pub use select::DeviceKind;
pub use shader::{ShaderCompiler, ShaderStage};
pub use sync::{Access, ImageUse};
pub use tlas::{Tlas, TlasInstance, TlasUpdate};
