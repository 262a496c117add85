//! Glossy splatting (`shaders/passes/splat.vert` + `splat_glossy.frag`, docs/radiance-caching.md
//! §6.2): the radiance records for glossy lobes. The records' SH coefficients and their
//! translational gradients live with the records (`IcState::radiance`, so compaction, temporal
//! reuse and cache files keep them beside their records); this pass owns the rest:
//! * each pixel's glossy world weights (the direct pass writes them per sub-frame);
//! * the lobe table;
//! * the glossy target.
//!
//! Per record and pixel the fragment adds `(w·Σ_i c_i ⊙ W_i, w)` to the RGBA32F target with
//! (ONE, ONE) blending, `w` being the splat's own weight; the composite adds the target's
//! `rgb/a`. The convolution is linear, so weighting each record by the pixel's world weights
//! equals convolving the blended coefficients. It costs one target of 16 bytes per pixel
//! (plus 192 bytes of weights), not the 12 targets of 196 bytes that splatting the coefficients
//! themselves would need.

use radcache_material::glossy::{glossy_table, GLOSSY_TABLE_STRATA};
use radcache_shared::consts::RADIANCE_VEC4S;
use radcache_vk::{
    vk, Blend, Buffer, BufferDesc, ColorTarget, Context, GraphicsDesc, Image, ImageDesc,
    MemoryLocation, Pipeline, Recorder, RenderTargets, Resource, ShaderCompiler,
};

use crate::bindings::{splat_glossy as b, FRAME};
use crate::error::{Error, Result};
use crate::passes::gbuffer::GBuffer;
use crate::passes::splat::SplatWeights;
use crate::scene::features::ShaderModule;
use crate::scene::GpuScene;
use crate::state::IcState;

/// Bytes of glossy world weights per pixel (`RADIANCE_VEC4S` vec4).
pub const WEIGHT_BYTES_PER_PIXEL: u64 = RADIANCE_VEC4S as u64 * 16;

/// The glossy splat's pipeline, target and buffers.
pub struct GlossySplatPass {
    pipeline: Pipeline,
    /// Σ w·L_glossy (rgb) and Σ w (a) per pixel.
    pub sum: Image,
    /// Each pixel's glossy world weights (`RADIANCE_VEC4S` vec4 per pixel).
    pub weights: Buffer,
    /// The lobe table ([`glossy_table`]).
    pub table: Buffer,
}

impl std::fmt::Debug for GlossySplatPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GlossySplatPass").finish_non_exhaustive()
    }
}

impl GlossySplatPass {
    /// The shader modules the pass compiles, `gradients` as in [`GlossySplatPass::new`]: the
    /// splat's vertex shader and the glossy fragment shader.
    pub(crate) fn modules(gradients: bool) -> Vec<ShaderModule> {
        let defines = if gradients {
            vec![("GLOSSY_GRADIENTS", "1")]
        } else {
            Vec::new()
        };
        vec![
            ShaderModule::plain("passes/splat.vert"),
            ShaderModule::new("passes/splat_glossy.frag", defines),
        ]
    }

    /// Compiles the pass and allocates the target and the weights for `width × height` pixels,
    /// and the table; `gradients` extrapolates
    /// the coefficients by their translational gradients (docs/radiance-caching.md §7).
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        width: u32,
        height: u32,
        gradients: bool,
    ) -> Result<Self> {
        let [vertex, fragment] = <[ShaderModule; 2]>::try_from(Self::modules(gradients))
            .expect("two glossy splat modules");
        let vertex = vertex.compile(shaders)?;
        let fragment = fragment.compile(shaders)?;
        let format = vk::Format::R32G32B32A32_SFLOAT;
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "splat.glossy",
                vertex: &vertex,
                fragment: &fragment,
                bindings: &b::layout(),
                push_constant_size: std::mem::size_of::<SplatWeights>() as u32,
                color_formats: &[format],
                depth: None,
                blend: Blend::Additive,
                cull: vk::CullModeFlags::NONE,
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            },
        )?;
        let sum = Image::new(
            ctx,
            &ImageDesc {
                name: "splat.glossy.sum",
                width,
                height,
                format,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::STORAGE,
            },
        )?;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let buffer = |name, size: u64| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size: size.max(16),
                    usage: storage,
                    location: MemoryLocation::GpuOnly,
                    alignment: 0,
                },
            )
        };
        let pixels = u64::from(width) * u64::from(height);
        let table: Vec<f32> = glossy_table(GLOSSY_TABLE_STRATA);
        Ok(GlossySplatPass {
            pipeline,
            sum,
            weights: buffer("splat.glossy.weights", pixels * WEIGHT_BYTES_PER_PIXEL)?,
            table: ctx.create_buffer_init("splat.glossy.table", storage, &table)?,
        })
    }

    /// Records the glossy splat of every record with `weights` (the final splat's, without
    /// marking), after the direct pass wrote the pixels' world weights; `state` must hold
    /// radiance blocks ([`crate::state::IcStateDesc::radiance`]).
    pub fn record(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        state: &IcState,
        weights: &SplatWeights,
    ) -> Result<()> {
        let radiance = state.radiance.as_ref().ok_or_else(|| {
            Error::Invalid("the glossy splat needs a cache with radiance blocks".into())
        })?;
        let push = SplatWeights {
            mark_frame: 0,
            ..*weights
        };
        let mut bindings = vec![scene.bindings()[FRAME as usize]];
        bindings.extend(gbuffer.bindings());
        bindings.extend([
            (b::RECORDS, Resource::Buffer(&state.records)),
            (b::LAST_USED, Resource::Buffer(&state.last_used)),
            (b::RADIANCE, Resource::Buffer(radiance)),
            (b::GLOSSY_WEIGHTS, Resource::Buffer(&self.weights)),
        ]);
        rec.pass("splat.glossy", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.begin_rendering(&RenderTargets {
                colors: &[ColorTarget {
                    image: &self.sum,
                    clear: Some([0.0; 4]),
                }],
                depth: None,
                indirect: &[&state.counters],
            });
            // The draw of every record (IcCounters::draw, as SplatScope::All).
            rec.draw_indirect(&state.counters, 32, 1);
            rec.end_rendering();
        });
        Ok(())
    }
}
