//! Recording copies, fills and clears; image readback; the explicit barrier the acceleration
//! structure builds of this crate use.
//!
//! None of these is allowed inside a rendering, and each checks its ranges: a violation is a
//! programming error and panics. The barriers and layout transitions before each are derived from
//! its source and destination (`hazard.rs`).

use ash::vk;
use bytemuck::Pod;

use crate::buffer::{Buffer, BufferDesc, MemoryLocation};
use crate::commands::Recorder;
use crate::context::Context;
use crate::error::{Error, Result};
use crate::hazard::{Scope, Use};
use crate::image::Image;
use crate::sync::Access;

impl Recorder {
    /// A global memory dependency: everything `src` did is visible to `dst`. Only for what the
    /// tracks do not see (acceleration structure builds and the ray queries that read them).
    pub(crate) fn barrier(&mut self, src: Access, dst: Access) {
        self.check_outside_rendering("barrier");
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(src.stage)
            .src_access_mask(src.access)
            .dst_stage_mask(dst.stage)
            .dst_access_mask(dst.access)];
        let info = vk::DependencyInfo::default().memory_barriers(&barrier);
        // SAFETY: recording outside a rendering (checked above); `info` outlives the call.
        unsafe { self.shared.device.cmd_pipeline_barrier2(self.cmd, &info) };
    }

    /// Copies `size` bytes between buffers.
    pub fn copy_buffer(
        &mut self,
        src: &Buffer,
        src_offset: u64,
        dst: &Buffer,
        dst_offset: u64,
        size: u64,
    ) {
        self.check_outside_rendering("copy_buffer");
        if size == 0 {
            return;
        }
        let in_range =
            |b: &Buffer, offset: u64| offset.checked_add(size).is_some_and(|e| e <= b.size());
        assert!(
            in_range(src, src_offset) && in_range(dst, dst_offset),
            "copy_buffer: {size} bytes from {:?}+{src_offset} ({} bytes) to {:?}+{dst_offset} ({} \
             bytes) run past the end of a buffer",
            src.name(),
            src.size(),
            dst.name(),
            dst.size()
        );
        assert!(
            src.raw() != dst.raw()
                || src_offset + size <= dst_offset
                || dst_offset + size <= src_offset,
            "copy_buffer: overlapping ranges within buffer {:?}",
            src.name()
        );
        src.used_by(self.index);
        dst.used_by(self.index);
        let uses = [
            (src.target(), Use::read(Access::TRANSFER_READ)),
            (dst.target(), Use::write(Access::TRANSFER_WRITE)),
        ];
        self.sync("copy_buffer", Scope::Outside, &uses);
        let region = [vk::BufferCopy {
            src_offset,
            dst_offset,
            size,
        }];
        // SAFETY: recording outside a rendering; both buffers have transfer usage (always added
        // at creation), the ranges lie inside them and do not overlap (checked above), and both
        // outlive the recording (the graveyard).
        unsafe {
            self.shared
                .device
                .cmd_copy_buffer(self.cmd, src.raw(), dst.raw(), &region)
        };
    }

    /// Fills `size` bytes (multiple of 4, or `vk::WHOLE_SIZE`) at `offset` with `value`.
    pub fn fill_buffer(&mut self, buffer: &Buffer, offset: u64, size: u64, value: u32) {
        self.check_outside_rendering("fill_buffer");
        let whole = size == vk::WHOLE_SIZE;
        assert!(
            offset.is_multiple_of(4)
                && offset < buffer.size()
                && (whole
                    || (size > 0
                        && size.is_multiple_of(4)
                        && offset.checked_add(size).is_some_and(|e| e <= buffer.size()))),
            "fill_buffer: {size} bytes at {offset} of buffer {:?} ({} bytes): offset and size \
             must be multiples of 4 inside the buffer",
            buffer.name(),
            buffer.size()
        );
        buffer.used_by(self.index);
        let uses = [(buffer.target(), Use::write(Access::TRANSFER_WRITE))];
        self.sync("fill_buffer", Scope::Outside, &uses);
        // SAFETY: recording outside a rendering; the buffer has TRANSFER_DST usage (always
        // added), the range is aligned and inside it (checked above), and it outlives the
        // recording (the graveyard).
        unsafe {
            self.shared
                .device
                .cmd_fill_buffer(self.cmd, buffer.raw(), offset, size, value)
        };
    }

    /// Writes small data (at most 65536 bytes, a multiple of 4) into a buffer in the command
    /// stream.
    pub fn update_buffer<T: Pod>(&mut self, buffer: &Buffer, offset: u64, data: &[T]) {
        self.check_outside_rendering("update_buffer");
        let bytes: &[u8] = bytemuck::cast_slice(data);
        assert!(
            bytes.len() <= 65536 && bytes.len().is_multiple_of(4),
            "update_buffer of buffer {:?}: {} bytes (at most 65536, a multiple of 4)",
            buffer.name(),
            bytes.len()
        );
        if bytes.is_empty() {
            return;
        }
        assert!(
            offset.is_multiple_of(4)
                && offset
                    .checked_add(bytes.len() as u64)
                    .is_some_and(|e| e <= buffer.size()),
            "update_buffer: {} bytes at {offset} run past the end of buffer {:?} ({} bytes) or \
             are not 4-aligned",
            bytes.len(),
            buffer.name(),
            buffer.size()
        );
        buffer.used_by(self.index);
        let uses = [(buffer.target(), Use::write(Access::TRANSFER_WRITE))];
        self.sync("update_buffer", Scope::Outside, &uses);
        // SAFETY: recording outside a rendering; size, alignment and range checked above; the
        // buffer has TRANSFER_DST usage (always added) and outlives the recording.
        unsafe {
            self.shared
                .device
                .cmd_update_buffer(self.cmd, buffer.raw(), offset, bytes)
        };
    }

    /// Clears a colour image.
    pub fn clear_color(&mut self, image: &Image, value: [f32; 4]) {
        self.check_outside_rendering("clear_color");
        assert!(
            !image.is_depth(),
            "clear_color: image {:?} is a depth image",
            image.name()
        );
        let uses = [(
            image.target(),
            Use::write(Access::TRANSFER_WRITE).in_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL),
        )];
        self.sync("clear_color", Scope::Outside, &uses);
        let range = [image.subresource_range()];
        let color = vk::ClearColorValue { float32: value };
        // SAFETY: recording outside a rendering; a colour image with TRANSFER_DST usage (always
        // added), transitioned to TRANSFER_DST_OPTIMAL above.
        unsafe {
            self.shared.device.cmd_clear_color_image(
                self.cmd,
                image.raw(),
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &color,
                &range,
            )
        };
    }

    /// Copies a whole image into a tightly packed buffer.
    pub fn copy_image_to_buffer(&mut self, image: &Image, buffer: &Buffer) {
        self.check_outside_rendering("copy_image_to_buffer");
        let (w, h) = image.extent();
        let texel = texel_bytes(image.format()).unwrap_or_else(|| {
            panic!(
                "copy_image_to_buffer: the texel size of image {:?}'s format {:?} is unknown",
                image.name(),
                image.format()
            )
        });
        let bytes = u64::from(w) * u64::from(h) * texel;
        assert!(
            bytes <= buffer.size(),
            "copy_image_to_buffer: image {:?} needs {bytes} bytes, buffer {:?} has {}",
            image.name(),
            buffer.name(),
            buffer.size()
        );
        buffer.used_by(self.index);
        let uses = [
            (
                image.target(),
                Use::read(Access::TRANSFER_READ).in_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
            ),
            (buffer.target(), Use::write(Access::TRANSFER_WRITE)),
        ];
        self.sync("copy_image_to_buffer", Scope::Outside, &uses);
        let region = [vk::BufferImageCopy {
            buffer_offset: 0,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: image.aspect(),
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D {
                width: w,
                height: h,
                depth: 1,
            },
        }];
        // SAFETY: recording outside a rendering; the image was transitioned to
        // TRANSFER_SRC_OPTIMAL above and the buffer holds every texel (checked above); both have transfer
        // usage (always added).
        unsafe {
            self.shared.device.cmd_copy_image_to_buffer(
                self.cmd,
                image.raw(),
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer.raw(),
                &region,
            )
        };
    }
}

