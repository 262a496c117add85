//! Recording barriers, image transitions, copies, fills and clears; image readback.

use ash::vk;
use bytemuck::Pod;

use crate::buffer::{Buffer, BufferDesc, MemoryLocation};
use crate::commands::Recorder;
use crate::context::Context;
use crate::error::{Error, Result};
use crate::image::Image;
use crate::sync::{Access, ImageUse};

impl Recorder {
    /// A global memory dependency: everything `src` did is visible to `dst`.
    pub fn barrier(&mut self, src: Access, dst: Access) {
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(src.stage)
            .src_access_mask(src.access)
            .dst_stage_mask(dst.stage)
            .dst_access_mask(dst.access)];
        let info = vk::DependencyInfo::default().memory_barriers(&barrier);
        // SAFETY: recording; `info` outlives the call.
        unsafe { self.shared.device.cmd_pipeline_barrier2(self.cmd, &info) };
    }

    /// Transitions `image` to the layout of `usage`, after whatever it was last used for.
    pub fn use_image(&mut self, image: &Image, usage: ImageUse) {
        let mut state = image.state.lock().unwrap_or_else(|p| p.into_inner());
        let (old_layout, src) = *state;
        let (new_layout, dst) = usage.layout_and_access(image.is_depth());
        let barrier = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(if src.stage.is_empty() {
                vk::PipelineStageFlags2::NONE
            } else {
                src.stage
            })
            .src_access_mask(src.access)
            .dst_stage_mask(dst.stage)
            .dst_access_mask(dst.access)
            .old_layout(old_layout)
            .new_layout(new_layout)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.raw())
            .subresource_range(image.subresource_range())];
        let info = vk::DependencyInfo::default().image_memory_barriers(&barrier);
        // SAFETY: recording; the image is live and `old_layout` is its tracked current layout.
        unsafe { self.shared.device.cmd_pipeline_barrier2(self.cmd, &info) };
        *state = (new_layout, dst);
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
        if size == 0 {
            return;
        }
        let region = [vk::BufferCopy {
            src_offset,
            dst_offset,
            size,
        }];
        // SAFETY: recording; both buffers have transfer usage and outlive the recording.
        unsafe {
            self.shared
                .device
                .cmd_copy_buffer(self.cmd, src.raw(), dst.raw(), &region)
        };
    }

    /// Fills `size` bytes (multiple of 4, or `vk::WHOLE_SIZE`) at `offset` with `value`.
    pub fn fill_buffer(&mut self, buffer: &Buffer, offset: u64, size: u64, value: u32) {
        // SAFETY: recording; the buffer has TRANSFER_DST usage and outlives the recording.
        unsafe {
            self.shared
                .device
                .cmd_fill_buffer(self.cmd, buffer.raw(), offset, size, value)
        };
    }

    /// Writes small data (at most 65536 bytes, a multiple of 4) into a buffer in the command
    /// stream.
    pub fn update_buffer<T: Pod>(&mut self, buffer: &Buffer, offset: u64, data: &[T]) {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        assert!(
            bytes.len() <= 65536 && bytes.len().is_multiple_of(4),
            "update_buffer size"
        );
        if bytes.is_empty() {
            return;
        }
        // SAFETY: recording; size limits checked above; the buffer outlives the recording.
        unsafe {
            self.shared
                .device
                .cmd_update_buffer(self.cmd, buffer.raw(), offset, bytes)
        };
    }

    /// Clears a colour image (it must be in `ImageUse::TransferDst`).
    pub fn clear_color(&mut self, image: &Image, value: [f32; 4]) {
        let range = [image.subresource_range()];
        let color = vk::ClearColorValue { float32: value };
        // SAFETY: recording; the image is in TRANSFER_DST_OPTIMAL (tracked by `use_image`).
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

    /// Copies a whole image (in `ImageUse::TransferSrc`) into a tightly packed buffer.
    pub fn copy_image_to_buffer(&mut self, image: &Image, buffer: &Buffer) {
        let (w, h) = image.extent();
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
        // SAFETY: recording; the image is in TRANSFER_SRC_OPTIMAL (tracked by `use_image`).
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
        rec.use_image(image, ImageUse::TransferSrc);
        rec.copy_image_to_buffer(image, &staging);
        rec.barrier(Access::TRANSFER_WRITE, Access::HOST_READ);
        self.submit(rec)?.wait()?;
        staging.read(count)
    }
}
