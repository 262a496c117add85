//! Small upload helpers shared by the scene's buffers, and the projection convention.

use glam::Mat4;
use radcache_vk::{vk, Buffer, BufferDesc, Context, MemoryLocation};

use crate::error::Result;

pub(crate) fn storage(
    ctx: &Context,
    name: &str,
    extra: vk::BufferUsageFlags,
    bytes: &[u8],
) -> Result<Buffer> {
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER | extra;
    if bytes.is_empty() {
        // Vulkan has no empty buffers; an unused binding still needs a valid one.
        return Ok(Buffer::new(
            ctx,
            &BufferDesc {
                name,
                size: 16,
                usage,
                location: MemoryLocation::GpuOnly,
                alignment: 0,
            },
        )?);
    }
    Ok(ctx.create_buffer_init(name, usage, bytes)?)
}

pub(crate) fn host_buffer(
    ctx: &Context,
    name: &str,
    usage: vk::BufferUsageFlags,
    size: u64,
) -> Result<Buffer> {
    Ok(Buffer::new(
        ctx,
        &BufferDesc {
            name,
            size: size.max(16),
            usage,
            location: MemoryLocation::CpuToGpu,
            alignment: 0,
        },
    )?)
}

pub(crate) fn cols(m: Mat4) -> [[f32; 4]; 4] {
    m.to_cols_array_2d()
}

/// The upper three rows of `m`, row-major (the TLAS instance layout).
pub(crate) fn rows3x4(m: Mat4) -> [f32; 12] {
    let t = m.transpose().to_cols_array();
    let mut out = [0.0; 12];
    out.copy_from_slice(&t[..12]);
    out
}

/// `clip_from_view` for radcache's rasterization and ray generation: a right-handed view looking
/// down −Z, reversed depth (1 at the near plane, 0 at infinity) and Vulkan's y-down clip space.
pub fn vulkan_clip_from_view(yfov: f32, aspect: f32, znear: f32) -> Mat4 {
    let flip_y = Mat4::from_diagonal(glam::Vec4::new(1.0, -1.0, 1.0, 1.0));
    flip_y * Mat4::perspective_infinite_reverse_rh(yfov, aspect, znear)
}
