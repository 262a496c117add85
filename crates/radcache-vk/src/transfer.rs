//! Recording barriers, image transitions, copies, fills and clears; image readback.
//!
//! None of these is allowed inside a rendering, and each checks its ranges and the tracked layout
//! of the images it touches: a violation is a programming error and panics.

use ash::vk;
use bytemuck::Pod;

use crate::buffer::{Buffer, BufferDesc, MemoryLocation};
use crate::commands::Recorder;
use crate::context::Context;
use crate::error::{Error, Result};
use crate::image::Image;
use crate::state::layout_of;
use crate::sync::{Access, ImageUse};

impl Recorder {
    /// A global memory dependency: everything `src` did is visible to `dst`.
    pub fn barrier(&mut self, src: Access, dst: Access) {
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

    /// Transitions `image` to the layout of `usage`, after whatever it was last used for.
    ///
    /// The layout is tracked per image at record time, so recordings that touch an image must
    /// reach the queue in the order they were recorded: this panics when another recording that
    /// transitioned `image` is still open (not submitted, not dropped). A recording dropped
    /// unsubmitted leaves its images `UNDEFINED` (their contents are then undefined too).
    pub fn use_image(&mut self, image: &Image, usage: ImageUse) {
        self.check_outside_rendering("use_image");
        let mut state = image.state.lock().unwrap_or_else(|p| p.into_inner());
        assert!(
            state.recording == self.index || !self.shared.is_unsubmitted(state.recording),
            "use_image in recording {:?}: image {:?} was last transitioned by recording {}, which \
             is still open (submit or drop it first: layouts are tracked in record order)",
            self.label,
            image.name(),
            state.recording
        );
        let (old_layout, src) = (state.layout, state.access);
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
        // SAFETY: recording outside a rendering (checked above); the image is live and
        // `old_layout` is the layout it will have when this barrier executes: the tracked layout
        // was set by this recording, by one already submitted (queue order = record order), or
        // reset to UNDEFINED when its recording was abandoned (checked above).
        unsafe { self.shared.device.cmd_pipeline_barrier2(self.cmd, &info) };
        state.layout = new_layout;
        state.access = dst;
        if state.recording != self.index {
            state.recording = self.index;
            drop(state);
            self.state.touched.push(image.state.clone());
        }
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
        // SAFETY: recording outside a rendering; size, alignment and range checked above; the
        // buffer has TRANSFER_DST usage (always added) and outlives the recording.
        unsafe {
            self.shared
                .device
                .cmd_update_buffer(self.cmd, buffer.raw(), offset, bytes)
        };
    }

    /// Clears a colour image (it must be in `ImageUse::TransferDst`).
    pub fn clear_color(&mut self, image: &Image, value: [f32; 4]) {
        self.check_outside_rendering("clear_color");
        assert!(
            !image.is_depth(),
            "clear_color: image {:?} is a depth image",
            image.name()
        );
        check_layout("clear_color", image, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
        let range = [image.subresource_range()];
        let color = vk::ClearColorValue { float32: value };
        // SAFETY: recording outside a rendering; a colour image with TRANSFER_DST usage (always
        // added) in TRANSFER_DST_OPTIMAL by its tracked layout (checked above, see `use_image`).
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
        self.check_outside_rendering("copy_image_to_buffer");
        check_layout(
            "copy_image_to_buffer",
            image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        );
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
        // SAFETY: recording outside a rendering; the image is in TRANSFER_SRC_OPTIMAL by its
        // tracked layout and the buffer holds every texel (checked above); both have transfer
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

/// Panics unless `image`'s tracked layout is `layout`.
fn check_layout(call: &str, image: &Image, layout: vk::ImageLayout) {
    let current = layout_of(&image.state);
    assert!(
        current == layout,
        "{call}: image {:?} is in layout {current:?}, not {layout:?} (use_image first)",
        image.name()
    );
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
