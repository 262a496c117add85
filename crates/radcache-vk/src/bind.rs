//! Recording with pipelines: binding a pipeline, its resources (push descriptors) and its push
//! constants. Each resource is checked against the pipeline's binding table, its usage and its
//! range when it is pushed; which bindings were pushed is remembered for the checks of the next
//! dispatch or draw (`state.rs`).

use ash::vk;
use bytemuck::Pod;

use crate::buffer::Buffer;
use crate::commands::Recorder;
use crate::hazard::{Scope, Target, Use};
use crate::image::{Image, Sampler};
use crate::pipeline::{BindingKind, BindingLayout, Pipeline};
use crate::state::{BoundPipeline, Pushed};
use crate::sync::Access;
use crate::tlas::Tlas;

/// A resource bound at a binding of the current pipeline.
#[derive(Debug, Clone, Copy)]
pub enum Resource<'a> {
    /// A whole storage or uniform buffer.
    Buffer(&'a Buffer),
    /// A range (offset, size) of a buffer.
    BufferRange(&'a Buffer, u64, u64),
    /// A top-level acceleration structure.
    Tlas(&'a Tlas),
    /// A storage image (transitioned to `GENERAL` for the dispatch or draw).
    StorageImage(&'a Image),
    /// A sampled image with its sampler (in a read-only layout).
    Sampled(&'a Image, &'a Sampler),
}

impl Recorder {
    /// Binds a compute or graphics pipeline. Bindings and push constants must be pushed again
    /// for it before the next dispatch or draw.
    pub fn bind_pipeline(&mut self, pipeline: &Pipeline) {
        // SAFETY: recording; the pipeline is a live object of this device, and the graveyard
        // keeps it until this recording has ended (`DeviceShared::retire`).
        unsafe {
            self.shared
                .device
                .cmd_bind_pipeline(self.cmd, pipeline.bind_point, pipeline.raw)
        };
        self.state.bound = Some(BoundPipeline::new(pipeline));
    }

    /// Pushes resources of the bound pipeline's binding table (all of them, or some now and the
    /// rest in later calls before the dispatch or draw). Every resource is checked against the
    /// table, its usage and its range; a mismatch is a programming error and panics.
    pub fn push_bindings(&mut self, resources: &[(u32, Resource<'_>)]) {
        let bound = self.bound_for("push_bindings");
        let (pipeline, bind_point, layout) = (bound.name.clone(), bound.bind_point, bound.layout);
        let layouts: Vec<BindingLayout> = resources
            .iter()
            .map(|(binding, res)| {
                let l = bound
                    .bindings
                    .iter()
                    .find(|b| b.binding == *binding)
                    .copied()
                    .unwrap_or_else(|| panic!("pipeline {pipeline:?} has no binding {binding}"));
                assert!(
                    l.count == 1,
                    "pipeline {pipeline:?}: binding {binding} is an array of {} descriptors; \
                     push_bindings writes one resource per binding",
                    l.count
                );
                self.check_resource(&pipeline, &l, res);
                l
            })
            .collect();
        let mut buffer_infos = Vec::with_capacity(resources.len());
        let mut image_infos = Vec::with_capacity(resources.len());
        let mut as_handles = Vec::with_capacity(resources.len());
        for (_, res) in resources {
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
                Resource::StorageImage(i) | Resource::Sampled(i, _) => {
                    image_infos.push(vk::DescriptorImageInfo {
                        sampler: match res {
                            Resource::Sampled(_, s) => s.raw(),
                            _ => vk::Sampler::null(),
                        },
                        image_view: i.view(),
                        image_layout: descriptor_layout(res),
                    })
                }
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
        for ((binding, res), l) in resources.iter().zip(&layouts) {
            let w = vk::WriteDescriptorSet::default()
                .dst_binding(*binding)
                .descriptor_type(l.kind.descriptor_type());
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
        // SAFETY: recording; each write matches the kind and count of its binding in the bound
        // pipeline's push-descriptor set layout, each buffer has the usage of its kind and its
        // range lies inside it at an allowed offset, each TLAS was built, each image has the
        // usage of its kind (all checked above). The layout an image descriptor names is checked
        // against the image's tracked layout at every dispatch or draw that may use it. Every
        // resource is kept alive by the graveyard until this recording has ended.
        unsafe {
            self.shared
                .push_descriptor
                .cmd_push_descriptor_set(self.cmd, bind_point, layout, 0, &writes)
        };
        let bound = self.state.bound.as_ref().expect("checked above");
        let graphics = bound.bind_point == vk::PipelineBindPoint::GRAPHICS;
        let stage = if graphics {
            vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::FRAGMENT_SHADER
        } else {
            vk::PipelineStageFlags2::COMPUTE_SHADER
        };
        let pushed: Vec<Pushed> = resources
            .iter()
            .zip(&layouts)
            .filter_map(|((binding, res), l)| {
                let writes = bound.written.contains(binding);
                shader_use(res, l.kind, stage, writes).map(|(target, use_)| Pushed {
                    binding: *binding,
                    target: target.clone(),
                    use_,
                })
            })
            .collect();
        for (binding, res) in resources {
            if let Resource::Buffer(b) | Resource::BufferRange(b, ..) = res {
                b.used_by(self.index);
            }
            let bound = self.state.bound.as_mut().expect("checked above");
            if !bound.pushed.contains(binding) {
                bound.pushed.push(*binding);
            }
            bound.uses.retain(|u| u.binding != *binding);
        }
        if graphics {
            // The draws come inside a rendering, where no barrier may be recorded: derive them
            // now (outside one, for the next rendering), or check that none is needed.
            let uses: Vec<_> = pushed.iter().map(|p| (&p.target, p.use_)).collect();
            self.sync("push_bindings", self.scope_or(Scope::NextRendering), &uses);
        }
        self.state
            .bound
            .as_mut()
            .expect("checked above")
            .uses
            .extend(pushed);
    }

    /// Panics unless `res` fits the binding `l` of pipeline `pipeline`.
    fn check_resource(&self, pipeline: &str, l: &BindingLayout, res: &Resource<'_>) {
        let binding = l.binding;
        let info = &self.shared.info;
        let ok = matches!(
            (l.kind, res),
            (
                BindingKind::StorageBuffer | BindingKind::UniformBuffer,
                Resource::Buffer(_) | Resource::BufferRange(..)
            ) | (BindingKind::AccelerationStructure, Resource::Tlas(_))
                | (BindingKind::StorageImage, Resource::StorageImage(_))
                | (BindingKind::SampledImage, Resource::Sampled(..))
        );
        assert!(
            ok,
            "pipeline {pipeline:?}: binding {binding} is {:?}, got {res:?}",
            l.kind
        );
        match *res {
            Resource::Buffer(b) | Resource::BufferRange(b, ..) => {
                let (offset, range) = match *res {
                    Resource::BufferRange(_, offset, size) => (offset, size),
                    _ => (0, vk::WHOLE_SIZE),
                };
                let (usage, alignment, max) = if l.kind == BindingKind::UniformBuffer {
                    (
                        vk::BufferUsageFlags::UNIFORM_BUFFER,
                        info.min_uniform_buffer_offset_alignment,
                        info.max_uniform_buffer_range,
                    )
                } else {
                    (
                        vk::BufferUsageFlags::STORAGE_BUFFER,
                        info.min_storage_buffer_offset_alignment,
                        info.max_storage_buffer_range,
                    )
                };
                assert!(
                    b.usage().contains(usage),
                    "pipeline {pipeline:?}: binding {binding} is {:?}, buffer {:?} has no {usage:?} \
                     usage",
                    l.kind,
                    b.name()
                );
                let effective = if range == vk::WHOLE_SIZE {
                    b.size().saturating_sub(offset)
                } else {
                    range
                };
                assert!(
                    offset < b.size()
                        && effective > 0
                        && offset.checked_add(effective).is_some_and(|e| e <= b.size())
                        && offset.is_multiple_of(alignment.max(1)),
                    "pipeline {pipeline:?}: binding {binding}: range {offset}+{effective} of buffer \
                     {:?} ({} bytes) is empty, out of bounds, or not aligned to {alignment}",
                    b.name(),
                    b.size()
                );
                assert!(
                    effective <= u64::from(max),
                    "pipeline {pipeline:?}: binding {binding}: {effective} bytes of buffer {:?} \
                     exceed the device's {max}-byte limit for a {:?} binding",
                    b.name(),
                    l.kind
                );
            }
            Resource::Tlas(t) => assert!(
                t.is_built(),
                "pipeline {pipeline:?}: binding {binding}: TLAS {:?} was never built",
                t.name()
            ),
            Resource::StorageImage(i) | Resource::Sampled(i, _) => {
                let usage = if l.kind == BindingKind::StorageImage {
                    vk::ImageUsageFlags::STORAGE
                } else {
                    vk::ImageUsageFlags::SAMPLED
                };
                assert!(
                    i.usage().contains(usage),
                    "pipeline {pipeline:?}: binding {binding}: image {:?} has no {usage:?} usage",
                    i.name()
                );
            }
        }
    }

    /// Sets the bound pipeline's push constants (`T` must be the size declared at creation).
    pub fn push_constants<T: Pod>(&mut self, data: &T) {
        let bound = self.bound_for("push_constants");
        let bytes = bytemuck::bytes_of(data);
        assert!(
            bound.push_constant_size > 0,
            "pipeline {:?} declares no push constants",
            bound.name
        );
        assert_eq!(
            bytes.len() as u32,
            bound.push_constant_size,
            "pipeline {:?}: push constants size",
            bound.name
        );
        // SAFETY: recording; the layout has one push-constant range of exactly these stages and
        // `bytes.len()` (> 0, a multiple of 4 as checked at pipeline creation) bytes at offset 0.
        unsafe {
            self.shared
                .device
                .cmd_push_constants(self.cmd, bound.layout, bound.stages, 0, bytes)
        };
        self.state
            .bound
            .as_mut()
            .expect("checked above")
            .constants_set = true;
    }
}

/// How a shader at `stage` uses the resource at a binding (`writes`: the binding is not
/// `readonly` in some shader of the pipeline); `None` for what is not tracked (a TLAS: its
/// builds order themselves against ray queries, `tlas.rs`).
fn shader_use<'a>(
    res: &Resource<'a>,
    kind: BindingKind,
    stage: vk::PipelineStageFlags2,
    writes: bool,
) -> Option<(&'a Target, Use)> {
    type A = vk::AccessFlags2;
    let storage = |writes: bool| {
        if writes {
            Use::write(Access::new(
                stage,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
            ))
        } else {
            Use::read(Access::new(stage, A::SHADER_STORAGE_READ))
        }
    };
    match *res {
        Resource::Buffer(b) | Resource::BufferRange(b, ..) => Some((
            b.target(),
            if kind == BindingKind::StorageBuffer {
                storage(writes)
            } else {
                Use::read(Access::new(stage, A::UNIFORM_READ))
            },
        )),
        Resource::StorageImage(i) => Some((
            i.target(),
            storage(writes).in_layout(descriptor_layout(res)),
        )),
        Resource::Sampled(i, _) => Some((
            i.target(),
            Use::read(Access::new(stage, A::SHADER_SAMPLED_READ)).in_layout(descriptor_layout(res)),
        )),
        Resource::Tlas(_) => None,
    }
}

/// The layout an image descriptor names (storage: GENERAL; sampled: the read-only layout).
fn descriptor_layout(res: &Resource<'_>) -> vk::ImageLayout {
    match res {
        Resource::Sampled(i, _) if i.is_depth() => vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
        Resource::Sampled(..) => vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        _ => vk::ImageLayout::GENERAL,
    }
}
