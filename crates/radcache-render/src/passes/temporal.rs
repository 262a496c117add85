//! Temporal radiance caching (`shaders/passes/temporal.comp`; docs/temporal.md §3, §1): records
//! kept across the frames of an animation whose geometry or lights move.
//!
//! Every record lives on the mesh instance it was created on (object-space point and normals in
//! `IcState::temporal`) and follows it. Records are evaluated **one frame ahead**: after the
//! cache phase of frame t, the frame's new records and the records whose lifespan ended are
//! evaluated (again), at their own points and with their own rays (deterministic per-record
//! seeds), in the scene of frame t + 1 ("look-ahead"). Against the record's previous known value
//! E_k (exact at frame t_k) this gives its rate over the span s = t + 1 − t_k and its lifespan
//! `min(s · a_t / |τ − 1|, Δt_max)` (τ the luminance ratio; `radcache_cache::temporal`), `Δt_max`
//! staggered by ±20 % per record so refreshes do not come in waves; the look-ahead value becomes
//! E_k. A record shows E_k, carried at most one frame forward at its rate (an expired record
//! shows it once more while its next value is computed). So a refresh costs one evaluation, and a
//! record whose light changes quickly is evaluated every other frame. A lifespan measured from one
//! frame's change misses a change still to come (an object approaching slowly at first), so a
//! record also expires when the share of its cosine-weighted hemisphere that the other moving
//! instances' bounding spheres cover (`radcache_cache::temporal::moving_cover`, summed; the
//! spheres at the scene's time are written by the host before the advance and the finish) has
//! changed by more than `a_t` since its last evaluation. Linear extrapolation over
//! the whole lifespan (docs/temporal.md §3.4) measured worse: a difference of two evaluations
//! carries the noise of the paths that diverge between the two scenes.
//!
//! [`crate::IcRenderer`] drives it: [`TemporalJob::Advance`] at the start of a frame (it
//! also re-clamps kept records' radii when the camera moved), the cache's hole filling, then
//! [`TemporalJob::Adopt`] for the frame's new records, the look-ahead
//! ([`TemporalJob::Shift`], the record pass on [`TemporalPass::lookahead`],
//! [`TemporalJob::Finish`]) with the scene at the next frame's time, and
//! [`TemporalJob::KeepInstances`] at the end.
//!
//! Radiance records (docs/radiance-caching.md §8) keep their SH coefficients in
//! `IcState::radiance` and are evaluated ahead with the irradiance: the adopt step copies the
//! blocks to [`TemporalPass::lookahead_radiance`], the look-ahead's record pass writes the listed
//! records' new blocks there, and [`TemporalJob::PromoteRadiance`] copies them back
//! after the frame's shading, so the next frame shows them. The coefficients get no rate (a
//! record shows its last evaluation, not an extrapolation: the lifespan, from the irradiance's
//! change, already bounds how stale it gets), and since they are in world space a kept record on
//! a rotating instance keeps them unrotated until its refresh.

use radcache_cache::temporal::temporal_is_valid;
use radcache_cache::IcParams;
use radcache_scene::Scene;
use radcache_shared::consts::TEMPORAL_FLAG_ADOPTED;
use radcache_shared::gpu::{GpuInstance, GpuRecord, GpuRecordTemporal, IcCounters};
use radcache_vk::{
    vk, Buffer, BufferDesc, Context, MemoryLocation, Pipeline, Recorder, Resource, ShaderCompiler,
};

use crate::bindings::temporal as b;
use crate::error::Result;
use crate::scene::features::{SceneFeatures, ShaderModule};
use crate::scene::GpuScene;
use crate::state::{IcState, RADIANCE_BYTES_PER_RECORD};

radcache_shared::gpu_struct! {
    /// The push constants of the pass (`TemporalPush` in GLSL).
    pub struct TemporalPush {
        /// Step.
        pub step: u32 => "uint",
        /// Frame.
        pub frame: u32 => "uint",
        /// First.
        pub first: u32 => "uint",
        /// Has previous.
        pub has_previous: u32 => "uint",
        /// Has lifespans.
        pub has_lifespans: u32 => "uint",
        /// Accuracy.
        pub accuracy: f32 => "float",
        /// Max age.
        pub max_age: f32 => "float",
        /// Capacity.
        pub capacity: u32 => "uint",
        /// Reclamp.
        pub reclamp: u32 => "uint",
        /// Min px.
        pub min_px: f32 => "float",
        /// Max px.
        pub max_px: f32 => "float",
        /// V scale.
        pub v_scale: f32 => "float",
        /// Moving count.
        pub moving_count: u32 => "uint",
    }
}

