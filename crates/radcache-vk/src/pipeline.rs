//! Compute and graphics pipelines (dynamic rendering) with one push-descriptor set each.
//!
//! Each pipeline declares its bindings as a table of `(binding, kind, count)`; resources are pushed
//! at record time (`Recorder::push_bindings`), so there are no descriptor pools to manage. Push
//! constants are one `Pod` struct per pass.

use std::sync::Arc;

use ash::vk;

use crate::context::{Context, DeviceShared, Garbage};
use crate::error::{Error, Result, VkResultExt};
use crate::pcache::PipelineKey;
use crate::reflect;

/// The kind of resource at a binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BindingKind {
    /// `buffer` block (std430 / scalar).
    StorageBuffer,
    /// `uniform` block.
    UniformBuffer,
    /// `accelerationStructureEXT`.
    AccelerationStructure,
    /// `image2D` (storage image).
    StorageImage,
    /// `sampler2D` (combined image sampler).
    SampledImage,
}

impl BindingKind {
    pub(crate) fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::AccelerationStructure => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            BindingKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }
}

/// One entry of a pipeline's binding table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BindingLayout {
    /// `layout(binding = N)`.
    pub binding: u32,
    /// What is bound.
    pub kind: BindingKind,
    /// Array length (1 for a single resource).
    pub count: u32,
}

impl BindingLayout {
    /// A single resource at `binding`.
    pub const fn new(binding: u32, kind: BindingKind) -> Self {
        BindingLayout {
            binding,
            kind,
            count: 1,
        }
    }
}

/// Colour blending of a graphics pipeline's attachments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blend {
    /// Replace.
    None,
    /// `dst = src + dst` on every channel (ONE, ONE, ADD).
    Additive,
}

/// Depth state of a graphics pipeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepthState {
    /// Depth attachment format.
    pub format: vk::Format,
    /// Compare op (test enabled unless `ALWAYS` with no write).
    pub compare: vk::CompareOp,
    /// Whether fragments write depth.
    pub write: bool,
}

/// What a graphics pipeline is made of.
#[derive(Debug, Clone)]
pub struct GraphicsDesc<'a> {
    /// Name (debug label, profiler scope).
    pub name: &'a str,
    /// Vertex shader SPIR-V.
    pub vertex: &'a [u32],
    /// Fragment shader SPIR-V.
    pub fragment: &'a [u32],
    /// Binding table.
    pub bindings: &'a [BindingLayout],
    /// Push-constant bytes (0 for none).
    pub push_constant_size: u32,
    /// Colour attachment formats.
    pub color_formats: &'a [vk::Format],
    /// Depth attachment, if any.
    pub depth: Option<DepthState>,
    /// Blending of every colour attachment.
    pub blend: Blend,
    /// Face culling.
    pub cull: vk::CullModeFlags,
    /// Primitive topology.
    pub topology: vk::PrimitiveTopology,
}

/// A pipeline, its layout and its push-descriptor set layout.
pub struct Pipeline {
    shared: Arc<DeviceShared>,
    pub(crate) raw: vk::Pipeline,
    pub(crate) layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pub(crate) bind_point: vk::PipelineBindPoint,
    pub(crate) bindings: Vec<BindingLayout>,
    pub(crate) push_constant_size: u32,
    pub(crate) stages: vk::ShaderStageFlags,
    /// Attachment formats of a graphics pipeline (none and `UNDEFINED` for compute).
    pub(crate) color_formats: Vec<vk::Format>,
    pub(crate) depth_format: vk::Format,
    /// Bindings some shader may write (not `readonly`); the rest are only read. The barriers
    /// before a dispatch or draw are derived from this (`hazard.rs`).
    pub(crate) written: Vec<u32>,
    name: String,
}

impl std::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline")
            .field("name", &self.name)
            .finish()
    }
}

struct Layouts {
    set: vk::DescriptorSetLayout,
    pipeline: vk::PipelineLayout,
}

