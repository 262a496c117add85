//! The irradiance cache's frame: [`IcRenderer`] owns the passes, the G-buffer and the cache
//! state, so a sequence creates its pipelines once and can keep its records from frame to frame.
//! [`IcRenderer::render`] is the list of the frame's phases (their bodies in `ic/phases.rs`, the
//! temporal steps in `ic/temporal.rs`, cache files in `ic/cache.rs`); the flow is described in
//! [`crate::frame`].

use std::time::Instant;

use radcache_cache::IcParams;
use radcache_scene::Scene;
use radcache_shared::gpu::GpuRecord;
use radcache_vk::{Context, ShaderCompiler};

use crate::error::{Error, Result};
use crate::frame::path::{FrameOutput, Progress};
use crate::frame::settings::{
    EmitterShadows, GlossyLight, IcDebug, IcSettings, IcStats, SplatMode,
};
use crate::passes::composite::{CompositePass, CompositeVariant, WithCentres};
use crate::passes::direct::{DirectCompositing, DirectPass, DirectShadows, DirectVariant};
use crate::passes::emission::EmissionPass;
use crate::passes::gbuffer::{GBuffer, GBufferPass, GBufferVariant};
use crate::passes::holes::HolePass;
use crate::passes::neighbours::NeighbourPass;
use crate::passes::record::{
    PathGrid, RecordInputs, RecordOutputs, RecordPass, RecordVariant, WithRadiance,
};
use crate::passes::splat::SplatPass;
use crate::passes::splat_glossy::GlossySplatPass;
use crate::passes::temporal::{NoLifespans, TemporalPass, TemporalVariant, WithLifespans};
use crate::scene::GpuScene;
use crate::state::{IcState, IcStateDesc};

mod anti_alias;
mod cache;
mod phases;
mod temporal;

use phases::FrameRun;

/// The passes that shade a sub-frame, as the splat mode makes them: splatting once
/// ([`SplatMode::Once`]), the composite keeps the centre samples and the direct pass composites
/// the later sub-frames against them (docs/cache-frame.md §6.5).
enum Shading {
    /// [`SplatMode::PerSubFrame`].
    PerSubFrame {
        direct: DirectPass,
        composite: CompositePass,
    },
    /// [`SplatMode::Once`].
    Once {
        direct: DirectPass<DirectCompositing>,
        composite: CompositePass<WithCentres>,
    },
}

/// The record pass, as the frame's radiance records make it.
enum Records {
    /// Irradiance records alone.
    Irradiance(RecordPass),
    /// Records with radiance blocks ([`crate::scene::ScenePlan::radiance_cache`]).
    Radiance(RecordPass<WithRadiance>),
}

impl Records {
    /// Records `inputs`' job into `records`, with `radiance` the buffer of the blocks for a
    /// pass made with them (and only then).
    fn record(
        &self,
        rec: &mut radcache_vk::Recorder,
        inputs: &RecordInputs<'_>,
        records: &radcache_vk::Buffer,
        radiance: Option<&radcache_vk::Buffer>,
    ) -> Result<()> {
        match (self, radiance) {
            (Records::Irradiance(pass), None) => {
                pass.record(rec, inputs, &RecordOutputs::records(records))
            }
            (Records::Radiance(pass), Some(blocks)) => {
                let outputs = RecordOutputs::with_radiance(records, blocks);
                pass.record(rec, inputs, &outputs)
            }
            (Records::Irradiance(_), Some(_)) => Err(Error::Invalid(
                "the record pass was made without radiance blocks to write".into(),
            )),
            (Records::Radiance(_), None) => Err(Error::Invalid(
                "the record pass writes radiance blocks, and no buffer holds them".into(),
            )),
        }
    }

    /// Ray queries of the last submitted dispatch.
    fn rays(&self) -> Result<u64> {
        match self {
            Records::Irradiance(pass) => pass.rays(),
            Records::Radiance(pass) => pass.rays(),
        }
    }