use radcache_shared::consts::TemporalStep as Mode;

/// Whether a temporal pass's records carry lifespans, fixed when the pass is made: the type
/// parameter of [`TemporalVariant`] and [`TemporalPass`], and what [`TemporalPass::record`]
/// takes ([`RecordLifespans::Job`]). [`NoLifespans`] (records kept under unchanged lighting, or
/// imported): the only step is re-clamping the kept records to a new view ([`KeptJob`]), and the
/// pass allocates no look-ahead copy; [`WithLifespans`] (a scene whose lighting changes, a time
/// step): every [`TemporalJob`]. A pass without lifespans cannot be given a step that needs them
/// (its look-ahead buffer holds one record) —
///
/// ```compile_fail,E0308
/// use radcache_render::passes::temporal::{TemporalInputs, TemporalJob, TemporalPass};
/// use radcache_vk::Recorder;
///
/// // `TemporalPass<NoLifespans>` takes a `KeptJob`.
/// fn adopt(pass: &mut TemporalPass, rec: &mut Recorder, io: &TemporalInputs<'_>) {
///     let job = TemporalJob::Adopt { frame: 1, first: 0, records: 8, listed: 8 };
///     pass.record(rec, io, job).unwrap();
/// }
/// ```
///
/// — while a pass made with them can:
///
/// ```
/// use radcache_render::passes::temporal::{TemporalInputs, TemporalJob, TemporalPass, WithLifespans};
/// use radcache_vk::Recorder;
///
/// fn adopt(pass: &mut TemporalPass<WithLifespans>, rec: &mut Recorder, io: &TemporalInputs<'_>) {
///     let job = TemporalJob::Adopt { frame: 1, first: 0, records: 8, listed: 8 };
///     pass.record(rec, io, job).unwrap();
/// }
/// ```
pub trait RecordLifespans:
    sealed::Sealed + Copy + std::fmt::Debug + PartialEq + Eq + 'static
{
    /// The steps a pass of this kind records.
    type Job<'a>: Copy + std::fmt::Debug + Into<TemporalJob<'a>>;
    /// Records carry lifespans: the look-ahead copy of the records is allocated.
    const LIFESPANS: bool;
}

mod sealed {
    /// Only this file's kinds are [`super::RecordLifespans`].
    pub trait Sealed {}
    impl Sealed for super::NoLifespans {}
    impl Sealed for super::WithLifespans {}
}

/// Records kept without lifespans (unchanged lighting; imported records): the pass re-clamps
/// them to a new view and nothing else.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoLifespans;

impl RecordLifespans for NoLifespans {
    type Job<'a> = KeptJob<'a>;
    const LIFESPANS: bool = false;
}

/// Records with lifespans, evaluated one frame ahead (a time step).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WithLifespans;

impl RecordLifespans for WithLifespans {
    type Job<'a> = TemporalJob<'a>;
    const LIFESPANS: bool = true;
}

/// The step of a temporal pass whose records carry no lifespans ([`NoLifespans`]).
#[derive(Debug, Clone, Copy)]
pub enum KeptJob<'a> {
    /// Empties the list, then clamps the radius of every one of the `records` kept from earlier
    /// frames to `reclamp`'s [R⁻, R⁺] at the record's pixel footprint in the current view (the
    /// camera moved). The neighbour grid must be rebuilt afterwards.
    Advance {
        /// The frame.
        frame: u32,
        /// Records kept.
        records: u32,
        /// The parameters.
        reclamp: &'a IcParams,
    },
}

impl<'a> From<KeptJob<'a>> for TemporalJob<'a> {
    fn from(job: KeptJob<'a>) -> TemporalJob<'a> {
        match job {
            KeptJob::Advance {
                frame,
                records,
                reclamp,
            } => TemporalJob::Advance {
                frame,
                records,
                lifespans: None,
                reclamp: Some(reclamp),
            },
        }
    }
}

