//! Plain-data layouts shared between Rust and GLSL, with the generator of their GLSL side.
//!
//! Rust is the source of truth (structs in [`gpu`], constants and step enums in [`consts`]): each struct is `#[repr(C)]` and `bytemuck::Pod`, a test checks its
//! offsets against std430, and `cargo xtask codegen` writes `shaders/shared/layouts.glsl` (a test
//! fails when that file is stale).

pub mod consts;
pub mod dispatch;
pub mod glsl_twin;
pub mod gpu;
pub mod layout;

pub use gpu::*;