    /// The radiance grid the gathers share, if any.
    fn grid(&self) -> Option<&PathGrid> {
        match self {
            Records::Irradiance(pass) => pass.grid(),
            Records::Radiance(pass) => pass.grid(),
        }
    }
}

/// The temporal pass, as the frame's records are kept: with lifespans (a time step) or only
/// re-clamped to new views (`settle_records`, imported records).
enum Temporal {
    /// Records without lifespans.
    Kept(TemporalPass<NoLifespans>),
    /// Records with lifespans, evaluated one frame ahead.
    Lifespans(TemporalPass<WithLifespans>),
}

impl Temporal {
    /// The records carry lifespans.
    fn lifespans(&self) -> bool {
        matches!(self, Temporal::Lifespans(_))
    }

    /// Forgets the previous frame's instances and any pending look-ahead.
    fn forget(&mut self) {
        match self {
            Temporal::Kept(t) => t.forget(),
            Temporal::Lifespans(t) => t.forget(),
        }
    }
}

/// `$body` with `$c` bound to the composite pass of `$shading`, whichever its kind (the
/// accumulators' reads and the emission do not depend on it).
macro_rules! with_composite {
    ($shading:expr, |$c:ident| $body:expr) => {
        match $shading {
            Shading::PerSubFrame { composite: $c, .. } => $body,
            Shading::Once { composite: $c, .. } => $body,
        }
    };
}
use with_composite;

/// The cache's passes and state for one image size and one set of cache parameters.
pub struct IcRenderer {
    width: u32,
    height: u32,
    params: IcParams,
    gbuffer: GBuffer,
    gbuffer_pass: GBufferPass,
    /// The direct and composite passes.
    shading: Shading,
    splat: SplatPass,
    /// Radiance records for glossy lobes (docs/radiance-caching.md §6): in scenes with
    /// materials rough enough ([`radcache_scene::ScenePlan::radiance_cache`]); the blocks are
    /// in `state.radiance`, kept across frames and in cache files with their records (§8).
    glossy: Option<GlossySplatPass>,
    /// The records' radiance blocks are theirs (false after [`IcRenderer::import_cache`] of a
    /// file without blocks, until the records are made again).
    glossy_valid: bool,
    holes: HolePass,
    neighbours: NeighbourPass,
    records: Records,
    emission: EmissionPass,
    state: IcState,
    /// Records kept across frames (created for sequences: `settle_records` or a time step).
    temporal: Option<Temporal>,
    /// The previous frame's `clip_from_world` (kept records are re-clamped when it changes).
    last_view: Option<[[f32; 4]; 4]>,
    /// Re-clamp the kept records at the next frame whatever its view (imported records, made
    /// for an unknown view: `import_cache`).
    reclamp_next: bool,
    /// False until a frame has left records to keep.
    has_records: bool,
    /// Frames rendered (the last-use marks of `IcState::last_used`).
    frames: u32,
    /// The records hold a constant environment's light ([`crate::SkyLight::Records`] in a scene
    /// with one).
    sky_in_records: bool,
    /// How often the records are splatted (set at creation: the composite's centre samples).
    splat_mode: SplatMode,
    /// The settings the renderer was made with: a frame must ask for the same `config` fields.
    made_with: IcSettings,
}

