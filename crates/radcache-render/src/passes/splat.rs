//! Irradiance splatting (`shaders/passes/splat.vert` + `splat.frag`): one instanced quad per
//! record, drawn indirectly (the instance count is the GPU's record count), adding (w·Ẽ, w) into
//! an RGBA32F target with (ONE, ONE) blending. No depth test: the G-buffer already resolved
//! visibility, and the fragment rejects points outside the record's zone.

use radcache_cache::IcParams;
use radcache_vk::{
    vk, Blend, ColorTarget, Context, GraphicsDesc, Image, ImageDesc, Pipeline, Recorder,
    RenderTargets, Resource, ShaderCompiler,
};

use crate::bindings::{splat as b, FRAME};
use crate::error::Result;
use crate::passes::gbuffer::GBuffer;
use crate::scene::features::ShaderModule;
use crate::scene::GpuScene;
use crate::state::IcState;

/// Which records a splat draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatScope {
    /// Clear the target, then splat every record.
    All,
    /// Add the last batch's records to the target as it is (`IcCounters::batch_draw`): the
    /// coverage of a creation level grows by what the previous level created.
    LastBatch,
}

/// Format of the record-count target.
const COUNT_FORMAT: vk::Format = vk::Format::R32_SFLOAT;

radcache_shared::gpu_struct! {
    /// Weighting of one splat pass (its push constants, `SplatWeights` in GLSL): the kind, its
    /// parameter, and the in-front tolerance.
    pub struct SplatWeights {
        /// `WEIGHT_WARD` or `WEIGHT_TL`.
        pub kind: u32 => "uint",
        /// `a` (Ward) or `κ` (T&L).
        pub param: f32 => "float",
        /// Weights at or below this are rejected (0: the whole zone).
        pub w_min: f32 => "float",
        /// In-front tolerance in pixel footprints.
        pub front_tol_px: f32 => "float",
        /// Frame number written to the last-use slot of every record that weighs on a pixel (0:
        /// none; the final splat marks, the coverage splats do not).
        pub mark_frame: u32 => "uint",
        /// Padding.
        pub pad0: u32 => "uint",
        /// Padding.
        pub pad1: u32 => "uint",
        /// Padding.
        pub pad2: u32 => "uint",
    }
}

impl SplatWeights {
    /// The weighting `params` describe.
    pub fn from_params(params: &IcParams) -> SplatWeights {
        SplatWeights {
            kind: params.weight_kind as u32,
            param: params.weight_param(),
            // Every weight above zero counts, for both kinds: the whole zone is drawn (a positive
            // floor would cut the zone where its weights are small but still normalise).
            w_min: 0.0,
            front_tol_px: params.front_tolerance_px,
            mark_frame: 0,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        }
    }
}

/// What a splat draws (a pipeline each).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplatOutput {
    /// Σ w·Ẽ and Σ w into [`SplatPass::sum`].
    Irradiance,
    /// The same and the number of records per pixel into [`SplatPass::count`] (the debug AOV).
    IrradianceAndCount,
    /// Σ w alone (`SPLAT_COVERAGE`, the colour zero): what hole selection reads.
    Coverage,
}

/// The splat pipelines and their accumulation target.
pub struct SplatPass {
    /// [`SplatOutput::Irradiance`].
    irradiance: Pipeline,
    /// [`SplatOutput::IrradianceAndCount`].
    counted: Pipeline,
    /// [`SplatOutput::Coverage`].
    coverage: Pipeline,
    /// Σ w·Ẽ (rgb) and Σ w (a) per pixel.
    pub sum: Image,
    /// Number of records that reach each pixel (R32F).
    pub count: Image,
}

impl std::fmt::Debug for SplatPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SplatPass").finish_non_exhaustive()
    }
}

/// What a splat reads: the scene's frame constants, the G-buffer's samples, and the records with
/// their counters (the draw's indirect arguments) and last-use marks.
#[derive(Debug, Clone, Copy)]
pub struct SplatInputs<'a> {
    /// The scene.
    pub scene: &'a GpuScene,
    /// The samples the records are splatted at.
    pub gbuffer: &'a GBuffer,
    /// The records.
    pub state: &'a IcState,
}

/// One splat draw: its profiler scope, the records it covers, what it draws and its weights.
#[derive(Debug, Clone, Copy)]
pub struct SplatDraw<'a> {
    /// The profiler scope (e.g. `splat`).
    pub name: &'a str,
    /// The records splatted.
    pub scope: SplatScope,
    /// The targets drawn.
    pub output: SplatOutput,
    /// The weights (creation or final).
    pub weights: &'a SplatWeights,
}

