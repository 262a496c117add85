//! The reference path tracer pass (`shaders/passes/path_trace.comp`): unbiased, progressive,
//! box-filtered, with next-event estimation and MIS (see the shader's header for the estimator).
//!
//! Samples accumulate per pixel in a Kahan-compensated float sum on the GPU, so 10⁵ samples per
//! pixel keep full float precision. The host drives it in chunks: each submission traces
//! `sample_count` samples per pixel, and [`PathTracer::chunk_size`] adapts that count so one
//! submission stays short (drivers, lavapipe included, kill long dispatches).

use radcache_shared::dispatch::image_dispatch;
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::path_trace as b;
use crate::error::Result;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;

/// The shader, relative to `shaders/`.
pub const SHADER: &str = "passes/path_trace.comp";

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`PathTracePush` in GLSL).
    pub struct PathTracePush {
        /// Sample start.
        pub sample_start: u32 => "uint",
        /// Sample count.
        pub sample_count: u32 => "uint",
        /// Padding.
        pub pad: [u32; 2] => "uvec2",
    }
}

/// Accumulation state and pipeline of the path tracer for one image size.
pub struct PathTracer {
    pipeline: Pipeline,
    accum: Buffer,
    compensation: Buffer,
    rays: Buffer,
    width: u32,
    height: u32,
    samples: u32,
}

/// What a path-tracer recording does.
#[derive(Debug, Clone, Copy)]
pub enum PathTraceJob<'a> {
    /// Clear the accumulators (the start of a new image).
    Clear,
    /// `count` more samples per pixel of `scene` (one dispatch) in a pass named `path_trace`.
    Samples {
        /// The scene.
        scene: &'a GpuScene,
        /// Samples per pixel to add.
        count: u32,
    },
}

impl std::fmt::Debug for PathTracer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PathTracer")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("samples", &self.samples)
            .finish_non_exhaustive()
    }
}

impl PathTracer {
    /// The shader module the pass compiles for a scene with `features`.
    pub(crate) fn modules(features: &SceneFeatures) -> Vec<ShaderModule> {
        vec![ShaderModule::new(SHADER, features.defines())]
    }

    /// Width and height of the accumulators.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Compiles the pass for `scene`'s plan and allocates `width × height` accumulators.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        width: u32,
        height: u32,
    ) -> Result<PathTracer> {
        let spirv = Self::modules(&scene.features())[0].compile(shaders)?;
        let bindings = b::layout();
        let pipeline = Pipeline::compute(
            ctx,
            "path_trace",
            &spirv,
            &bindings,
            std::mem::size_of::<PathTracePush>() as u32,
        )?;
        let pixels = u64::from(width) * u64::from(height);
        let accum_desc = |name| BufferDesc {
            name,
            size: pixels * 16,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
            alignment: 0,
        };
        let accum = Buffer::new(ctx, &accum_desc("path_trace.accum"))?;
        let compensation = Buffer::new(ctx, &accum_desc("path_trace.compensation"))?;
        let rays = Buffer::new(
            ctx,
            &BufferDesc {
                name: "path_trace.ray_count",
                size: 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
                alignment: 0,
            },
        )?;
        Ok(PathTracer {
            pipeline,
            accum,
            compensation,
            rays,
            width,
            height,
            samples: 0,
        })
    }

    /// Samples per pixel accumulated so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Records `job`: clearing the accumulators, or more samples.
    pub fn record(&mut self, rec: &mut Recorder, job: PathTraceJob<'_>) -> Result<()> {
        let (scene, count) = match job {
            PathTraceJob::Clear => {
                rec.fill_buffer(&self.accum, 0, vk::WHOLE_SIZE, 0);
                rec.fill_buffer(&self.compensation, 0, vk::WHOLE_SIZE, 0);
                self.samples = 0;
                return Ok(());
            }
            PathTraceJob::Samples { scene, count } => (scene, count),
        };
        rec.fill_buffer(&self.rays, 0, vk::WHOLE_SIZE, 0);
        let push = PathTracePush {
            sample_start: self.samples,
            sample_count: count,
            pad: [0; 2],
        };
        let (w, h) = (self.width, self.height);
        let mut bindings = scene.bindings();
        bindings.extend([
            (b::ACCUM, Resource::Buffer(&self.accum)),
            (b::COMPENSATION, Resource::Buffer(&self.compensation)),
            (b::RAY_COUNT, Resource::Buffer(&self.rays)),
        ]);
        let pipeline = &self.pipeline;
        rec.pass("path_trace", |rec| {
            rec.bind_pipeline(pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            let [x, y, z] = image_dispatch(w, h);
            rec.dispatch(x, y, z)
        })?;
        self.samples += count;
        Ok(())
    }

    /// Ray queries issued by the last submitted chunk (read after its fence).
    pub fn last_chunk_rays(&self) -> Result<u64> {
        Ok(u64::from(self.rays.read::<u32>(1)?[0]))
    }

    /// Reads the mean radiance per pixel (rows top to bottom). Non-finite values cannot occur (the
    /// shader drops non-finite samples); any that would are counted and replaced by black.
    pub fn read_mean(&self, ctx: &Context) -> Result<(Vec<[f32; 3]>, u64)> {
        let sums: Vec<[f32; 4]> =
            ctx.read_buffer(&self.accum, (self.width * self.height) as usize)?;
        let mut bad = 0u64;
        let pixels = sums
            .iter()
            .map(|s| {
                let n = s[3].max(1.0);
                let v = [s[0] / n, s[1] / n, s[2] / n];
                if v.iter().all(|c| c.is_finite()) {
                    v
                } else {
                    bad += 1;
                    [0.0; 3]
                }
            })
            .collect();
        Ok((pixels, bad))
    }

    /// Samples per submission so that one submission takes about `target_ms`, from the time
    /// `last_ms` the last `last_count` samples took; at least 1, at most 256.
    pub fn chunk_size(last_count: u32, last_ms: f64, target_ms: f64) -> u32 {
        if last_ms <= 0.0 || !last_ms.is_finite() {
            return (last_count * 2).clamp(1, 256);
        }
        let per_sample = last_ms / f64::from(last_count.max(1));
        let n = (target_ms / per_sample).floor();
        // Grow at most 4× per step, so one slow estimate cannot produce a huge submission.
        (n as u32).clamp(1, (last_count * 4).clamp(1, 256))
    }
}

#[cfg(test)]
mod tests {
    use super::PathTracer;

    #[test]
    fn chunk_size_tracks_the_target() {
        assert_eq!(PathTracer::chunk_size(1, 10.0, 200.0), 4);
        assert_eq!(PathTracer::chunk_size(8, 80.0, 200.0), 20);
        assert_eq!(PathTracer::chunk_size(64, 1.0, 200.0), 256);
        assert_eq!(PathTracer::chunk_size(4, 1000.0, 200.0), 1);
        assert_eq!(PathTracer::chunk_size(3, 0.0, 200.0), 6);
    }
}
