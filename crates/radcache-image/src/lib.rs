//! Images, image files and image error metrics for radcache.
//!
//! - [`Image`]: linear RGB `f32` beauty (row-major, top row first) plus named AOV [`Layer`]s.
//! - [`write_exr`] / [`read_exr`]: OpenEXR with render [`Metadata`] in header attributes; `f32`
//!   or `f16` samples; AOVs as `<layer>.<channel>` channels. The writer never stores NaN or
//!   ±inf: it fails with [`Error::NonFinite`] unless [`ExrOptions::sanitize`] is set. The reader
//!   also reads plain RGB(A) EXRs from other tools (e.g. environment maps).
//! - [`contact_sheet`]: a sequence's frames reduced and tiled into one image.
//! - [`write_png`]: 8-bit sRGB preview with exposure and an optional filmic curve ([`ToneMap`]).
//! - [`frame_path`], [`output_path`], [`png_beside`]: output path patterns (`frame_####.exr`).
//! - [`equal_error`]: the path tracer's time to reach an error, from its measured points.
//! - [`compare`] → [`Metrics`] (RMSE, relMSE, MAE, 8×8 block RMSE, mean ratios, FLIP,
//!   non-finite counts) and [`Thresholds::check`].
//!
//! Every file is written atomically (temporary file + rename, [`write_atomic`]), so readers of
//! a sequence never see a partial frame. Errors ([`Error`]) name the file concerned; bad input
//! never panics.

mod atomic;
mod color;
mod contact;
pub mod equal_error;
mod error;
mod exr_read;
mod exr_write;
mod flicker;
mod flip;
mod image;
mod metadata;
mod metrics;
mod paths;
mod preview;
mod thresholds;

pub use atomic::write_atomic;
pub use color::{
    aces_filmic, display_u8, exposure_scale, srgb_decode, srgb_encode, srgb_to_u8, tone_map,
    ToneMap,
};
pub use contact::{contact_sheet, reduce, reduction_factor, GAP as CONTACT_SHEET_GAP};
pub use error::{Error, Result};
pub use exr_read::read_exr;
pub use exr_write::{write_exr, ExrOptions};
pub use flicker::{
    flicker, FlickerMeter, FlickerMode, FlickerPair, FlickerReport, STATIC_TOLERANCE,
};
pub use image::{Image, Layer, ALBEDO, DEPTH, NORMAL};
pub use metadata::{Metadata, RADCACHE_VERSION};
pub use metrics::{compare, Metrics, BLOCK_SIZE};
pub use paths::{frame_path, has_frame_pattern, output_path, png_beside};
pub use preview::{to_srgb8, write_png, PngOptions};
pub use thresholds::Thresholds;