/// The temporal pipeline, the list of records to evaluate this frame, the look-ahead copy of the
/// records, the previous frame's instances and the moving instances' bounding spheres; `L`,
/// whether its records carry lifespans ([`RecordLifespans`]).
pub struct TemporalPass<L: RecordLifespans = NoLifespans> {
    pipeline: Pipeline,
    /// Record indices to evaluate this frame (`uint[capacity]`).
    pub list: Buffer,
    /// The list's `IcCounters` (counts.x = records, counts.y = listed, dispatch = one workgroup
    /// per listed record): the record pass's refresh reads it as its requests' counters.
    pub list_counters: Buffer,
    /// The records evaluated at the next frame's time (same indices as the cache's).
    pub lookahead: Buffer,
    /// Their radiance blocks (same indices), with lifespans in a cache with radiance blocks.
    pub lookahead_radiance: Option<Buffer>,
    /// Records whose look-ahead radiance blocks go to the cache after this frame's shading
    /// ([`TemporalJob::PromoteRadiance`]); 0 = none pending.
    promote: u32,
    previous: Buffer,
    /// Two vec4 per moving instance: bounding sphere (centre, radius) at the scene's current
    /// time, then (instance index, 0, 0, 0) (`temporal.comp`'s motion-aware expiry).
    moving: Buffer,
    moving_count: u32,
    has_previous: bool,
    lifespans: std::marker::PhantomData<L>,
    capacity: u32,
}

impl<L: RecordLifespans> std::fmt::Debug for TemporalPass<L> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TemporalPass")
            .field("capacity", &self.capacity)
            .finish_non_exhaustive()
    }
}

/// What the temporal pass works on: the scene (its instances now, and their previous
/// transforms kept by [`TemporalJob::KeepInstances`]) and the cache's records.
#[derive(Debug, Clone, Copy)]
pub struct TemporalInputs<'a> {
    /// The scene, at the time the step needs (the frame's, or the next frame's for
    /// [`TemporalJob::Shift`]).
    pub scene: &'a GpuScene,
    /// The records, their temporal states and counters.
    pub state: &'a IcState,
}

/// One step of a frame's temporal bookkeeping, in the frame's order (a pass made
/// [`WithLifespans`]).
#[derive(Debug, Clone, Copy)]
pub enum TemporalJob<'a> {
    /// Empties the list, then, over the `records` kept from earlier frames: with `lifespans`
    /// (the scene, the frame's time, the parameters), moves every record with its instance and
    /// extrapolates it to `frame`, or lists it when it expired (its lifespan ended, or the
    /// moving instances' cover of it changed by more than `a_t`); with `reclamp` (the camera
    /// moved), clamps every radius to the parameters' [R⁻, R⁺] at the record's pixel footprint
    /// in the current view. The scene and view must be the frame's; the neighbour grid must be
    /// rebuilt afterwards.
    Advance {
        /// The frame.
        frame: u32,
        /// Records kept.
        records: u32,
        /// The scene, the frame's time and the parameters, where records carry lifespans.
        lifespans: Option<(&'a Scene, f32, &'a IcParams)>,
        /// The parameters, where the camera moved.
        reclamp: Option<&'a IcParams>,
    },
    /// Lists the records `first .. records` (created this frame) after the expired ones and
    /// makes every listed record born at `frame` (at the scene's current time); `listed` is the
    /// list's length afterwards (expired + new, at most the capacity). Then copies the records
    /// (and their radiance blocks, when both the cache and the pass have them) to the look-ahead
    /// buffers.
    Adopt {
        /// The frame.
        frame: u32,
        /// The first record created this frame.
        first: u32,
        /// The records.
        records: u32,
        /// The list's length afterwards.
        listed: u32,
    },
    /// Moves the listed look-ahead records to the instances' current transforms (the scene must
    /// be at the next frame's time).
    Shift {
        /// The list's length.
        listed: u32,
    },
    /// The rate and lifespan of every listed record from its known value and its look-ahead
    /// value, which becomes its known value for frame `frame + 1`, and its cover by the moving
    /// instances of `next` (the scene, at the next frame's time).
    Finish {
        /// The frame.
        frame: u32,
        /// The list's length.
        listed: u32,
        /// The lifespans' parameters.
        lifespans: Lifespans,
        /// The scene and the next frame's time.
        next: (&'a Scene, f32),
    },
    /// Copies the radiance blocks the look-ahead computed (and the unlisted records' unchanged
    /// ones) back to the cache, once the frame's shading has read the current ones; nothing when
    /// no look-ahead is pending.
    PromoteRadiance,
    /// Keeps the scene's current instances as the previous frame's (the next advance rotates
    /// gradients by the change since).
    KeepInstances,
}

/// Temporal accuracy and largest lifespan of the cache's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lifespans {
    /// `a_t`.
    pub accuracy: f32,
    /// `Δt_max` in frames.
    pub max_age: f32,
}

