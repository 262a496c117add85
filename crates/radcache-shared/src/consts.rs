//! Constants and step enums shared by Rust and GLSL, declared once here and generated into
//! `shaders/shared/constants.glsl` by `cargo xtask codegen` (a test fails when that file is
//! stale). No shader writes one of these values by hand.

/// A scalar constant that has a GLSL spelling.
pub trait GlslScalar: Copy {
    /// The GLSL type name.
    const GLSL: &'static str;
    /// The value as a GLSL literal of that type (exact: floats round-trip).
    fn literal(self) -> String;
}

impl GlslScalar for u32 {
    const GLSL: &'static str = "uint";
    fn literal(self) -> String {
        format!("{self}u")
    }
}

impl GlslScalar for i32 {
    const GLSL: &'static str = "int";
    fn literal(self) -> String {
        format!("{self}")
    }
}

impl GlslScalar for f32 {
    const GLSL: &'static str = "float";
    fn literal(self) -> String {
        // `{:?}` is the shortest representation that round-trips, always with '.' or 'e'.
        let s = format!("{self:?}");
        assert!(self.is_finite(), "GLSL has no literal for {s}");
        s
    }
}

/// `const TYPE NAME = VALUE;` for one constant.
pub fn glsl_const<T: GlslScalar>(name: &str, value: T) -> String {
    format!("const {} {name} = {};\n", T::GLSL, value.literal())
}

