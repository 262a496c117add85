//! Recording with pipelines: binding resources (push descriptors), push constants, dispatches,
//! dynamic rendering and draws.

use ash::vk;
use bytemuck::Pod;

use crate::buffer::Buffer;
use crate::commands::Recorder;
use crate::error::{Error, Result};
use crate::image::{Image, Sampler};
use crate::pipeline::{BindingKind, BindingLayout, Pipeline};
use crate::tlas::Tlas;

/// The pipeline bound last, remembered for bindings and push constants.
#[derive(Debug, Clone)]
pub(crate) struct BoundPipeline {
    bind_point: vk::PipelineBindPoint,
    layout: vk::PipelineLayout,
    bindings: Vec<BindingLayout>,
    push_constant_size: u32,
    stages: vk::ShaderStageFlags,
    name: String,
}

/// A resource bound at a binding of the current pipeline.
#[derive(Debug, Clone, Copy)]
pub enum Resource<'a> {
    /// A whole storage or uniform buffer.
    Buffer(&'a Buffer),
    /// A range (offset, size) of a buffer.
    BufferRange(&'a Buffer, u64, u64),
    /// A top-level acceleration structure.
    Tlas(&'a Tlas),
    /// A storage image (in `GENERAL` layout: `ImageUse::ComputeStorage`/`FragmentStorage`).
    StorageImage(&'a Image),
    /// A sampled image with its sampler (in a read-only layout).
    Sampled(&'a Image, &'a Sampler),
}

/// A colour attachment of a rendering.
#[derive(Debug, Clone, Copy)]
pub struct ColorTarget<'a> {
    /// The image (must be in `ImageUse::ColorAttachment`).
    pub image: &'a Image,
    /// Clear to this value, or load the existing contents when `None`.
    pub clear: Option<[f32; 4]>,
}

/// The depth attachment of a rendering.
#[derive(Debug, Clone, Copy)]
pub struct DepthTarget<'a> {
    /// The image (must be in `ImageUse::DepthAttachment`).
    pub image: &'a Image,
    /// Clear to this depth, or load the existing contents when `None`.
    pub clear: Option<f32>,
}

impl Recorder {
    /// Binds a compute or graphics pipeline.
    pub fn bind_pipeline(&mut self, pipeline: &Pipeline) {
        // SAFETY: recording; the pipeline is kept alive until this recording ends.
        unsafe {
            self.shared
                .device
                .cmd_bind_pipeline(self.cmd, pipeline.bind_point, pipeline.raw)
        };
        self.bound = Some(BoundPipeline {
            bind_point: pipeline.bind_point,
            layout: pipeline.layout,
            bindings: pipeline.bindings.clone(),
            push_constant_size: pipeline.push_constant_size,
            stages: pipeline.stages,
            name: pipeline.name().to_string(),
        });
    }

    fn bound(&self) -> &BoundPipeline {
        self.bound
            .as_ref()
            .expect("bind a pipeline before binding resources or dispatching")
    }

    /// Pushes the resources of the bound pipeline's binding table. Every binding is checked
    /// against the table (a mismatch is a programming error and panics).
    pub fn push_bindings(&mut self, resources: &[(u32, Resource<'_>)]) {
        let bound = self.bound().clone();
        let mut buffer_infos = Vec::with_capacity(resources.len());
        let mut image_infos = Vec::with_capacity(resources.len());
        let mut as_handles = Vec::with_capacity(resources.len());
        for (binding, res) in resources {
            let layout = bound
                .bindings
                .iter()
                .find(|b| b.binding == *binding)
                .unwrap_or_else(|| panic!("pipeline {} has no binding {binding}", bound.name));
            let ok = matches!(
                (layout.kind, res),
                (
                    BindingKind::StorageBuffer | BindingKind::UniformBuffer,
                    Resource::Buffer(_)
                ) | (
                    BindingKind::StorageBuffer | BindingKind::UniformBuffer,
                    Resource::BufferRange(..)
                ) | (BindingKind::AccelerationStructure, Resource::Tlas(_))
                    | (BindingKind::StorageImage, Resource::StorageImage(_))
                    | (BindingKind::SampledImage, Resource::Sampled(..))
            );
            assert!(
                ok,
                "pipeline {}: binding {binding} is {:?}, got {res:?}",
                bound.name, layout.kind
            );
            match res {
                Resource::Buffer(b) => buffer_infos.push(vk::DescriptorBufferInfo {
                    buffer: b.raw(),
                    offset: 0,
                    range: vk::WHOLE_SIZE,
                }),
                Resource::BufferRange(b, offset, size) => {
                    buffer_infos.push(vk::DescriptorBufferInfo {
                        buffer: b.raw(),
                        offset: *offset,
                        range: *size,
                    })
                }
                Resource::Tlas(t) => as_handles.push(t.raw()),
                Resource::StorageImage(i) => image_infos.push(vk::DescriptorImageInfo {
                    sampler: vk::Sampler::null(),
                    image_view: i.view(),
                    image_layout: vk::ImageLayout::GENERAL,
                }),
                Resource::Sampled(i, s) => image_infos.push(vk::DescriptorImageInfo {
                    sampler: s.raw(),
                    image_view: i.view(),
                    image_layout: if i.is_depth() {
                        vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL
                    } else {
                        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL
                    },
                }),
            }
        }
        // Second pass: build the writes, now that the info vectors no longer grow.
        let mut as_writes: Vec<vk::WriteDescriptorSetAccelerationStructureKHR<'_>> = as_handles
            .iter()
            .map(|h| {
                vk::WriteDescriptorSetAccelerationStructureKHR::default()
                    .acceleration_structures(std::slice::from_ref(h))
            })
            .collect();
        let (mut bi, mut ii) = (0, 0);
        let mut as_iter = as_writes.iter_mut();
        let mut writes = Vec::with_capacity(resources.len());
        for (binding, res) in resources {
            let kind = bound
                .bindings
                .iter()
                .find(|b| b.binding == *binding)
                .map(|b| b.kind)
                .unwrap_or(BindingKind::StorageBuffer);
            let w = vk::WriteDescriptorSet::default()
                .dst_binding(*binding)
                .descriptor_type(kind.descriptor_type());
            let w = match res {
                Resource::Buffer(_) | Resource::BufferRange(..) => {
                    bi += 1;
                    w.buffer_info(&buffer_infos[bi - 1..bi])
                }
                Resource::StorageImage(_) | Resource::Sampled(..) => {
                    ii += 1;
                    w.image_info(&image_infos[ii - 1..ii])
                }
                Resource::Tlas(_) => {
                    let next = as_iter.next().expect("one AS write per TLAS resource");
                    let mut w = w.push_next(next);
                    // The count is not implied by any slice for acceleration structures.
                    w.descriptor_count = 1;
                    w
                }
            };
            writes.push(w);
        }
        // SAFETY: recording; the writes match the bound pipeline's push-descriptor set layout
        // (checked above) and every resource is kept alive until this recording ends.
        unsafe {
            self.shared.push_descriptor.cmd_push_descriptor_set(
                self.cmd,
                bound.bind_point,
                bound.layout,
                0,
                &writes,
            )
        };
    }

    /// Sets the bound pipeline's push constants.
    pub fn push_constants<T: Pod>(&mut self, data: &T) {
        let bound = self.bound();
        let bytes = bytemuck::bytes_of(data);
        assert_eq!(
            bytes.len() as u32,
            bound.push_constant_size,
            "pipeline {}: push constants size",
            bound.name
        );
        // SAFETY: recording; the range matches the layout's single push-constant range.
        unsafe {
            self.shared
                .device
                .cmd_push_constants(self.cmd, bound.layout, bound.stages, 0, bytes)
        };
    }

    /// Dispatches compute workgroups; errors if a count exceeds the device limit.
    pub fn dispatch(&mut self, x: u32, y: u32, z: u32) -> Result<()> {
        let max = self.shared.info.max_compute_work_group_count;
        if x > max[0] || y > max[1] || z > max[2] {
            return Err(Error::Invalid(format!(
                "dispatch ({x}, {y}, {z}) exceeds maxComputeWorkGroupCount {max:?}"
            )));
        }
        if x == 0 || y == 0 || z == 0 {
            return Ok(());
        }
        // SAFETY: recording with a compute pipeline bound.
        unsafe { self.shared.device.cmd_dispatch(self.cmd, x, y, z) };
        Ok(())
    }

    /// Dispatches with the `uvec3` group counts stored at `offset` in `args`.
    pub fn dispatch_indirect(&mut self, args: &Buffer, offset: u64) {
        // SAFETY: recording with a compute pipeline bound; `args` has INDIRECT usage (validated).
        unsafe {
            self.shared
                .device
                .cmd_dispatch_indirect(self.cmd, args.raw(), offset)
        };
    }

    /// Begins dynamic rendering into the targets over their full extent, with matching viewport
    /// (y down, depth 0..1) and scissor.
    pub fn begin_rendering(&mut self, colors: &[ColorTarget<'_>], depth: Option<DepthTarget<'_>>) {
        let extent = colors
            .first()
            .map(|c| c.image.extent())
            .or(depth.map(|d| d.image.extent()))
            .expect("rendering needs at least one attachment");
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
        // SAFETY: recording outside a rendering; attachments are in the layouts named above
        // (callers transition them with `use_image`) and outlive the recording.
        unsafe {
            self.shared.device.cmd_begin_rendering(self.cmd, &info);
            self.shared
                .device
                .cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.shared.device.cmd_set_scissor(self.cmd, 0, &[area]);
        }
    }

    /// Ends dynamic rendering.
    pub fn end_rendering(&mut self) {
        // SAFETY: recording inside a rendering begun by `begin_rendering`.
        unsafe { self.shared.device.cmd_end_rendering(self.cmd) };
    }

    /// Draws non-indexed vertices (vertex pulling: no vertex buffers).
    pub fn draw(&mut self, vertex_count: u32, instance_count: u32) {
        // SAFETY: recording inside a rendering with a graphics pipeline bound.
        unsafe {
            self.shared
                .device
                .cmd_draw(self.cmd, vertex_count, instance_count, 0, 0)
        };
    }

    /// Draws with `VkDrawIndirectCommand`s read from `args`.
    pub fn draw_indirect(&mut self, args: &Buffer, offset: u64, draw_count: u32) {
        // SAFETY: recording inside a rendering with a graphics pipeline bound.
        unsafe {
            self.shared.device.cmd_draw_indirect(
                self.cmd,
                args.raw(),
                offset,
                draw_count,
                std::mem::size_of::<vk::DrawIndirectCommand>() as u32,
            )
        };
    }

    /// Binds a `u32` index buffer.
    pub fn bind_index_buffer(&mut self, indices: &Buffer, offset: u64) {
        // SAFETY: recording; the buffer has INDEX_BUFFER usage (validated by the layer).
        unsafe {
            self.shared.device.cmd_bind_index_buffer(
                self.cmd,
                indices.raw(),
                offset,
                vk::IndexType::UINT32,
            )
        };
    }

    /// Draws indexed triangles; `first_instance` reaches the shader as `gl_InstanceIndex`.
    pub fn draw_indexed(&mut self, index_count: u32, first_index: u32, first_instance: u32) {
        // SAFETY: recording inside a rendering with a graphics pipeline and index buffer bound.
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