/// What the temporal pass is made for: its buffers; `L`, whether its records carry lifespans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TemporalVariant<L: RecordLifespans = NoLifespans> {
    /// Records of the cache.
    pub record_capacity: u32,
    /// With [`WithLifespans`] (a scene whose lighting changes) the look-ahead copy of the
    /// records is allocated.
    pub lifespans: L,
    /// With lifespans, the cache has radiance blocks: their look-ahead copy too.
    pub radiance: bool,
}

impl TemporalPass {
    /// The shader module the pass compiles for a scene with `features` (with lifespans or
    /// without).
    pub(crate) fn modules(features: &SceneFeatures) -> Vec<ShaderModule> {
        vec![ShaderModule::new(
            "passes/temporal.comp",
            features.defines(),
        )]
    }
}

impl<L: RecordLifespans> TemporalPass<L> {
    /// Compiles the pass for `scene` and allocates its buffers for `variant`.
    pub fn new(
        ctx: &Context,
        shaders: &ShaderCompiler,
        scene: &GpuScene,
        variant: &TemporalVariant<L>,
    ) -> Result<TemporalPass<L>> {
        let TemporalVariant {
            record_capacity,
            radiance,
            ..
        } = *variant;
        let lifespans = L::LIFESPANS;
        let spirv = TemporalPass::<NoLifespans>::modules(&scene.features())[0].compile(shaders)?;
        let pipeline = Pipeline::compute(
            ctx,
            "temporal",
            &spirv,
            &b::layout(),
            std::mem::size_of::<TemporalPush>() as u32,
        )?;
        let buffer = |name, size: u64, usage, location| {
            Buffer::new(
                ctx,
                &BufferDesc {
                    name,
                    size: size.max(16),
                    usage,
                    location,
                    alignment: 0,
                },
            )
        };
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let capacity = record_capacity.max(1);
        let (_, instances) = scene.instances();
        Ok(TemporalPass {
            pipeline,
            list: buffer(
                "temporal.list",
                u64::from(capacity) * 4,
                storage,
                MemoryLocation::GpuOnly,
            )?,
            list_counters: buffer(
                "temporal.counters",
                std::mem::size_of::<IcCounters>() as u64,
                storage | vk::BufferUsageFlags::INDIRECT_BUFFER,
                MemoryLocation::GpuToCpu,
            )?,
            lookahead: buffer(
                "temporal.lookahead",
                u64::from(if lifespans { capacity } else { 1 })
                    * std::mem::size_of::<GpuRecord>() as u64,
                storage | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )?,
            lookahead_radiance: if lifespans && radiance {
                Some(buffer(
                    "temporal.lookahead_radiance",
                    u64::from(capacity) * RADIANCE_BYTES_PER_RECORD,
                    storage
                        | vk::BufferUsageFlags::TRANSFER_SRC
                        | vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuOnly,
                )?)
            } else {
                None
            },
            promote: 0,
            previous: buffer(
                "temporal.previous_instances",
                u64::from(instances.max(1)) * std::mem::size_of::<GpuInstance>() as u64,
                storage | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )?,
            moving: buffer(
                "temporal.moving_spheres",
                u64::from(instances.max(1)) * 32,
                storage,
                MemoryLocation::CpuToGpu,
            )?,
            moving_count: 0,
            has_previous: false,
            lifespans: std::marker::PhantomData,
            capacity,
        })
    }

    fn dispatch(
        &self,
        rec: &mut Recorder,
        io: &TemporalInputs<'_>,
        mode: Mode,
        push: TemporalPush,
        invocations: u32,
    ) -> Result<()> {
        let (scene, state) = (io.scene, io.state);
        let mut bindings = scene.bindings();
        bindings.extend([
            (b::COUNTERS, Resource::Buffer(&state.counters)),
            (b::RECORDS, Resource::Buffer(&state.records)),
            (b::TEMPORAL, Resource::Buffer(&state.temporal)),
            (b::LIST, Resource::Buffer(&self.list)),
            (b::LIST_COUNTERS, Resource::Buffer(&self.list_counters)),
            (b::LOOKAHEAD, Resource::Buffer(&self.lookahead)),
            (b::PREVIOUS, Resource::Buffer(&self.previous)),
            (b::MOVING, Resource::Buffer(&self.moving)),
        ]);
        let push = TemporalPush {
            step: mode as u32,
            capacity: self.capacity,
            moving_count: self.moving_count,
            ..push
        };
        rec.pass("temporal", |rec| {
            rec.bind_pipeline(&self.pipeline);
            rec.push_bindings(&bindings);
            rec.push_constants(&push);
            rec.dispatch(invocations.div_ceil(64).max(1), 1, 1)
        })?;
        Ok(())
    }

