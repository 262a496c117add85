//! Recording work: dispatches, dynamic rendering and draws. Each call checks its preconditions
//! against the recording's state (`state.rs`) and panics, naming the pipeline and the resource,
//! when one does not hold.

use ash::vk;

use crate::buffer::Buffer;
use crate::commands::Recorder;
use crate::error::{Error, Result};
use crate::hazard::{Scope, Target, Use};
use crate::image::Image;
use crate::state::{IndexBuffer, Rendering};
use crate::sync::Access;

/// What a rendering draws into, and the indirect arguments its draws read: everything a
/// rendering needs prepared before it begins (no barrier may be recorded inside one). The
/// attachments' layouts and barriers are derived; the draws' bindings are prepared by pushing them
/// before `begin_rendering`.
#[derive(Debug, Clone, Copy, Default)]
pub struct RenderTargets<'a> {
    /// The colour attachments, in the pipelines' order.
    pub colors: &'a [ColorTarget<'a>],
    /// The depth attachment, if any.
    pub depth: Option<DepthTarget<'a>>,
    /// Buffers the draws read indirect arguments from.
    pub indirect: &'a [&'a Buffer],
}

/// A colour attachment of a rendering.
#[derive(Debug, Clone, Copy)]
pub struct ColorTarget<'a> {
    /// The image.
    pub image: &'a Image,
    /// Clear to this value, or load the existing contents when `None`.
    pub clear: Option<[f32; 4]>,
}

/// The depth attachment of a rendering.
#[derive(Debug, Clone, Copy)]
pub struct DepthTarget<'a> {
    /// The image.
    pub image: &'a Image,
    /// Clear to this depth, or load the existing contents when `None`.
    pub clear: Option<f32>,
}

const DISPATCH_ARGS: u64 = std::mem::size_of::<vk::DispatchIndirectCommand>() as u64;
const DRAW_ARGS: u64 = std::mem::size_of::<vk::DrawIndirectCommand>() as u64;

impl Recorder {
    /// Dispatches compute workgroups; errors if a count exceeds the device limit. Panics unless a
    /// compute pipeline is bound with all its bindings (and push constants) pushed, outside a
    /// rendering.
    pub fn dispatch(&mut self, x: u32, y: u32, z: u32) -> Result<()> {
        self.check_dispatch("dispatch");
        let max = self.shared.info.max_compute_work_group_count;
        if x > max[0] || y > max[1] || z > max[2] {
            return Err(Error::Invalid(format!(
                "dispatch ({x}, {y}, {z}) exceeds maxComputeWorkGroupCount {max:?}"
            )));
        }
        if x == 0 || y == 0 || z == 0 {
            return Ok(());
        }
        self.sync_bound("dispatch", None);
        // SAFETY: recording outside a rendering, with a compute pipeline bound whose every
        // binding and push constant was set since (`check_dispatch`); counts within the limits.
        unsafe { self.shared.device.cmd_dispatch(self.cmd, x, y, z) };
        Ok(())
    }

    /// Dispatches with the `uvec3` group counts stored at `offset` in `args`, which must have
    /// `INDIRECT_BUFFER` usage and hold the 12 bytes at a multiple of 4; the same pipeline checks
    /// as [`Self::dispatch`] apply. The counts themselves are GPU data: the shader that writes
    /// them must keep each within `DeviceInfo::max_compute_work_group_count` (the host cannot
    /// read them at record time).
    pub fn dispatch_indirect(&mut self, args: &Buffer, offset: u64) {
        self.check_dispatch("dispatch_indirect");
        self.check_indirect("dispatch_indirect", args, offset, DISPATCH_ARGS);
        args.used_by(self.index);
        self.sync_bound("dispatch_indirect", Some(args));
        // SAFETY: as for `dispatch`; `args` has INDIRECT_BUFFER usage and holds the arguments at
        // an aligned offset (`check_indirect`). The group counts are GPU data no host check can
        // see: keeping them within the limits is the documented contract above, left to the
        // shader that writes them (the one precondition here that is not checked).
        unsafe {
            self.shared
                .device
                .cmd_dispatch_indirect(self.cmd, args.raw(), offset)
        };
    }