/// Declares `pub const`s and the function that writes their GLSL declarations.
#[macro_export]
macro_rules! gpu_consts {
    (
        $(#[$gmeta:meta])*
        fn $glsl_fn:ident;
        $( $(#[$meta:meta])* pub const $name:ident : $ty:ty = $value:expr; )*
    ) => {
        $( $(#[$meta])* pub const $name: $ty = $value; )*

        $(#[$gmeta])*
        pub fn $glsl_fn() -> String {
            let mut s = String::new();
            $( s.push_str(&$crate::consts::glsl_const(stringify!($name), $name)); )*
            s
        }
    };
}

/// Declares a `#[repr(u32)]` enum whose variants are a shader's steps or kinds, and its GLSL
/// constants `PREFIX_VARIANT` (variant names in upper snake case).
#[macro_export]
macro_rules! gpu_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident ($prefix:literal) {
            $( $(#[$vmeta:meta])* $variant:ident = $value:literal ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(u32)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $value ),*
        }

        impl $name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];

            /// The GLSL constants of the variants.
            pub fn glsl() -> String {
                let mut s = String::new();
                $(
                    let name = format!(
                        "{}_{}",
                        $prefix,
                        $crate::consts::upper_snake(stringify!($variant))
                    );
                    s.push_str(&$crate::consts::glsl_const(&name, $name::$variant as u32));
                )*
                s
            }
        }
    };
}

/// `BeginLevel` → `BEGIN_LEVEL`.
pub fn upper_snake(camel: &str) -> String {
    let mut s = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_uppercase());
    }
    s
}

gpu_consts! {
    /// The irradiance-cache constants' GLSL (the CPU twins in `radcache-cache` use the same).
    fn ircache_glsl;
    /// Distances at or above this value are misses ("no geometry"); radii are capped to it.
    /// Chosen well below 2^126 so that `x / r` stays inside Vulkan's guaranteed division range.
    pub const IC_FAR: f32 = 1.0e30;
    /// Smallest radius any weight or clamp divides by (the `R = 0` guard, docs/irradiance-cache.md).
    pub const R_FLOOR: f32 = 1.0e-20;
    /// Ward error floor: `w = 1 / max(ε, WARD_MIN_ERROR)` caps the weight at 1000 (RADIANCE's cap).
    pub const WARD_MIN_ERROR: f32 = 1.0e-3;
    /// `sqrt(1 − cos 10°)`: the Tabellion–Lamorlette normal-error scale.
    pub const TL_NORMAL_SCALE: f32 = 0.123_256_41;
    /// Smallest T&L κ accepted (κ = 0 would give an unbounded zone of influence).
    pub const KAPPA_MIN: f32 = 1.0e-3;
    /// `sin²(10°)`: rows lying entirely above 10° elevation (`cos²θ_j⁺ >= sin²10°`) take part in
    /// the restricted minimum distance (Mitsuba's grazing-ray guard).
    pub const ELEVATION_MIN_SIN2: f32 = 0.030_153_69;
    /// Per-channel upper bound of the extrapolated irradiance relative to the record's value.
    pub const EXTRAPOLATION_MAX_FACTOR: f32 = 4.0;
    /// Hessian error control (docs/irradiance-cache.md §10.4): the bound on a record's integrated
    /// second-order error in pixels, `R = (4·HESSIAN_ERROR·s²/|λ|)^{1/4}` (`s` the pixel
    /// footprint); an order-of-magnitude choice, not tuned.
    pub const HESSIAN_ERROR: f32 = 1000.0;
    /// Below `τ = S/h²` of this value the edge Hessian uses the series of `atan(√τ)/√τ`
    /// (docs/irradiance-cache.md §10.3).
    pub const HESSIAN_SERIES_TAU: f32 = 0.15;
    /// `WeightKind::Ward` on the GPU.
    pub const WEIGHT_WARD: u32 = 0;
    /// `WeightKind::TabellionLamorlette` on the GPU.
    pub const WEIGHT_TL: u32 = 1;
}

gpu_consts! {
    /// The record pass's and neighbour grid's constants' GLSL.
    fn record_glsl;
    /// Most strata (M·N) of one record's hemisphere (the shared-memory arrays of the record pass).
    pub const MAX_STRATA: u32 = 1728;
    /// Invocations per record (the record pass's workgroup size).
    pub const RECORD_GROUP: u32 = 64;
    /// `GpuRecord.info.w`: the gathered irradiance was not finite (stored as black).
    pub const RECORD_FLAG_INVALID_IRRADIANCE: u32 = 1;
    /// `GpuRecord.info.w`: the request's pixel held no surface (an empty record).
    pub const RECORD_FLAG_NO_SURFACE: u32 = 2;
    /// `GpuRecord.info.w`: the radius was clamped up to R⁻.
    pub const RECORD_FLAG_CLAMPED_UP: u32 = 4;
    /// `GpuRecord.info.w`: the radius was clamped down to R⁺.
    pub const RECORD_FLAG_CLAMPED_DOWN: u32 = 8;
    /// `GpuRecord.info.w`: the shading normal was folded toward the geometric one.
    pub const RECORD_FLAG_FOLDED: u32 = 16;
    /// `GpuRecord.info.w`: made for a glossy lobe from the cache (on a pixel whose material is
    /// not Lambertian and has a roughness of at least `GLOSSY_ROUGHNESS_MIN`); with
    /// `GLOSSY_DENSITY` its radius also obeys the glossy gradient limit
    /// (docs/radiance-caching.md §9), at creation and at every refresh.
    pub const RECORD_FLAG_GLOSSY: u32 = 32;
    /// Bits of `GpuRecord.info.w` that hold flags; the mesh instance is stored above them.
    pub const RECORD_FLAGS_MASK: u32 = 0xff;
    /// Shift of the mesh instance in `GpuRecord.info.w`.
    pub const RECORD_INSTANCE_SHIFT: u32 = 8;
    /// `GpuRecordTemporal.info.z`: the record was adopted by the temporal state.
    pub const TEMPORAL_FLAG_ADOPTED: u32 = 1;
    /// Multiplier of the pass seed in a sub-frame's creation seed
    /// (`seed · SEED_SUB_FRAME_MUL ^ sub_frame`, the golden-ratio constant).
    pub const SEED_SUB_FRAME_MUL: u32 = 0x9e37_79b9;
    /// Levels of the neighbour grid: cell sizes from 2^level_max down to 2^(level_max − 11);
    /// smaller radii use the finest level.
    pub const GRID_LEVELS: u32 = 12;
    /// Grid entries per record: one in table A, one per level in table B.
    pub const GRID_SLOTS: u32 = 13;
    /// Vertices of one splat quad (two triangles; `DrawArgs::vertex_count` of the splat draws).
    pub const QUAD_VERTICES: u32 = 6;
    /// Longest bucket list the neighbour pass walks (a guard; never reached in practice).
    pub const GRID_MAX_LIST: u32 = 4096;
    /// 32-bit words of one `GpuRecord` (the neighbour pass's atomic view of the records).
    pub const GPU_RECORD_WORDS: u32 = (std::mem::size_of::<crate::gpu::GpuRecord>() / 4) as u32;
    /// Word of `GpuRecord.normal_rorig.w` (`R_orig`) within a record.
    pub const GPU_RECORD_R_ORIG_WORD: u32 =
        ((std::mem::offset_of!(crate::gpu::GpuRecord, normal_rorig) + 12) / 4) as u32;
    /// Cells of the gather paths' radiance grid (docs/cache-frame.md §4.1; a power of two).
    pub const PATH_GRID_CELLS: u32 = 1 << 18;
    /// Slots a cell's key probes (linear probing) before the grid counts as full for it.
    pub const PATH_GRID_PROBES: u32 = 8;
    /// Continuations a cell gathers before the record dispatches after it take its mean.
    pub const PATH_GRID_READY: u32 = 16;
    /// Fixed-point steps per unit of radiance in the cells' 64-bit sums (order-independent, so
    /// the records do not depend on the order in which the invocations add).
    pub const PATH_GRID_SCALE: f32 = 1048576.0;
    /// Largest radiance a continuation deposits (clamped): 2^24 of them cannot overflow a sum.
    pub const PATH_GRID_MAX_SAMPLE: f32 = 65536.0;
    /// A cell's edge in pixel footprints at its distance from the camera, before rounding up to
    /// a power of two.
    pub const PATH_GRID_CELL_PX: f32 = 16.0;
    /// The largest cell edge, as a fraction of the scene's bounding-box diagonal (rounded down
    /// to a power of two): at low resolutions the pixel rule would make cells as wide as a
    /// room, and a cell that straddles a thin wall mixes the light of both sides.
    pub const PATH_GRID_MAX_CELL: f32 = 1.0 / 16.0;
    /// A vertex takes its cell's mean only when the segment that found it is at least this many
    /// cell edges long (near a corner the light changes within a cell).
    pub const PATH_GRID_MIN_SEGMENT: f32 = 2.0;
}

const _: () = assert!(GRID_SLOTS == GRID_LEVELS + 1);
const _: () = assert!(PATH_GRID_CELLS.is_power_of_two());
const _: () = assert!(RECORD_FLAG_GLOSSY <= RECORD_FLAGS_MASK);
const _: () = assert!(RECORD_FLAGS_MASK == (1 << RECORD_INSTANCE_SHIFT) - 1);

gpu_consts! {
    /// The BRDF constants' GLSL (`radcache-material` and `shaders/common/brdf.glsl` use the same).
    fn material_glsl;
    /// Smallest GGX α used: glTF roughness 0 (a perfect mirror) is clamped to this value so that
    /// D, the pdf and the sample weights stay finite (the peak of D is `1/(π α²) ≈ 3.2·10⁵`).
    pub const ALPHA_MIN: f32 = 1.0e-3;
    /// Cosines to the normal below this value count as "at or below the horizon": the BRDF, its
    /// pdf and the sample weights are 0 there (it bounds `V ≤ 0.5/(2·COS_MIN·α)`).
    pub const COS_MIN: f32 = 1.0e-6;
    /// Smith's Λ of a fully masked direction (`cos θ <= 0`): the largest finite f32.
    pub const SMITH_LAMBDA_MASKED: f32 = f32::MAX;
    /// Coefficients of the fit of Schlick's hemispherical mean `W(n·v)` in `t = 1 − n·v`,
    /// lowest power first (least-squares fit, maximum error 8·10⁻⁶; docs/materials.md §6).
    pub const SCHLICK_MEAN_C0: f32 = 8.2245e-5;
    /// See [`SCHLICK_MEAN_C0`].
    pub const SCHLICK_MEAN_C1: f32 = 2.01882e-3;
    /// See [`SCHLICK_MEAN_C0`].
    pub const SCHLICK_MEAN_C2: f32 = 9.31768e-3;
    /// See [`SCHLICK_MEAN_C0`].
    pub const SCHLICK_MEAN_C3: f32 = 7.77722e-3;
    /// See [`SCHLICK_MEAN_C0`].
    pub const SCHLICK_MEAN_C4: f32 = 8.96681e-3;
    /// Smallest cosine between a normal-mapped shading normal and the geometric normal: a map
    /// texel that tilts the normal further is bent back to this cosine (docs/materials.md §12).
    pub const NORMAL_MAP_COS_MIN: f32 = 0.05;
}

gpu_consts! {
    /// The radiance-caching constants' GLSL (`radcache-material`'s `sh`/`glossy` and
    /// `shaders/common/sh.glsl`, `glossy.glsl`; docs/radiance-caching.md).
    fn glossy_glsl;
    /// Bands of the spherical harmonics of a radiance record (0 to 3; §4).
    pub const SH_BANDS: u32 = 4;
    /// Coefficients per colour channel of a radiance record: `SH_BANDS²`.
    pub const SH_COEFFS: u32 = SH_BANDS * SH_BANDS;
    /// `1/(2√π)`: `Y_0^0`.
    pub const SH_K00: f32 = 0.282_094_79;
    /// `√(3/(4π))`: band 1.
    pub const SH_K1: f32 = 0.488_602_51;
    /// `√(15/(4π))`: `Y_2^{-2}`, `Y_2^{-1}`, `Y_2^1`.
    pub const SH_K2: f32 = 1.092_548_4;
    /// `√(5/(16π))`: `Y_2^0`.
    pub const SH_K20: f32 = 0.315_391_57;
    /// `√(15/(16π))`: `Y_2^2`.
    pub const SH_K22: f32 = 0.546_274_2;
    /// `√(35/(32π))`: `Y_3^{±3}`.
    pub const SH_K33: f32 = 0.590_043_6;
    /// `√(105/(4π))`: `Y_3^{-2}`.
    pub const SH_K32: f32 = 2.890_611_4;
    /// `√(21/(32π))`: `Y_3^{±1}`.
    pub const SH_K31: f32 = 0.457_045_8;
    /// `√(7/(16π))`: `Y_3^0`.
    pub const SH_K30: f32 = 0.373_176_33;
    /// `√(105/(16π))`: `Y_3^2`.
    pub const SH_K32B: f32 = 1.445_305_7;
    /// Rows of the glossy lobe table: roughness `j/(GLOSSY_TABLE_ROUGHNESS − 1)` over `[0, 1]`.
    pub const GLOSSY_TABLE_ROUGHNESS: u32 = 16;
    /// Columns of the glossy lobe table: `n·v` from `GLOSSY_NV_MIN` to 1, evenly spaced.
    pub const GLOSSY_TABLE_NV: u32 = 16;
    /// The smallest `n·v` of the glossy lobe table; views closer to the horizon use its column.
    pub const GLOSSY_NV_MIN: f32 = 0.02;
    /// vec4s per record of the radiance coefficients (`3·SH_COEFFS` floats, packed: coefficient
    /// `i`'s channel `c` at float `3i + c`).
    pub const RADIANCE_VEC4S: u32 = 3 * SH_COEFFS / 4;
    /// vec4s (uvec4 words) per record in the radiance buffer (docs/radiance-caching.md §7.2):
    /// its coefficients as f32 (`RADIANCE_VEC4S`), then the gradients' scale `s` (one f32, in
    /// lane 0 of vec4 `RADIANCE_VEC4S`), then the translational gradients along world x, y and z
    /// divided by `s`, as f16 pairs (`packHalf2x16`; 24 words per axis, floats packed as the
    /// coefficients, from vec4 `RADIANCE_VEC4S + 1`), and one vec4 holding the record's glossy
    /// gradient limit in lane 0 (docs/radiance-caching.md §9; the rest zero): 512 bytes, so
    /// 2¹⁸ records fit the 128 MiB a storage buffer binding may span on lavapipe.
    pub const RECORD_RADIANCE_VEC4S: u32 = 32;
    /// The smallest roughness whose specular lobe is taken from radiance records: from here up
    /// the 4-band product errs by at most 10 % in a room (7.5 % at 0.6, 11.8 % at 0.55;
    /// docs/radiance-caching.md §4); sharper lobes stay path traced per pixel.
    pub const GLOSSY_ROUGHNESS_MIN: f32 = 0.6;
}

gpu_consts! {
    /// The alpha tests of a material, `GpuMaterial::textures.w` (an `ivec4`, hence `int`;
    /// `radcache-render`'s `scene/pack.rs` writes them, `shaders/common/scene.glsl` reads them).
    fn scene_glsl;
    /// No alpha test: every point is there (opaque, or an untextured alpha that keeps every point).
    pub const ALPHA_NONE: i32 = 0;
    /// glTF `MASK`: a point is there when its alpha is at least the material's cutoff.
    pub const ALPHA_MASK: i32 = 1;
    /// glTF `BLEND`: a point is there with probability alpha (a hashed uniform number below it).
    pub const ALPHA_BLEND: i32 = 2;
}

gpu_consts! {
    /// The words of the direct pass's adaptive shadow buffer (`shaders/passes/direct.comp`,
    /// docs/cache-frame.md §8.2): `SHADOW_WORDS_ANALYTIC` words a pixel with emitters in closed
    /// form (`HAS_ANALYTIC_EMITTERS`), `SHADOW_WORDS_SAMPLED` without, from word
    /// `SHADOW_WORDS × the pixel's index`; `SHADOW_WORD_*` is a word's index within a pixel's.
    fn direct_shadows_glsl;
    /// What the pixel's neighbourhood saw of the emitters in this frame's sub-frames so far (a
    /// [`ShadowClass`]; written at sub-frame 0, raised to a penumbra by later ones).
    pub const SHADOW_WORD_SEEN: u32 = 0;
    /// What sub-frame 0 saw, frozen for the later sub-frames to compare with the neighbours':
    /// the emitters' [`ShadowClass`] (bits 0–1, `SHADOW_NONE` where the pixel was no surface),
    /// the visibility of the reused punctual lights (bit 2 + i set where light i's shadow ray was
    /// unoccluded) and [`SHADOW_EDGE`].
    pub const SHADOW_WORD_FROZEN: u32 = 1;
    /// The distance from the camera of sub-frame 0's sample (its float bits), which tells a later
    /// sample on another surface.
    pub const SHADOW_WORD_DISTANCE: u32 = 2;
    /// With emitters in closed form: sub-frame 0's shading normal (octahedral, `packSnorm2x16`).
    pub const SHADOW_WORD_NORMAL: u32 = 3;
    /// With emitters in closed form: the first of three words (r, g, b; float bits) holding the
    /// emitters' unshadowed irradiance at sub-frame 0's sample, taken again by later samples on
    /// that surface.
    pub const SHADOW_WORD_UNSHADOWED: u32 = 4;
    /// Words a pixel with emitters in closed form: up to the unshadowed irradiance's three.
    pub const SHADOW_WORDS_ANALYTIC: u32 = 7;
    /// Words a pixel without emitters in closed form: up to the distance.
    pub const SHADOW_WORDS_SAMPLED: u32 = 3;
    /// Bit 31 of the frozen word: sub-frame 0's samples of the pixel's 3×3 neighbourhood did not
    /// all lie on the pixel's surface (no reuse at the pixel).
    pub const SHADOW_EDGE: u32 = 1 << 31;
}

const _: () = assert!(SHADOW_WORDS_SAMPLED == SHADOW_WORD_DISTANCE + 1);
const _: () = assert!(SHADOW_WORDS_ANALYTIC == SHADOW_WORD_UNSHADOWED + 3);
const _: () = assert!(SHADOW_WORD_NORMAL >= SHADOW_WORDS_SAMPLED);

gpu_enum! {
    /// What a pixel's neighbourhood saw of the emitters in the direct pass's adaptive shadows
    /// (`shaders/passes/direct.comp`): the values of a pixel's [`SHADOW_WORD_SEEN`] and of bits
    /// 0–1 of its [`SHADOW_WORD_FROZEN`].
    pub enum ShadowClass("SHADOW") {
        /// Every emitter sample was occluded.
        Hidden = 0,
        /// Every emitter sample was unoccluded.
        Lit = 1,
        /// Some were and some were not (or unknown): every sample is kept.
        Penumbra = 2,
        /// No class: the pixel held no surface (or its emitters are sampled in its MIS).
        None = 3,
    }
}

// The classes fit bits 0–1 of the frozen word.
const _: () = assert!(ShadowClass::None as u32 <= 3);

gpu_enum! {
    /// The steps of the cache's counter bookkeeping (`shaders/passes/ic_counters.comp`).
    pub enum CounterStep("COUNTERS") {
        /// No records, no requests; the capacities from the push constants.
        Reset = 0,
        /// A creation level starts: no requests, hole count 0.
        BeginLevel = 1,
        /// The requests become the record pass's indirect dispatch (one workgroup per request
        /// that fits), and the batch starts at the record count.
        BeginBatch = 2,
        /// The batch joins the records: the record count grows, the splat draw covers every
        /// record and the batch draw the batch's.
        EndBatch = 3,
    }
}

gpu_enum! {
    /// The steps of the neighbour-clamping pass (`shaders/passes/neighbours.comp`).
    pub enum NeighbourStep("NEIGHBOURS") {
        /// Insert the records before the batch into the grid.
        InsertOld = 0,
        /// Insert the batch's records into the grid.
        InsertBatch = 1,
        /// Clamp the batch's radii against their neighbours (and the neighbours' against them).
        Clamp = 2,
    }
}

gpu_enum! {
    /// The steps of the temporal pass (`shaders/passes/temporal.comp`).
    pub enum TemporalStep("TEMPORAL") {
        /// Clear the frame's list of records to evaluate.
        Begin = 0,
        /// Move the kept records with their instances, list the expired ones.
        Advance = 1,
        /// List the frame's new records.
        Append = 2,
        /// Give the listed new records their temporal state.
        Adopt = 3,
        /// Copy the listed records, moved to the next frame's time, for the look-ahead.
        Shift = 4,
        /// Derive rates and lifespans from the look-ahead values.
        Finish = 5,
    }
}

gpu_enum! {
    /// Where the record pass's requests come from (`shaders/passes/record.comp`).
    pub enum RecordSource("RECORD_SOURCE") {
        /// Requests are pixels of the G-buffer: new records.
        Pixels = 0,
        /// Requests are record indices: evaluations of existing records (look-ahead, refresh).
        Records = 1,
    }
}

gpu_enum! {
    /// The function families of the BRDF's GLSL twin test (`shaders/tests/brdf_twin.comp`).
    pub enum BrdfTwinMode("BRDF_TWIN") {
        /// Fresnel, GGX and Smith terms.
        Terms = 0,
        /// Evaluation, diffuse share, sampling and pdfs of a material.
        Brdf = 1,
        /// The projected solid angle of a triangle (radcache-material's `polygon`).
        Polygon = 2,
    }
}

gpu_enum! {
    /// The function families of the spherical-harmonics twin test (`shaders/tests/sh_twin.comp`).
    pub enum ShTwinMode("SH_TWIN") {
        /// The basis, projection and reconstruction.
        Basis = 0,
        /// The change of frame by evaluation, the table lookup and the glossy radiance.
        Glossy = 1,
        /// The glossy lobe's world-space weights.
        Weights = 2,
        /// One basis function at a time (`sh_basis_one`).
        BasisOne = 3,
    }
}

gpu_enum! {
    /// The formula families of the GLSL twin test (`shaders/tests/ircache_twin.comp`).
    pub enum TwinMode("TWIN") {
        /// Stratified hemisphere sampling and hashing.
        Sampling = 0,
        /// Record weights and splat radii.
        Weight = 1,
        /// Extrapolation with gradients.
        Extrapolate = 2,
        /// Harmonic-mean radius and clamping.
        Radius = 3,
        /// A whole record from stratum samples.
        Record = 4,
        /// The temporal formulas.
        Temporal = 5,
        /// The Hessian error control's per-edge and per-cell functions.
        HessianTerms = 6,
        /// A whole record's Hessian and radius from stratum samples.
        HessianRecord = 7,
    }
}

/// `shaders/shared/constants.glsl`.
pub fn generated_glsl() -> String {
    let mut s = String::from(
        "// Generated by `cargo xtask codegen` from crates/radcache-shared/src/consts.rs. Do not edit.\n\
         #ifndef RADCACHE_SHARED_CONSTANTS_GLSL\n#define RADCACHE_SHARED_CONSTANTS_GLSL\n\n",
    );
    for part in [
        ircache_glsl(),
        record_glsl(),
        CounterStep::glsl(),
        NeighbourStep::glsl(),
        TemporalStep::glsl(),
        RecordSource::glsl(),
        TwinMode::glsl(),
        material_glsl(),
        BrdfTwinMode::glsl(),
        glossy_glsl(),
        ShTwinMode::glsl(),
        scene_glsl(),
        direct_shadows_glsl(),
        ShadowClass::glsl(),
    ] {
        s.push_str(&part);
        s.push('\n');
    }
    s.push_str("#endif\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_round_trip() {
        for v in [
            IC_FAR,
            R_FLOOR,
            TL_NORMAL_SCALE,
            ELEVATION_MIN_SIN2,
            4.0,
            0.5,
            1.0e-3,
        ] {
            let lit = v.literal();
            assert!(lit.contains('.') || lit.contains('e'), "{lit}");
            assert_eq!(lit.parse::<f32>().unwrap(), v, "{lit}");
        }
        assert_eq!(0x9e37_79b9u32.literal(), "2654435769u");
        assert_eq!((-3i32).literal(), "-3");
    }

    #[test]
    fn enums_name_their_variants() {
        assert_eq!(upper_snake("BeginLevel"), "BEGIN_LEVEL");
        let text = CounterStep::glsl();
        assert!(
            text.contains("const uint COUNTERS_BEGIN_LEVEL = 1u;"),
            "{text}"
        );
        assert_eq!(TemporalStep::ALL.len(), 6);
    }

    #[test]
    fn generated_glsl_is_up_to_date() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../shaders/shared/constants.glsl"
        );
        let on_disk = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            on_disk == generated_glsl(),
            "shaders/shared/constants.glsl is stale: run `cargo xtask codegen`"
        );
    }
}
