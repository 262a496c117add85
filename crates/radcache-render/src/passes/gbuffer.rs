//! The cache's G-buffer, ray traced or rasterized as the scene's plan says
//! ([`radcache_scene::ScenePlan::traced_gbuffer`]: many triangles; docs/cache-frame.md §2).
//!
//! Traced (`shaders/passes/gbuffer.comp`): one camera ray per pixel through its jittered sample,
//! its first hit written with the rules below. Rasterized (`shaders/passes/gbuffer.vert` +
//! `gbuffer.frag`): one draw per instance with vertex pulling, reversed-Z depth (cleared to 0,
//! GREATER), no culling (both sides are drawn; the emission rule decides what a back face
//! emits), and a sub-pixel jitter per sub-frame; then the repair (`gbuffer.comp` with
//! `GBUFFER_REPAIR`, two dispatches) traces the camera ray to each sample that lies behind a
//! surface edge (a neighbour nearer and off its plane) and writes a surface hit before it
//! instead (rasterization snapped a zero-thickness wall's edge away from the sample, so the
//! sample sees the floor behind the wall): the G-buffer never holds a point the camera cannot
//! see (the stiff suite's `two_rooms`).
//!
//! Either writes the five images of `shaders/common/gbuffer.glsl` (position, shading normal +
//! footprint, geometric normal + material, albedo, emission), zero on the background, and clears
//! the direct-light image. Both read the scene bindings 0–15. The traced pass and the repair
//! also read the G-buffer's activity mask (`gbuffer_pass::ACTIVE`): a pixel that per-pixel
//! adaptive anti-aliasing has stopped gets position w = −1 and nothing else
//! (docs/cache-frame.md §7.2).

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, ColorTarget, Context, DepthState, DepthTarget, GraphicsDesc, Pipeline, Recorder,
    RenderTargets, ShaderCompiler,
};

use crate::bindings::SCENE;
use crate::error::Result;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;
use radcache_scene::ScenePlan;

mod images;

pub use images::{GBuffer, DEPTH_FORMAT, GBUFFER_BINDINGS, GBUFFER_FORMAT};

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`GBufferPush` in GLSL).
    pub struct GBufferPush {
        /// Instance.
        pub instance: u32 => "uint",
        /// The stage of the rasterized G-buffer's repair (`gbuffer.comp` with `GBUFFER_REPAIR`):
        /// 0 marks the samples behind a surface edge, 1 traces them; 0 elsewhere.
        pub repair_stage: u32 => "uint",
        /// Jitter.
        pub jitter: [f32; 2] => "vec2",
    }
}

/// How the G-buffer is made: what the G-buffer pass is compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GBufferVariant {
    /// One camera ray per pixel (`gbuffer.comp`).
    Traced,
    /// The triangles rasterized (`gbuffer.vert` and `.frag`), then the samples behind a
    /// surface edge traced (`gbuffer.comp` with `GBUFFER_REPAIR`).
    Rasterized,
}

impl GBufferVariant {
    /// As `plan` chooses ([`ScenePlan::traced_gbuffer`]: traced from
    /// [`radcache_scene::plan::TRACED_GBUFFER_MIN_TRIANGLES`] instanced triangles).
    pub fn planned(plan: &ScenePlan) -> GBufferVariant {
        if plan.traced_gbuffer {
            GBufferVariant::Traced
        } else {
            GBufferVariant::Rasterized
        }
    }
}

/// The G-buffer pipeline: rasterization, or the ray-traced one (`gbuffer.comp`) where the plan
/// says so.
pub struct GBufferPass {
    pipeline: Pipeline,
    /// The rasterized G-buffer's repair (`gbuffer.comp` with `GBUFFER_REPAIR`); `None` where
    /// the G-buffer is traced.
    repair: Option<Pipeline>,
}

impl std::fmt::Debug for GBufferPass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GBufferPass")
            .field("traced", &self.traced())
            .finish_non_exhaustive()
    }
}

impl GBufferPass {
    /// The shader modules the pass compiles for a scene with `features` and `variant`: the
    /// traced G-buffer's compute shader; or the repair's compute shader and the rasterizer's
    /// vertex and fragment shaders.
    pub(crate) fn modules(features: &SceneFeatures, variant: GBufferVariant) -> Vec<ShaderModule> {
        let defines = features.material_defines();
        if variant == GBufferVariant::Traced {
            return vec![ShaderModule::new("passes/gbuffer.comp", defines)];
        }
        let mut repair = defines.clone();
        repair.push(("GBUFFER_REPAIR", "1"));
        vec![
            ShaderModule::new("passes/gbuffer.comp", repair),
            ShaderModule::new("passes/gbuffer.vert", defines.clone()),
            ShaderModule::new("passes/gbuffer.frag", defines),
        ]
    }