/// Bytes per texel of the formats radcache reads back.
fn texel_bytes(format: vk::Format) -> Option<u64> {
    match format {
        vk::Format::R32G32B32A32_SFLOAT => Some(16),
        vk::Format::R16G16B16A16_SFLOAT => Some(8),
        vk::Format::R32_SFLOAT | vk::Format::D32_SFLOAT | vk::Format::R32_UINT => Some(4),
        vk::Format::R32G32_SFLOAT | vk::Format::R32G32_UINT => Some(8),
        vk::Format::R8G8B8A8_UNORM | vk::Format::R8G8B8A8_SRGB => Some(4),
        _ => None,
    }
}

impl Context {
    /// Reads a whole image back as `T` texels (e.g. `[f32; 4]` for RGBA32F), waiting for the GPU.
    pub fn read_image<T: Pod>(&self, image: &Image) -> Result<Vec<T>> {
        let texel = texel_bytes(image.format()).ok_or_else(|| {
            Error::Invalid(format!(
                "readback of {:?} images is not supported",
                image.format()
            ))
        })?;
        if texel != std::mem::size_of::<T>() as u64 {
            return Err(Error::Invalid(format!(
                "image {:?} has {texel}-byte texels, asked for {}",
                image.name(),
                std::mem::size_of::<T>()
            )));
        }
        let (w, h) = image.extent();
        let count = w as usize * h as usize;
        let staging = Buffer::new(
            self,
            &BufferDesc {
                name: "staging.image_readback",
                size: count as u64 * texel,
                usage: vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
                alignment: 0,
            },
        )?;
        let mut rec = self.begin("image_readback")?;
        rec.copy_image_to_buffer(image, &staging);
        self.submit(rec)?.wait()?;
        staging.read(count)
    }
}