    /// Begins dynamic rendering into the targets over their full extent, with matching viewport
    /// (y down, depth 0..1) and scissor, after the barriers and layout transitions that the
    /// attachments and the indirect arguments need. Panics when a rendering is already open, or
    /// when an attachment lacks its usage or is smaller than the first one.
    pub fn begin_rendering(&mut self, targets: &RenderTargets<'_>) {
        let RenderTargets {
            colors,
            depth,
            indirect,
        } = *targets;
        assert!(
            self.state.rendering.is_none(),
            "begin_rendering in recording {:?}: a rendering is already open (end_rendering first)",
            self.label
        );
        let extent = colors
            .first()
            .map(|c| c.image.extent())
            .or(depth.map(|d| d.image.extent()))
            .expect("rendering needs at least one attachment");
        let max = self.shared.info.max_color_attachments;
        assert!(
            colors.len() <= max as usize,
            "begin_rendering: {} colour attachments, the device allows {max}",
            colors.len()
        );
        for c in colors {
            check_attachment(c.image, extent, vk::ImageUsageFlags::COLOR_ATTACHMENT);
            assert!(
                !c.image.is_depth(),
                "begin_rendering: depth image {:?} given as a colour target",
                c.image.name()
            );
        }
        if let Some(d) = depth {
            check_attachment(
                d.image,
                extent,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            );
            assert!(
                d.image.is_depth(),
                "begin_rendering: colour image {:?} given as the depth target",
                d.image.name()
            );
        }
        let mut uses: Vec<(&Target, Use)> = colors
            .iter()
            .map(|c| {
                let u = Use::write(Access::COLOR_ATTACHMENT)
                    .in_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
                (c.image.target(), u)
            })
            .collect();
        if let Some(d) = depth {
            let u = Use::write(Access::DEPTH_ATTACHMENT)
                .in_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
            uses.push((d.image.target(), u));
        }
        for args in indirect {
            args.used_by(self.index);
            uses.push((args.target(), Use::read(Access::INDIRECT)));
        }
        self.sync("begin_rendering", Scope::NextRendering, &uses);
        let color_infos: Vec<_> = colors
            .iter()
            .map(|c| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(c.image.view())
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(if c.clear.is_some() {
                        vk::AttachmentLoadOp::CLEAR
                    } else {
                        vk::AttachmentLoadOp::LOAD
                    })
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue {
                        color: vk::ClearColorValue {
                            float32: c.clear.unwrap_or_default(),
                        },
                    })
            })
            .collect();
        let depth_info = depth.map(|d| {
            vk::RenderingAttachmentInfo::default()
                .image_view(d.image.view())
                .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .load_op(if d.clear.is_some() {
                    vk::AttachmentLoadOp::CLEAR
                } else {
                    vk::AttachmentLoadOp::LOAD
                })
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: d.clear.unwrap_or(1.0),
                        stencil: 0,
                    },
                })
        });
        let area = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D {
                width: extent.0,
                height: extent.1,
            },
        };
        let mut info = vk::RenderingInfo::default()
            .render_area(area)
            .layer_count(1)
            .color_attachments(&color_infos);
        if let Some(d) = depth_info.as_ref() {
            info = info.depth_attachment(d);
        }
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: extent.0 as f32,
            height: extent.1 as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: recording outside a rendering (checked above); every attachment has its usage,
        // was transitioned to the layout named above (`sync`) and contains the render area
        // (`check_attachment`); the images outlive the recording (the graveyard).
        unsafe {
            self.shared.device.cmd_begin_rendering(self.cmd, &info);
            self.shared
                .device
                .cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.shared.device.cmd_set_scissor(self.cmd, 0, &[area]);
        }
        self.state.renderings += 1;
        self.state.rendering = Some(Rendering {
            color_formats: colors.iter().map(|c| c.image.format()).collect(),
            depth_format: depth.map_or(vk::Format::UNDEFINED, |d| d.image.format()),
        });
    }

    /// Ends dynamic rendering; panics when none is open.
    pub fn end_rendering(&mut self) {
        assert!(
            self.state.rendering.take().is_some(),
            "end_rendering in recording {:?}: no rendering is open",
            self.label
        );
        // SAFETY: recording inside a rendering begun by `begin_rendering` (checked above).
        unsafe { self.shared.device.cmd_end_rendering(self.cmd) };
    }

    /// Draws non-indexed vertices (vertex pulling: no vertex buffers). Panics unless a graphics
    /// pipeline made for the open rendering's formats is bound with all its bindings (and push
    /// constants) pushed.
    pub fn draw(&mut self, vertex_count: u32, instance_count: u32) {
        self.check_draw("draw");
        self.sync_bound("draw", None);
        // SAFETY: recording inside a rendering whose formats match the bound graphics pipeline,
        // every binding and push constant set (`check_draw`); no vertex buffers are declared.
        unsafe {
            self.shared
                .device
                .cmd_draw(self.cmd, vertex_count, instance_count, 0, 0)
        };
    }

    /// Draws with `draw_count` (0 or 1: multi-draw is not enabled) `VkDrawIndirectCommand`s read
    /// from `args` at `offset`, which must have `INDIRECT_BUFFER` usage and hold them at a
    /// multiple of 4; the same pipeline checks as [`Self::draw`] apply. Any `firstInstance` is
    /// allowed (drawIndirectFirstInstance is enabled); the counts are the shader's to bound.
    pub fn draw_indirect(&mut self, args: &Buffer, offset: u64, draw_count: u32) {
        self.check_draw("draw_indirect");
        assert!(
            draw_count <= 1,
            "draw_indirect with buffer {:?}: draw_count {draw_count} needs multiDrawIndirect, \
             which radcache does not enable",
            args.name()
        );
        self.check_indirect(
            "draw_indirect",
            args,
            offset,
            u64::from(draw_count) * DRAW_ARGS,
        );
        args.used_by(self.index);
        self.sync_bound("draw_indirect", Some(args));
        // SAFETY: as for `draw`; `args` has INDIRECT_BUFFER usage and holds `draw_count` ≤ 1
        // commands at an aligned offset (`check_indirect`). Every value of their fields is valid:
        // drawIndirectFirstInstance is enabled, and vertex pulling reads no vertex buffers.
        unsafe {
            self.shared.device.cmd_draw_indirect(
                self.cmd,
                args.raw(),
                offset,
                draw_count,
                DRAW_ARGS as u32,
            )
        };
    }

    /// Binds a `u32` index buffer from byte `offset` (a multiple of 4); panics unless `indices`
    /// has `INDEX_BUFFER` usage and `offset` lies inside it.
    pub fn bind_index_buffer(&mut self, indices: &Buffer, offset: u64) {
        assert!(
            indices.usage().contains(vk::BufferUsageFlags::INDEX_BUFFER),
            "bind_index_buffer: buffer {:?} has no INDEX_BUFFER usage",
            indices.name()
        );
        assert!(
            offset.is_multiple_of(4) && offset < indices.size(),
            "bind_index_buffer: offset {offset} is not a multiple of 4 inside buffer {:?} ({} \
             bytes)",
            indices.name(),
            indices.size()
        );
        indices.used_by(self.index);
        let uses = [(indices.target(), Use::read(Access::INDEX_READ))];
        self.sync(
            "bind_index_buffer",
            self.scope_or(Scope::NextRendering),
            &uses,
        );
        // SAFETY: recording; the buffer has INDEX_BUFFER usage and `offset` is a multiple of the
        // index size inside it (checked above); it outlives the recording (the graveyard).
        unsafe {
            self.shared.device.cmd_bind_index_buffer(
                self.cmd,
                indices.raw(),
                offset,
                vk::IndexType::UINT32,
            )
        };
        self.state.index = Some(IndexBuffer {
            name: indices.name().to_string(),
            count: (indices.size() - offset) / 4,
        });
    }

    /// Draws indexed triangles; `first_instance` reaches the shader as `gl_InstanceIndex`. Panics
    /// as [`Self::draw`] does, and unless the bound index buffer holds the indices drawn.
    pub fn draw_indexed(&mut self, index_count: u32, first_index: u32, first_instance: u32) {
        self.check_draw("draw_indexed");
        self.sync_bound("draw_indexed", None);
        let index = self
            .state
            .index
            .as_ref()
            .expect("draw_indexed: no index buffer is bound (bind_index_buffer first)");
        let end = u64::from(first_index) + u64::from(index_count);
        assert!(
            end <= index.count,
            "draw_indexed: indices {first_index}..{end} run past the end of index buffer {:?} \
             ({} indices)",
            index.name,
            index.count
        );
        // SAFETY: as for `draw`; an index buffer with INDEX_BUFFER usage is bound and holds the
        // indices drawn (checked above).
        unsafe {
            self.shared.device.cmd_draw_indexed(
                self.cmd,
                index_count,
                1,
                first_index,
                0,
                first_instance,
            )
        };
    }
}