fn create_layouts(
    shared: &DeviceShared,
    bindings: &[BindingLayout],
    push_constant_size: u32,
    stages: vk::ShaderStageFlags,
) -> Result<Layouts> {
    if push_constant_size > shared.info.max_push_constants_size
        || !push_constant_size.is_multiple_of(4)
    {
        return Err(Error::Invalid(format!(
            "push constants of {push_constant_size} bytes (limit {}, multiple of 4)",
            shared.info.max_push_constants_size
        )));
    }
    let vk_bindings: Vec<_> = bindings
        .iter()
        .map(|b| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(b.binding)
                .descriptor_type(b.kind.descriptor_type())
                .descriptor_count(b.count)
                .stage_flags(stages)
        })
        .collect();
    let info = vk::DescriptorSetLayoutCreateInfo::default()
        .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
        .bindings(&vk_bindings);
    // SAFETY: the device is live; `info` is valid for the call.
    let set = unsafe { shared.device.create_descriptor_set_layout(&info, None) }
        .call("vkCreateDescriptorSetLayout")?;
    let ranges = [vk::PushConstantRange {
        stage_flags: stages,
        offset: 0,
        size: push_constant_size,
    }];
    let sets = [set];
    let mut info = vk::PipelineLayoutCreateInfo::default().set_layouts(&sets);
    if push_constant_size > 0 {
        info = info.push_constant_ranges(&ranges);
    }
    // SAFETY: as above.
    match unsafe { shared.device.create_pipeline_layout(&info, None) } {
        Ok(pipeline) => Ok(Layouts { set, pipeline }),
        Err(e) => {
            // SAFETY: `set` is unused.
            unsafe { shared.device.destroy_descriptor_set_layout(set, None) };
            Err(Error::Vk {
                call: "vkCreatePipelineLayout",
                result: e,
            })
        }
    }
}

/// The first word of every SPIR-V module.
pub(crate) const SPIRV_MAGIC: u32 = 0x0723_0203;

/// A shader module. The SPIR-V must be a valid module: its header and the resources it uses
/// (`reflect::check_layout`) are checked, the rest is trusted to come from
/// [`crate::ShaderCompiler`] (shaderc emits valid modules).
fn shader_module(shared: &DeviceShared, spirv: &[u32]) -> Result<vk::ShaderModule> {
    if spirv.len() < 5 || spirv[0] != SPIRV_MAGIC {
        return Err(Error::Invalid(format!(
            "not a SPIR-V module ({} words, first {:#010x})",
            spirv.len(),
            spirv.first().copied().unwrap_or(0)
        )));
    }
    let info = vk::ShaderModuleCreateInfo::default().code(spirv);
    // SAFETY: the device is live; `spirv` has a SPIR-V header (checked above). Its body is not
    // validated here: radcache's modules come from `ShaderCompiler` (shaderc), and the pipeline
    // constructors document that the words must be a valid module (a residual contract).
    unsafe { shared.device.create_shader_module(&info, None) }.call("vkCreateShaderModule")
}