impl<'a> SplatDraw<'a> {
    /// Every record with `weights`, counting the records per pixel too, in the scope `splat`.
    pub fn all(weights: &'a SplatWeights) -> SplatDraw<'a> {
        SplatDraw {
            name: "splat",
            scope: SplatScope::All,
            output: SplatOutput::IrradianceAndCount,
            weights,
        }
    }
}

impl SplatPass {
    /// The shader modules the pass compiles: the vertex shader, and the fragment shader for
    /// irradiance, irradiance and count, and coverage.
    pub(crate) fn modules() -> Vec<ShaderModule> {
        vec![
            ShaderModule::plain("passes/splat.vert"),
            ShaderModule::plain("passes/splat.frag"),
            ShaderModule::new("passes/splat.frag", vec![("SPLAT_COUNT", "1")]),
            ShaderModule::new("passes/splat.frag", vec![("SPLAT_COVERAGE", "1")]),
        ]
    }

    /// Compiles the pass and allocates the `width × height` accumulation target.
    pub fn new(ctx: &Context, shaders: &ShaderCompiler, width: u32, height: u32) -> Result<Self> {
        let [vertex, irradiance, counted, coverage] =
            <[ShaderModule; 4]>::try_from(Self::modules()).expect("four splat modules");
        let vertex = vertex.compile(shaders)?;
        let bindings = b::layout();
        let format = vk::Format::R32G32B32A32_SFLOAT;
        let pipeline_for = |name: &str, module: &ShaderModule| -> Result<Pipeline> {
            let fragment = module.compile(shaders)?;
            let counted = module.defines.iter().any(|(d, _)| *d == "SPLAT_COUNT");
            let formats = [format, COUNT_FORMAT];
            Ok(Pipeline::graphics(
                ctx,
                &GraphicsDesc {
                    name,
                    vertex: &vertex,
                    fragment: &fragment,
                    bindings: &bindings,
                    push_constant_size: std::mem::size_of::<SplatWeights>() as u32,
                    color_formats: &formats[..if counted { 2 } else { 1 }],
                    depth: None,
                    blend: Blend::Additive,
                    cull: vk::CullModeFlags::NONE,
                    topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                },
            )?)
        };
        let irradiance = pipeline_for("splat", &irradiance)?;
        let counted = pipeline_for("splat.counted", &counted)?;
        let coverage = pipeline_for("splat.coverage", &coverage)?;
        let sum = Image::new(
            ctx,
            &ImageDesc {
                name: "splat.sum",
                width,
                height,
                format,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::STORAGE,
            },
        )?;
        let count = Image::new(
            ctx,
            &ImageDesc {
                name: "splat.count",
                width,
                height,
                format: COUNT_FORMAT,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::STORAGE,
            },
        )?;
        Ok(SplatPass {
            irradiance,
            counted,
            coverage,
            sum,
            count,
        })
    }

    /// Records splatting the records of `draw.scope` with `draw.weights` into the pass's
    /// targets, in a profiler scope named `draw.name`, drawing `draw.output`; the count target is
    /// left as it is unless the output draws it. [`SplatOutput::Coverage`] gives the same Σ w in
    /// the target's alpha as the others, with zero in its colour (hole selection reads Σ w
    /// alone), so its fragments skip the irradiance's extrapolation.
    pub fn record(
        &self,
        rec: &mut Recorder,
        inputs: &SplatInputs<'_>,
        draw: &SplatDraw<'_>,
    ) -> Result<()> {
        let SplatInputs {
            scene,
            gbuffer,
            state,
        } = *inputs;
        let SplatDraw {
            name,
            scope,
            output,
            weights,
        } = *draw;
        let pipeline = match output {
            SplatOutput::Irradiance => &self.irradiance,
            SplatOutput::IrradianceAndCount => &self.counted,
            SplatOutput::Coverage => &self.coverage,
        };
        let counted = output == SplatOutput::IrradianceAndCount;
        let (clear, offset) = match scope {
            SplatScope::All => (Some([0.0; 4]), 32),
            SplatScope::LastBatch => (None, 64),
        };
        let scene_bindings = scene.bindings();
        let mut bindings = vec![scene_bindings[FRAME as usize]];
        bindings.extend(gbuffer.bindings());
        bindings.push((b::RECORDS, Resource::Buffer(&state.records)));
        bindings.push((b::LAST_USED, Resource::Buffer(&state.last_used)));
        rec.pass(name, |rec| {
            let colors = [
                ColorTarget {
                    image: &self.sum,
                    clear,
                },
                ColorTarget {
                    image: &self.count,
                    clear,
                },
            ];
            rec.bind_pipeline(pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(weights);
            rec.begin_rendering(&RenderTargets {
                colors: &colors[..if counted { 2 } else { 1 }],
                depth: None,
                indirect: &[&state.counters],
            });
            rec.draw_indirect(&state.counters, offset, 1);
            rec.end_rendering();
        });
        Ok(())
    }
}