/// Panics unless `image` has `usage` and contains `extent`.
fn check_attachment(image: &Image, extent: (u32, u32), usage: vk::ImageUsageFlags) {
    assert!(
        image.usage().contains(usage),
        "begin_rendering: image {:?} has no {usage:?} usage",
        image.name()
    );
    let (w, h) = image.extent();
    assert!(
        w >= extent.0 && h >= extent.1,
        "begin_rendering: image {:?} ({w}×{h}) is smaller than the render area ({}×{})",
        image.name(),
        extent.0,
        extent.1
    );
}

impl Recorder {
    /// Derives the barriers the bound pipeline's pushed resources (and `args`, read as indirect
    /// arguments) need before a dispatch, or checks that a draw needs none, then checks that
    /// every pushed image is in its descriptor's layout.
    fn sync_bound(&mut self, call: &str, args: Option<&Buffer>) {
        // The uses are taken out of the bound pipeline while `sync` needs the recorder.
        let pushed = std::mem::take(
            &mut self
                .state
                .bound
                .as_mut()
                .expect("check_dispatch or check_draw found it bound")
                .uses,
        );
        let mut uses: Vec<(&Target, Use)> = pushed.iter().map(|p| (&p.target, p.use_)).collect();
        uses.extend(args.map(|a| (a.target(), Use::read(Access::INDIRECT))));
        self.sync(call, self.scope_or(Scope::Outside), &uses);
        self.state
            .bound
            .as_mut()
            .expect("check_dispatch or check_draw found it bound")
            .uses = pushed;
        self.check_layouts(call);
    }
}