impl Pipeline {
    /// A compute pipeline from SPIR-V with entry point `main`. The words must be a valid SPIR-V
    /// module (as [`crate::ShaderCompiler::compile`] returns); the header, and the binding table
    /// and push constants against the resources the shader uses, are checked (an error names
    /// the pipeline and the binding).
    pub fn compute(
        ctx: &Context,
        name: &str,
        spirv: &[u32],
        bindings: &[BindingLayout],
        push_constant_size: u32,
    ) -> Result<Self> {
        let shared = &ctx.shared;
        let stages = vk::ShaderStageFlags::COMPUTE;
        let layouts = create_layouts(shared, bindings, push_constant_size, stages)?;
        let mut pipeline = Pipeline {
            shared: shared.clone(),
            raw: vk::Pipeline::null(),
            layout: layouts.pipeline,
            set_layout: layouts.set,
            bind_point: vk::PipelineBindPoint::COMPUTE,
            bindings: bindings.to_vec(),
            push_constant_size,
            stages,
            color_formats: Vec::new(),
            depth_format: vk::Format::UNDEFINED,
            written: Vec::new(),
            name: name.to_string(),
        };
        pipeline.written = reflect::check_layout(name, &[spirv], bindings, push_constant_size)?;
        let module = shader_module(shared, spirv)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main");
        let mut feedback = vk::PipelineCreationFeedback::default();
        let mut stage_feedback = [vk::PipelineCreationFeedback::default()];
        let mut feedback_info = vk::PipelineCreationFeedbackCreateInfo::default()
            .pipeline_creation_feedback(&mut feedback)
            .pipeline_stage_creation_feedbacks(&mut stage_feedback);
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layouts.pipeline)
            .push_next(&mut feedback_info)];
        let cache = &shared.pipeline_cache;
        let driver_bytes = cache.driver_bytes(&shared.device);
        let started = std::time::Instant::now();
        // SAFETY: module, layout and cache are live; the layout declares every resource and the
        // push constants the shader uses (`reflect::check_layout` above); `info` and the feedback
        // structs it points to (one per stage, as the count says) outlive the call.
        let created = unsafe {
            shared
                .device
                .create_compute_pipelines(cache.raw(), &info, None)
        };
        if created.is_ok() {
            let key = PipelineKey::compute(spirv, bindings, push_constant_size);
            cache.record(key, &feedback, started, driver_bytes);
        }
        // SAFETY: the module is no longer needed once the pipeline call returned.
        unsafe { shared.device.destroy_shader_module(module, None) };
        pipeline.raw = created.map_err(|(_, e)| Error::Vk {
            call: "vkCreateComputePipelines",
            result: e,
        })?[0];
        shared.set_name(pipeline.raw, name);
        Ok(pipeline)
    }

    /// A graphics pipeline for dynamic rendering (viewport and scissor are dynamic). The shaders
    /// must be valid SPIR-V modules (as [`crate::ShaderCompiler::compile`] returns); headers,
    /// binding table and push constants are checked as for [`Self::compute`].
    pub fn graphics(ctx: &Context, desc: &GraphicsDesc<'_>) -> Result<Self> {
        let shared = &ctx.shared;
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let layouts = create_layouts(shared, desc.bindings, desc.push_constant_size, stages)?;
        let mut pipeline = Pipeline {
            shared: shared.clone(),
            raw: vk::Pipeline::null(),
            layout: layouts.pipeline,
            set_layout: layouts.set,
            bind_point: vk::PipelineBindPoint::GRAPHICS,
            bindings: desc.bindings.to_vec(),
            push_constant_size: desc.push_constant_size,
            stages,
            color_formats: desc.color_formats.to_vec(),
            depth_format: desc.depth.map_or(vk::Format::UNDEFINED, |d| d.format),
            written: Vec::new(),
            name: desc.name.to_string(),
        };
        pipeline.written = reflect::check_layout(
            desc.name,
            &[desc.vertex, desc.fragment],
            desc.bindings,
            desc.push_constant_size,
        )?;
        let vs = shader_module(shared, desc.vertex)?;
        let fs = match shader_module(shared, desc.fragment) {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: `vs` is unused.
                unsafe { shared.device.destroy_shader_module(vs, None) };
                return Err(e);
            }
        };
        let stage_infos = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vs)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs)
                .name(c"main"),
        ];
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let input_assembly =
            vk::PipelineInputAssemblyStateCreateInfo::default().topology(desc.topology);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(desc.cull)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = desc
            .depth
            .map_or_else(vk::PipelineDepthStencilStateCreateInfo::default, |d| {
                vk::PipelineDepthStencilStateCreateInfo::default()
                    .depth_test_enable(true)
                    .depth_write_enable(d.write)
                    .depth_compare_op(d.compare)
            });
        let attachment = match desc.blend {
            Blend::None => vk::PipelineColorBlendAttachmentState::default()
                .color_write_mask(vk::ColorComponentFlags::RGBA),
            Blend::Additive => vk::PipelineColorBlendAttachmentState::default()
                .blend_enable(true)
                .src_color_blend_factor(vk::BlendFactor::ONE)
                .dst_color_blend_factor(vk::BlendFactor::ONE)
                .color_blend_op(vk::BlendOp::ADD)
                .src_alpha_blend_factor(vk::BlendFactor::ONE)
                .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                .alpha_blend_op(vk::BlendOp::ADD)
                .color_write_mask(vk::ColorComponentFlags::RGBA),
        };
        let attachments = vec![attachment; desc.color_formats.len()];
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut feedback = vk::PipelineCreationFeedback::default();
        let mut stage_feedback = [vk::PipelineCreationFeedback::default(); 2];
        let mut feedback_info = vk::PipelineCreationFeedbackCreateInfo::default()
            .pipeline_creation_feedback(&mut feedback)
            .pipeline_stage_creation_feedbacks(&mut stage_feedback);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth.map_or(vk::Format::UNDEFINED, |d| d.format));
        let info = [vk::GraphicsPipelineCreateInfo::default()
            .stages(&stage_infos)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layouts.pipeline)
            .push_next(&mut rendering)
            .push_next(&mut feedback_info)];
        let cache = &shared.pipeline_cache;
        let driver_bytes = cache.driver_bytes(&shared.device);
        let started = std::time::Instant::now();
        // SAFETY: every state struct, and the feedback structs (one per stage, as the count says),
        // lives until the call returns; modules, layout and cache are live; the layout declares
        // every resource and the push constants the shaders use (`reflect::check_layout` above).
        let created = unsafe {
            shared
                .device
                .create_graphics_pipelines(cache.raw(), &info, None)
        };
        if created.is_ok() {
            let key = PipelineKey::graphics(desc);
            cache.record(key, &feedback, started, driver_bytes);
        }
        // SAFETY: the modules are no longer needed once the pipeline call returned.
        unsafe {
            shared.device.destroy_shader_module(vs, None);
            shared.device.destroy_shader_module(fs, None);
        }
        pipeline.raw = created.map_err(|(_, e)| Error::Vk {
            call: "vkCreateGraphicsPipelines",
            result: e,
        })?[0];
        shared.set_name(pipeline.raw, desc.name);
        Ok(pipeline)
    }

    /// The pipeline's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        self.shared
            .retire(Garbage::Pipeline(self.raw, self.layout, self.set_layout));
    }
}