impl std::fmt::Debug for IcRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IcRenderer")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl IcRenderer {
    /// Creates the passes for `settings` (size, parameters, record capacity) and `gpu`'s plan.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        gpu: &GpuScene,
        settings: &IcSettings,
    ) -> Result<IcRenderer> {
        let (w, h) = (settings.width, settings.height);
        if w == 0 || h == 0 {
            return Err(Error::Invalid(format!("the image size {w}x{h} is empty")));
        }
        if !settings.params.is_valid() {
            return Err(Error::Invalid(format!(
                "invalid cache parameters: {:?}",
                settings.params
            )));
        }
        let params = settings.params;
        let temporal = settings.time_step_s > 0.0 || settings.settle_records;
        let radiance = gpu.plan().radiance_cache() && settings.glossy.records();
        let glossy = if radiance {
            let gradients = settings.glossy == GlossyLight::Records;
            Some(GlossySplatPass::new(ctx, shaders, w, h, gradients)?)
        } else {
            None
        };
        let capacity = settings.record_capacity;
        Ok(IcRenderer {
            width: w,
            height: h,
            params,
            gbuffer: GBuffer::new(ctx, w, h)?,
            gbuffer_pass: GBufferPass::new(ctx, shaders, gpu, GBufferVariant::planned(gpu.plan()))?,
            shading: Self::shading(ctx, shaders, gpu, settings, radiance)?,
            splat: SplatPass::new(ctx, shaders, w, h)?,
            glossy,
            glossy_valid: true,
            holes: HolePass::new(ctx, shaders)?,
            neighbours: NeighbourPass::new(ctx, shaders)?,
            records: {
                let variant = RecordVariant {
                    path_grid: settings.path_grid,
                    ..RecordVariant::new(params, settings.sky)
                };
                if radiance {
                    let radiance = WithRadiance {
                        glossy_spacing: settings.glossy_spacing,
                    };
                    Records::Radiance(RecordPass::new(ctx, shaders, gpu, &variant.with(radiance))?)
                } else {
                    Records::Irradiance(RecordPass::new(ctx, shaders, gpu, &variant)?)
                }
            },
            emission: EmissionPass::new(ctx, shaders, gpu)?,
            state: IcState::new(
                ctx,
                shaders,
                &IcStateDesc {
                    radiance,
                    ..IcStateDesc::new(capacity, w * h)
                },
            )?,
            temporal: if temporal {
                let record_capacity = capacity;
                Some(if settings.time_step_s > 0.0 {
                    let variant = TemporalVariant {
                        record_capacity,
                        lifespans: WithLifespans,
                        radiance,
                    };
                    Temporal::Lifespans(TemporalPass::new(ctx, shaders, gpu, &variant)?)
                } else {
                    let variant = TemporalVariant {
                        record_capacity,
                        lifespans: NoLifespans,
                        radiance,
                    };
                    Temporal::Kept(TemporalPass::new(ctx, shaders, gpu, &variant)?)
                })
            } else {
                None
            },
            last_view: None,
            reclamp_next: false,
            has_records: false,
            frames: 0,
            sky_in_records: settings
                .sky
                .define(gpu.has_constant_environment())
                .is_some(),
            splat_mode: settings.splat,
            made_with: settings.clone(),
        })
    }

    /// The direct and composite passes for `settings`' splat mode (`radiance`: the frame has
    /// radiance records).
    fn shading(
        ctx: &Context,
        shaders: &ShaderCompiler,
        gpu: &GpuScene,
        settings: &IcSettings,
        radiance: bool,
    ) -> Result<Shading> {
        let (w, h) = (settings.width, settings.height);
        let moments = settings.anti_aliasing.is_some();
        let direct = DirectVariant {
            radiance,
            shadows: match settings.emitter_shadows {
                EmitterShadows::Adaptive => DirectShadows::Adaptive { pixels: w * h },
                EmitterShadows::Fixed => DirectShadows::Fixed,
            },
            specular_paths: settings.specular_paths,
            ..DirectVariant::new(settings.sky, settings.emitters)
        };
        let composite = CompositeVariant {
            radiance,
            moments,
            ..CompositeVariant::new(w, h)
        };
        Ok(match settings.splat {
            SplatMode::PerSubFrame => Shading::PerSubFrame {
                direct: DirectPass::new(ctx, shaders, gpu, &direct)?,
                composite: CompositePass::new(ctx, shaders, gpu, &composite)?,
            },
            // Splatting once, the later sub-frames' composite is the direct pass's.
            SplatMode::Once => Shading::Once {
                direct: DirectPass::new(
                    ctx,
                    shaders,
                    gpu,
                    &direct.to(DirectCompositing { moments }),
                )?,
                composite: CompositePass::new(ctx, shaders, gpu, &composite.with(WithCentres))?,
            },
        })
    }

    /// Drops every record: the next frame builds its cache from scratch.
    pub fn forget(&mut self) {
        self.has_records = false;
        self.glossy_valid = true;
    }

    /// The glossy splat when its records' coefficients are valid.
    fn glossy(&self) -> Option<&GlossySplatPass> {
        self.glossy.as_ref().filter(|_| self.glossy_valid)
    }

    /// The cache's GPU state (records, counters).
    pub fn state(&self) -> &IcState {
        &self.state
    }

    /// Renders `scene` at `settings.time`, keeping the records of the previous frame unless
    /// [`IcRenderer::forget`] was called (records are world-space: right for a static scene
    /// under any camera motion). `settings` must have the `config` fields the renderer was
    /// created with (an error names the first that differs). The phases are described in [`crate::frame`].
    pub fn render(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        gpu: &mut GpuScene,
        settings: &IcSettings,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<(FrameOutput, IcStats)> {
        self.check(settings)?;
        // Splatting once, only the centres' holes matter: the cache phase fills those alone.
        let cache_sub_frames = match self.splat_mode {
            SplatMode::Once => 1,
            SplatMode::PerSubFrame => settings.sub_frames,
        };
        let mut run = FrameRun::new(
            self.params.levels,
            cache_sub_frames,
            settings.sub_frames,
            progress,
        );
        let view = self.setup(ctx, scene, gpu, settings, &mut run)?;
        self.cache_phase(ctx, gpu, settings, &mut run)?;
        if settings.time_step_s > 0.0 {
            self.look_ahead(ctx, scene, gpu, settings, &view, &mut run)?;
        }
        run.add_rays("records", run.stats.record_rays);
        self.has_records = true;
        for k in 0..run.shade_total {
            self.shade_sub_frame(ctx, gpu, settings, k, &mut run)?;
        }
        if let Some(aa) = settings.anti_aliasing {
            self.anti_alias(ctx, gpu, settings, aa, &mut run)?;
        }
        self.finish(ctx, gpu, settings, run)
    }

    /// Refuses settings the renderer was not made for, naming the first `config` field that
    /// differs ([`IcSettings::config_change`]).
    fn check(&self, settings: &IcSettings) -> Result<()> {
        match settings.config_change(&self.made_with) {
            None => Ok(()),
            Some(change) => Err(Error::Invalid(change.to_string())),
        }
    }

    fn read_debug(&self, ctx: &Context, sub_frames: u32, records: u64) -> Result<IcDebug> {
        let (indirect, weight_sum, records_per_pixel) =
            with_composite!(&self.shading, |c| c.read_debug(ctx, sub_frames))?;
        let mut record_positions = vec![0.0f32; (self.width * self.height) as usize];
        let all: Vec<GpuRecord> = ctx.read_buffer(&self.state.records, records as usize)?;
        for r in &all {
            if let Some(p) = record_positions.get_mut(r.info[0] as usize) {
                *p = 1.0;
            }
        }
        Ok(IcDebug {
            indirect,
            weight_sum,
            records_per_pixel,
            record_positions,
        })
    }
}

/// Renders `scene` at `settings.time` with the irradiance cache, from an empty cache (a
/// sequence keeps an [`IcRenderer`] instead, to create the pipelines once and keep records).
pub fn render_ic(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    settings: &IcSettings,
    progress: &mut dyn FnMut(Progress),
) -> Result<(FrameOutput, IcStats)> {
    let start = Instant::now();
    let mut renderer = IcRenderer::new(ctx, shaders, gpu, settings)?;
    let pipelines_s = start.elapsed().as_secs_f64();
    let (mut out, mut stats) = renderer.render(ctx, scene, gpu, settings, progress)?;
    out.time_s += pipelines_s;
    stats.phases_s.insert("pipelines".into(), pipelines_s);
    Ok((out, stats))
}