    /// Compiles the pass as `variant` ([`GBufferVariant::planned`] for the scene's plan) for
    /// `scene`'s materials (metallic and roughness are stored only where some material is not
    /// Lambertian; the rasterization carries tangents only where some primitive has a normal
    /// map).
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        variant: GBufferVariant,
    ) -> Result<GBufferPass> {
        let modules = Self::modules(&scene.features(), variant);
        let compute = |name: &str, module: &ShaderModule| -> Result<Pipeline> {
            let spirv = module.compile(shaders)?;
            Ok(Pipeline::compute(
                ctx,
                name,
                &spirv,
                &crate::bindings::gbuffer_pass::layout(),
                std::mem::size_of::<GBufferPush>() as u32,
            )?)
        };
        if variant == GBufferVariant::Traced {
            return Ok(GBufferPass {
                pipeline: compute("gbuffer", &modules[0])?,
                repair: None,
            });
        }
        let repair = compute("gbuffer.repair", &modules[0])?;
        let vertex = modules[1].compile(shaders)?;
        let fragment = modules[2].compile(shaders)?;
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "gbuffer",
                vertex: &vertex,
                fragment: &fragment,
                bindings: &SCENE,
                push_constant_size: std::mem::size_of::<GBufferPush>() as u32,
                color_formats: &[GBUFFER_FORMAT; 5],
                depth: Some(DepthState {
                    format: DEPTH_FORMAT,
                    compare: vk::CompareOp::GREATER,
                    write: true,
                }),
                blend: radcache_vk::Blend::None,
                cull: vk::CullModeFlags::NONE,
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            },
        )?;
        Ok(GBufferPass {
            pipeline,
            repair: Some(repair),
        })
    }

    /// The pass traces its G-buffer (the plan's `traced_gbuffer`).
    pub fn traced(&self) -> bool {
        self.repair.is_none()
    }

    /// Records the G-buffer of `scene`'s current view, clearing everything first, in the profiler
    /// scope `gbuffer`. `jitter` is where each pixel's sample lies relative to its centre (pixels,
    /// each in [−0.5, 0.5]): pixel p holds the first hit of the camera ray through
    /// p + 0.5 + `jitter` (`camera_ray(p, 0.5 + jitter)` in `shaders/common/path.glsl`), the
    /// direct-light image zeroed.
    pub fn record(
        &self,
        rec: &mut Recorder,
        scene: &GpuScene,
        gbuffer: &GBuffer,
        jitter: [f32; 2],
    ) -> Result<()> {
        if self.traced() {
            let mut bindings = scene.bindings();
            bindings.extend(gbuffer.bindings());
            bindings.push(gbuffer.active_binding());
            let (w, h) = (gbuffer.width, gbuffer.height);
            rec.pass("gbuffer", |rec| {
                rec.bind_pipeline(&self.pipeline);
                rec.push_bindings(&bindings);
                rec.push_constants(&GBufferPush {
                    instance: 0,
                    repair_stage: 0,
                    jitter,
                });
                let [x, y, z] = image_dispatch(w, h);
                rec.dispatch(x, y, z)
            })?;
            return Ok(());
        }
        let targets: Vec<ColorTarget<'_>> = gbuffer
            .attachments()
            .into_iter()
            .map(|image| ColorTarget {
                image,
                clear: Some([0.0; 4]),
            })
            .collect();
        let bindings = scene.bindings();
        let draws = scene.instance_draws();
        rec.pass("gbuffer", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.begin_rendering(&RenderTargets {
                colors: &targets,
                depth: Some(DepthTarget {
                    image: &gbuffer.depth,
                    clear: Some(0.0),
                }),
                indirect: &[],
            });
            for &(instance, triangles) in &draws {
                rec.push_constants(&GBufferPush {
                    instance,
                    repair_stage: 0,
                    jitter,
                });
                rec.draw(3 * triangles, 1);
            }
            rec.end_rendering();
        });
        rec.clear_color(&gbuffer.direct, [0.0; 4]);
        if let Some(repair) = &self.repair {
            let mut bindings = scene.bindings();
            bindings.extend(gbuffer.bindings());
            bindings.push(gbuffer.active_binding());
            let [x, y, z] = image_dispatch(gbuffer.width, gbuffer.height);
            rec.pass("gbuffer.repair", |rec| {
                rec.bind_pipeline(repair);
                rec.push_bindings(&bindings);
                for repair_stage in [0, 1] {
                    rec.push_constants(&GBufferPush {
                        instance: 0,
                        repair_stage,
                        jitter,
                    });
                    rec.dispatch(x, y, z)?;
                }
                Ok::<(), radcache_vk::Error>(())
            })?;
        }
        Ok(())
    }
}