    /// Records one step of the frame's temporal bookkeeping ([`TemporalJob`]; [`KeptJob`]
    /// for a pass without lifespans) over `io`'s records.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        io: &TemporalInputs<'_>,
        job: L::Job<'_>,
    ) -> Result<()> {
        match job.into() {
            TemporalJob::Advance {
                frame,
                records,
                lifespans,
                reclamp,
            } => self.record_advance(rec, io, frame, records, lifespans, reclamp),
            TemporalJob::Adopt {
                frame,
                first,
                records,
                listed,
            } => self.record_adopt(rec, io, frame, first, records, listed),
            TemporalJob::PromoteRadiance => {
                self.record_promote_radiance(rec, io.state);
                Ok(())
            }
            TemporalJob::Shift { listed } => self.record_shift(rec, io, listed),
            TemporalJob::Finish {
                frame,
                listed,
                lifespans,
                next,
            } => self.record_finish(rec, io, frame, listed, lifespans, next),
            TemporalJob::KeepInstances => {
                self.record_keep_instances(rec, io.scene);
                Ok(())
            }
        }
    }

    fn push(frame: u32) -> TemporalPush {
        TemporalPush {
            step: 0,
            frame,
            first: 0,
            has_previous: 0,
            has_lifespans: 0,
            accuracy: 0.0,
            max_age: 0.0,
            capacity: 0,
            reclamp: 0,
            min_px: 0.0,
            max_px: 0.0,
            v_scale: 1.0,
            moving_count: 0,
        }
    }

    /// Writes the bounding spheres of `scene`'s moving instances at time `t` for the next
    /// advance or finish (no submission reading them may be in flight).
    fn write_moving(&mut self, scene: &Scene, t: f32) -> Result<()> {
        let transforms = scene.instance_transforms(t);
        let mut spheres: Vec<[f32; 4]> = Vec::new();
        for (i, (inst, m)) in scene.instances.iter().zip(&transforms).enumerate() {
            let bounds = scene.meshes[inst.mesh].bounds;
            if !inst.dynamic || bounds.is_empty() {
                continue;
            }
            let world = bounds.transformed(m);
            let (centre, radius) = (world.center(), 0.5 * world.size().length());
            if centre.is_finite() && radius.is_finite() {
                spheres.push(centre.extend(radius).to_array());
                spheres.push([i as f32, 0.0, 0.0, 0.0]);
            }
        }
        self.moving_count = (spheres.len() / 2) as u32;
        if !spheres.is_empty() {
            self.moving.write(0, &spheres)?;
        }
        Ok(())
    }

    /// Records emptying the list, then, over the `records` kept from earlier frames: with
    /// `lifespans` (the scene, the frame's time, the parameters), moving every record with its
    /// instance and extrapolating it to `frame`, or listing it when it expired (its lifespan
    /// ended, or the moving instances' cover of it changed by more than `a_t`); with `reclamp`
    /// (the camera moved), clamping every radius to `params`' [R⁻, R⁺] at the record's pixel
    /// footprint in the current view. The scene and view must be the frame's; the neighbour grid
    /// must be rebuilt afterwards.
    fn record_advance(
        &mut self,
        rec: &mut Recorder,
        io: &TemporalInputs<'_>,
        frame: u32,
        records: u32,
        lifespans: Option<(&Scene, f32, &IcParams)>,
        reclamp: Option<&IcParams>,
    ) -> Result<()> {
        let push = Self::push(frame);
        self.dispatch(rec, io, Mode::Begin, push, 1)?;
        if records > 0 && (lifespans.is_some() || reclamp.is_some()) {
            let mut push = TemporalPush {
                has_previous: u32::from(self.has_previous),
                has_lifespans: u32::from(lifespans.is_some()),
                ..push
            };
            if let Some((source, time, params)) = lifespans {
                self.write_moving(source, time)?;
                push.accuracy = params.temporal_accuracy;
            }
            if let Some(p) = reclamp {
                push.reclamp = 1;
                push.min_px = p.min_spacing_px;
                push.max_px = p.max_spacing_px;
                push.v_scale = p.validity_scale();
            }
            self.dispatch(rec, io, Mode::Advance, push, records)?;
        }
        Ok(())
    }

    /// Records listing the records `first .. records` (created this frame) after the expired ones
    /// and making every listed record born at `frame` (at the scene's current time); `listed` is
    /// the list's length afterwards (expired + new, at most the capacity). Then copies the
    /// records (and their radiance blocks, when both the cache and the pass have them) to the
    /// look-ahead buffers.
    fn record_adopt(
        &mut self,
        rec: &mut Recorder,
        io: &TemporalInputs<'_>,
        frame: u32,
        first: u32,
        records: u32,
        listed: u32,
    ) -> Result<()> {
        let push = TemporalPush {
            first,
            ..Self::push(frame)
        };
        if records > first {
            self.dispatch(rec, io, Mode::Append, push, records - first)?;
        }
        self.dispatch(rec, io, Mode::Adopt, push, listed)?;
        let state = io.state;
        let bytes = u64::from(records) * std::mem::size_of::<GpuRecord>() as u64;
        if bytes > 0 {
            rec.copy_buffer(&state.records, 0, &self.lookahead, 0, bytes);
            self.promote = 0;
            if let (Some(from), Some(to)) = (&state.radiance, &self.lookahead_radiance) {
                if listed > 0 {
                    let bytes = u64::from(records) * RADIANCE_BYTES_PER_RECORD;
                    rec.copy_buffer(from, 0, to, 0, bytes);
                    self.promote = records;
                }
            }
        }
        Ok(())
    }

    /// Records copying the radiance blocks the look-ahead computed (and the unlisted records'
    /// unchanged ones) back to the cache, once the frame's shading has read the current ones;
    /// nothing when no look-ahead is pending.
    fn record_promote_radiance(&mut self, rec: &mut Recorder, state: &IcState) {
        if let (Some(from), Some(to)) = (&self.lookahead_radiance, &state.radiance) {
            if self.promote > 0 {
                let bytes = u64::from(self.promote) * RADIANCE_BYTES_PER_RECORD;
                rec.copy_buffer(from, 0, to, 0, bytes);
            }
        }
        self.promote = 0;
    }

    /// Records moving the listed look-ahead records to the instances' current transforms (the
    /// scene must be at the next frame's time).
    fn record_shift(&self, rec: &mut Recorder, io: &TemporalInputs<'_>, listed: u32) -> Result<()> {
        self.dispatch(rec, io, Mode::Shift, Self::push(0), listed)
    }

    /// Records the rate and lifespan of every listed record from its known value and its
    /// look-ahead value, which becomes its known value for frame `frame + 1`, and its cover by
    /// the moving instances of `next` (the scene, at the next frame's time).
    fn record_finish(
        &mut self,
        rec: &mut Recorder,
        io: &TemporalInputs<'_>,
        frame: u32,
        listed: u32,
        lifespans: Lifespans,
        next: (&Scene, f32),
    ) -> Result<()> {
        self.write_moving(next.0, next.1)?;
        let push = TemporalPush {
            accuracy: lifespans.accuracy,
            max_age: lifespans.max_age,
            ..Self::push(frame)
        };
        self.dispatch(rec, io, Mode::Finish, push, listed)
    }

    /// Records keeping the scene's current instances as the previous frame's (the next advance
    /// rotates gradients by the change since).
    fn record_keep_instances(&mut self, rec: &mut Recorder, scene: &GpuScene) {
        let (buffer, count) = scene.instances();
        let bytes = u64::from(count) * std::mem::size_of::<GpuInstance>() as u64;
        if bytes > 0 {
            rec.copy_buffer(buffer, 0, &self.previous, 0, bytes);
            self.has_previous = true;
        }
    }

    /// Forgets the previous frame's instances and any pending look-ahead (the next frame starts
    /// a new cache).
    pub fn forget(&mut self) {
        self.has_previous = false;
        self.promote = 0;
    }

    /// Listed records after the last submission (expired, then new).
    pub fn listed(&self) -> Result<u32> {
        let c = self.list_counters.read::<IcCounters>(1)?[0];
        Ok(c.requested.min(self.capacity))
    }
}

/// Whether the advance at `frame` lists the record of temporal state `t` for its lifespan
/// (`temporal.comp`, `TEMPORAL_ADVANCE`: its known value would outlive its lifespan at the next
/// frame); false for a record without lifespans (never adopted). The motion-aware expiry is not
/// included: it needs the moving instances.
pub fn expires_at(t: &GpuRecordTemporal, frame: u32) -> bool {
    let adopted = t.info[2] & TEMPORAL_FLAG_ADOPTED != 0;
    let age = frame as f32 - t.info[1] as f32;
    adopted && !temporal_is_valid(age + 1.0, t.object_position[3])
}
