//! Frames: the irradiance cache's frame ([`ic::IcRenderer`]) and the path tracer's
//! ([`path::render_path`]).
//!
//! FLOW (placeholder)

pub mod clock;
pub mod ic;
pub mod path;
pub mod settings;
