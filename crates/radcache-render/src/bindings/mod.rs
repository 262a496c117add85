//! The one owner of binding numbers and kinds. Bindings 0–15 are the scene's (every
//! pass that reads the scene pushes the same table); the G-buffer's six images follow at
//! [`PASS_BASE`] in the passes that read it; each pass's own bindings come next, declared once
//! here by `pass_bindings!` (below) as a named table. `cargo xtask codegen` writes every number to
//! `shaders/shared/bindings.glsl` as `B_<PASS>_<NAME>` (a test fails when it is stale), so no
//! shader writes a binding number; `radcache-vk` checks at record time that each binding pushed
//! has the declared kind and that none was left out.

use radcache_vk::{BindingKind, BindingLayout};

/// Frame constants (`FrameConstants`, uniform).
pub const FRAME: u32 = 0;
/// The TLAS.
pub const TLAS: u32 = 1;
/// All vertices (`GpuVertex[]`).
pub const VERTICES: u32 = 2;
/// All indices (`uint[]`, mesh-local).
pub const INDICES: u32 = 3;
/// Instances by custom index (`GpuInstance[]`).
pub const INSTANCES: u32 = 4;
/// Material index per triangle (`uint[]`, indexed by mesh first triangle + primitive).
pub const TRI_MATERIALS: u32 = 5;
/// Materials (`GpuMaterial[]`).
pub const MATERIALS: u32 = 6;
/// Texture descriptors (`GpuTexture[]`).
pub const TEXTURES: u32 = 7;
/// Texels of every texture (`uint[]`, RGBA8).
pub const TEXELS: u32 = 8;
/// Emissive triangles in world space (`GpuEmitter[]`).
pub const EMITTERS: u32 = 9;
/// Alias table over emitters, power-proportional (`GpuAlias[]`).
pub const EMITTER_ALIAS: u32 = 10;
/// Punctual lights (`GpuLight[]`).
pub const LIGHTS: u32 = 11;
/// Environment map texels (`vec4[]`, equirectangular, row-major, top row first).
pub const ENV_TEXELS: u32 = 12;
/// Alias table over environment texels (`GpuAlias[]`).
pub const ENV_ALIAS: u32 = 13;
/// Vertex tangents (`vec4[]`, parallel to the vertices; w = ±1 handedness, 0 where no normal map
/// applies). A 16-byte placeholder unless the plan has normal maps.
pub const TANGENTS: u32 = 14;
/// TEXCOORD_1 per vertex (`vec2[]`, parallel to the vertices; zero where a mesh has none). An
/// 16-byte placeholder unless the plan has TEXCOORD_1 (docs/materials.md §13).
pub const TEXCOORDS1: u32 = 15;
/// First binding of a pass's own resources.
pub const PASS_BASE: u32 = 16;

/// The scene's binding table (prefix of every scene-reading pass's table).
pub const SCENE: [BindingLayout; 16] = [
    BindingLayout::new(FRAME, BindingKind::UniformBuffer),
    BindingLayout::new(TLAS, BindingKind::AccelerationStructure),
    BindingLayout::new(VERTICES, BindingKind::StorageBuffer),
    BindingLayout::new(INDICES, BindingKind::StorageBuffer),
    BindingLayout::new(INSTANCES, BindingKind::StorageBuffer),
    BindingLayout::new(TRI_MATERIALS, BindingKind::StorageBuffer),
    BindingLayout::new(MATERIALS, BindingKind::StorageBuffer),
    BindingLayout::new(TEXTURES, BindingKind::StorageBuffer),
    BindingLayout::new(TEXELS, BindingKind::StorageBuffer),
    BindingLayout::new(EMITTERS, BindingKind::StorageBuffer),
    BindingLayout::new(EMITTER_ALIAS, BindingKind::StorageBuffer),
    BindingLayout::new(LIGHTS, BindingKind::StorageBuffer),
    BindingLayout::new(ENV_TEXELS, BindingKind::StorageBuffer),
    BindingLayout::new(ENV_ALIAS, BindingKind::StorageBuffer),
    BindingLayout::new(TANGENTS, BindingKind::StorageBuffer),
    BindingLayout::new(TEXCOORDS1, BindingKind::StorageBuffer),
];

/// One named binding of a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Binding {
    /// Name (upper snake case, as in GLSL without the `B_<PASS>_` prefix).
    pub name: &'static str,
    /// Binding number.
    pub binding: u32,
    /// Descriptor kind.
    pub kind: BindingKind,
}

impl Binding {
    /// The layout entry of this binding.
    pub const fn layout(&self) -> BindingLayout {
        BindingLayout::new(self.binding, self.kind)
    }
}

/// Declares a pass's binding table: a module with one `pub const` per binding (numbered in
/// order from `base`), the named table, the full layout (the prefix tables, then its own), and
/// the GLSL `#define`s.
macro_rules! pass_bindings {
    (
        $(#[$meta:meta])*
        pub mod $pass:ident ($glsl:literal, base = $base:expr, prefix = [$($prefix:expr),*]) {
            $( $(#[$bmeta:meta])* $name:ident : $kind:ident ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        pub mod $pass {
            #[allow(unused_imports)]
            use super::*;

            #[allow(non_camel_case_types, clippy::upper_case_acronyms, dead_code)]
            #[repr(u32)]
            enum Slot { $($name),* }

            $( $(#[$bmeta])* pub const $name: u32 = $base + Slot::$name as u32; )*

            /// The pass's own bindings, by name.
            pub const OWN: &[$crate::bindings::Binding] = &[$(
                $crate::bindings::Binding {
                    name: stringify!($name),
                    binding: $name,
                    kind: radcache_vk::BindingKind::$kind,
                }
            ),*];

            /// The pass's whole table: the prefix tables, then its own bindings.
            pub fn layout() -> Vec<radcache_vk::BindingLayout> {
                let prefix: &[&[radcache_vk::BindingLayout]] = &[$(&$prefix),*];
                prefix
                    .iter()
                    .flat_map(|t| t.iter().copied())
                    .chain(OWN.iter().map(|b| b.layout()))
                    .collect()
            }

            /// The GLSL `#define`s of the own bindings.
            pub fn glsl() -> String {
                $crate::bindings::glsl_defines($glsl, OWN)
            }
        }
    };
}

/// `#define B_<PASS>_<NAME> n` for each binding of `table`.
pub fn glsl_defines(pass: &str, table: &[Binding]) -> String {
    let mut s = format!("// {pass}\n");
    for b in table {
        s.push_str(&format!("#define B_{pass}_{} {}\n", b.name, b.binding));
    }
    s
}

pass_bindings! {
    /// The G-buffer images (`shaders/common/gbuffer.glsl`), storage images read by the cache's
    /// passes; the G-buffer pass writes them as attachments.
    pub mod gbuffer("GBUFFER", base = PASS_BASE, prefix = []) {
        /// World position (xyz), 1 on surfaces (w).
        POSITION: StorageImage,
        /// Shading normal (xyz), pixel footprint (w).
        NORMAL: StorageImage,
        /// Geometric normal (xyz), material index (w).
        GEOMETRIC: StorageImage,
        /// Diffuse albedo (rgb), mesh instance (w).
        ALBEDO: StorageImage,
        /// Emitted radiance toward the camera (rgb).
        EMISSION: StorageImage,
        /// Direct light toward the camera (rgb), written by the direct pass.
        DIRECT: StorageImage,
    }
}

/// The G-buffer's bindings as a layout prefix.
pub const GBUFFER: [BindingLayout; 6] = [
    gbuffer::OWN[0].layout(),
    gbuffer::OWN[1].layout(),
    gbuffer::OWN[2].layout(),
    gbuffer::OWN[3].layout(),
    gbuffer::OWN[4].layout(),
    gbuffer::OWN[5].layout(),
];

/// First binding after the G-buffer's.
pub const GBUFFER_END: u32 = PASS_BASE + GBUFFER.len() as u32;

/// The frame constants alone (the splat's only scene binding).
pub const FRAME_ONLY: [BindingLayout; 1] = [SCENE[0]];

pass_bindings! {
    /// `passes/gbuffer.comp` (traced, and the rasterized G-buffer's repair): which pixels the
    /// sub-frame shades.
    pub mod gbuffer_pass("GBUFFER_PASS", base = GBUFFER_END, prefix = [SCENE, GBUFFER]) {
        /// 1 where the pixel is shaded in this sub-frame, 0 where per-pixel adaptive
        /// anti-aliasing has stopped it (`uint[]`; docs/cache-frame.md §7.2).
        ACTIVE: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/aov.comp`: first-hit albedo, normal and depth.
    pub mod aov("AOV", base = PASS_BASE, prefix = [SCENE]) {
        /// Albedo per pixel (`vec4[]`).
        ALBEDO: StorageBuffer,
        /// Normal per pixel (`vec4[]`).
        NORMAL: StorageBuffer,
        /// Depth per pixel (`float[]`).
        DEPTH: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/composite.comp`: a sub-frame into the frame accumulator.
    pub mod composite("COMPOSITE", base = GBUFFER_END, prefix = [SCENE, GBUFFER]) {
        /// Σw·Ẽ (rgb), Σw (a): the splat target.
        SPLAT_SUM: StorageImage,
        /// The frame accumulator (`vec4[]`: Σ radiance, sub-frames; with `IC_AA_MOMENTS`,
        /// adaptive anti-aliasing, followed by Σ radiance² per pixel).
        ACCUM: StorageBuffer,
        /// Non-finite values dropped (`uint`).
        NONFINITE: StorageBuffer,
        /// The emission accumulator (`vec4[]`).
        EMISSION_ACCUM: StorageBuffer,
        /// Debug AOVs (`vec4[2 per pixel]`).
        DEBUG_ACCUM: StorageBuffer,
        /// Records reaching each pixel (the splat's count target).
        SPLAT_COUNT: StorageImage,
        /// Σw·L_glossy (rgb), Σw (a): the glossy splat's target (read with `HAS_RADIANCE_CACHE`).
        GLOSSY_SUM: StorageImage,
        /// Each pixel's centre sample (`vec4[2 per pixel]`: position, normal and footprint),
        /// for splatting once per frame (docs/cache-frame.md §6.5).
        CENTRE: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/direct.comp`: direct light at the G-buffer's points.
    pub mod direct("DIRECT", base = GBUFFER_END, prefix = [SCENE, GBUFFER]) {
        /// Ray queries traced (`uint`).
        RAY_COUNT: StorageBuffer,
        /// Each pixel's glossy world weights (`vec4[12 per pixel]`, written with
        /// `HAS_RADIANCE_CACHE`; docs/radiance-caching.md §6.2).
        GLOSSY_WEIGHTS: StorageBuffer,
        /// The glossy lobe's SH table (`float[]`, read with `HAS_RADIANCE_CACHE`).
        GLOSSY_TABLE: StorageBuffer,
        /// Adaptive shadows (docs/cache-frame.md §8.2), three `uint` a pixel (seven with
        /// emitters in closed form): what its neighbourhood saw of the emitters (hidden, lit or
        /// a penumbra) in the frame so far, sub-frame 0's answers frozen (the emitters' and the
        /// punctual lights' visibility), its sample's distance (and normal and the emitters'
        /// unshadowed irradiance there).
        SHADOWS: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/direct.comp` made to composite (`DIRECT_COMPOSITE`): after the direct pass's
    /// table ([`direct_composite_layout`]), the composite's resources (`composite`'s bindings
    /// of the same names) but the debug AOVs' (a frame with them composites in its own pass):
    /// the push descriptors of a pipeline are at most 32 (Vulkan's least `maxPushDescriptors`,
    /// lavapipe's), and the scene, the G-buffer and the direct pass take 26.
    pub mod direct_composite("DIRECT_COMPOSITE", base = direct::SHADOWS + 1, prefix = []) {
        /// The splat target.
        SPLAT_SUM: StorageImage,
        /// The frame accumulator.
        ACCUM: StorageBuffer,
        /// Non-finite values dropped, samples no centre matched.
        NONFINITE: StorageBuffer,
        /// The emission accumulator.
        EMISSION_ACCUM: StorageBuffer,
        /// The glossy splat's target.
        GLOSSY_SUM: StorageImage,
        /// The pixels' centre samples.
        CENTRE: StorageBuffer,
    }
}

/// The whole table of `passes/direct.comp` made to composite: the direct pass's, then
/// [`direct_composite`]'s own bindings.
pub fn direct_composite_layout() -> Vec<BindingLayout> {
    let own = direct_composite::OWN.iter().map(|b| b.layout());
    direct::layout().into_iter().chain(own).collect()
}

pass_bindings! {
    /// `passes/emission.comp`: box-filtered emission into the frame accumulator.
    pub mod emission("EMISSION", base = PASS_BASE, prefix = [SCENE]) {
        /// The frame accumulator (`vec4[]`).
        ACCUM: StorageBuffer,
        /// The composite's emission accumulator (`vec4[]`).
        EMISSION_ACCUM: StorageBuffer,
        /// Ray queries traced (`uint`).
        RAY_COUNT: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/holes.comp`: one request per S×S block with an uncovered pixel.
    pub mod holes("HOLES", base = GBUFFER_END, prefix = [GBUFFER]) {
        /// Σw·Ẽ (rgb), Σw (a): the coverage splat.
        SPLAT_SUM: StorageImage,
        /// Requested pixels (`uint[]`).
        REQUESTS: StorageBuffer,
        /// `IcCounters`.
        COUNTERS: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/ic_counters.comp`: the counters' bookkeeping.
    pub mod ic_counters("IC_COUNTERS", base = PASS_BASE, prefix = []) {
        /// `IcCounters`.
        COUNTERS: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/neighbours.comp`: neighbour clamping over a hash grid.
    pub mod neighbours("NEIGHBOURS", base = PASS_BASE, prefix = []) {
        /// `IcCounters`.
        COUNTERS: StorageBuffer,
        /// `GpuRecord[]`.
        RECORDS: StorageBuffer,
        /// The same records as words (atomic radius updates).
        RECORD_WORDS: StorageBuffer,
        /// Bucket list heads (`uint[]`).
        HEADS: StorageBuffer,
        /// List links (`uint[]`).
        NEXT: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/path_trace.comp`: the reference path tracer.
    pub mod path_trace("PATH_TRACE", base = PASS_BASE, prefix = [SCENE]) {
        /// Σ radiance per pixel (`vec4[]`).
        ACCUM: StorageBuffer,
        /// Kahan compensation of the sums (`vec4[]`).
        COMPENSATION: StorageBuffer,
        /// Ray queries traced (`uint`).
        RAY_COUNT: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/record.comp`: the records' gathers.
    pub mod record("RECORD", base = GBUFFER_END, prefix = [SCENE, GBUFFER]) {
        /// Requested pixels or record indices (`uint[]`).
        REQUESTS: StorageBuffer,
        /// `IcCounters` of the requests.
        COUNTERS: StorageBuffer,
        /// `GpuRecord[]` written.
        RECORDS: StorageBuffer,
        /// Ray queries traced (`uint`).
        RAY_COUNT: StorageBuffer,
        /// Stratum samples, for the twin tests (`vec4[]`).
        SAMPLES: StorageBuffer,
        /// The records' radiance coefficients (`vec4[12 per record]`, written with
        /// `HAS_RADIANCE_CACHE` where large enough; docs/radiance-caching.md §6.1).
        RADIANCE: StorageBuffer,
        /// The gather paths' radiance grid: per cell its key, ready epoch and count (`uvec4[]`,
        /// read and written with `PATH_GRID`; docs/cache-frame.md §4.1).
        PATH_GRID: StorageBuffer,
        /// The grid cells' fixed-point sums (`int64_t[4 per cell]`).
        PATH_GRID_SUMS: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/splat.vert` + `splat.frag`: the records' zones into the splat targets.
    pub mod splat("SPLAT", base = GBUFFER_END, prefix = [FRAME_ONLY, GBUFFER]) {
        /// `GpuRecord[]`.
        RECORDS: StorageBuffer,
        /// Last frame each record weighed on a pixel (`uint[]`).
        LAST_USED: StorageBuffer,
    }
}

pass_bindings! {
    /// `passes/splat.vert` + `splat_glossy.frag`: the records' radiance, weighted by each pixel's
    /// glossy lobe, into the glossy target. Its first two bindings are the splat's (the vertex
    /// shader is shared).
    pub mod splat_glossy("SPLAT_GLOSSY", base = GBUFFER_END, prefix = [FRAME_ONLY, GBUFFER]) {
        /// `GpuRecord[]`.
        RECORDS: StorageBuffer,
        /// Last frame each record weighed on a pixel (`uint[]`; not written here).
        LAST_USED: StorageBuffer,
        /// The records' radiance coefficients (`vec4[12 per record]`).
        RADIANCE: StorageBuffer,
        /// Each pixel's glossy world weights (`vec4[12 per pixel]`).
        GLOSSY_WEIGHTS: StorageBuffer,
    }
}

const _: () = assert!(splat_glossy::RECORDS == splat::RECORDS);
const _: () = assert!(splat_glossy::LAST_USED == splat::LAST_USED);

pass_bindings! {
    /// `passes/temporal.comp`: the records' temporal lifecycle.
    pub mod temporal("TEMPORAL", base = PASS_BASE, prefix = [SCENE]) {
        /// `IcCounters` of the cache.
        COUNTERS: StorageBuffer,
        /// `GpuRecord[]`.
        RECORDS: StorageBuffer,
        /// `GpuRecordTemporal[]`.
        TEMPORAL: StorageBuffer,
        /// Record indices to evaluate (`uint[]`).
        LIST: StorageBuffer,
        /// The list's `IcCounters`.
        LIST_COUNTERS: StorageBuffer,
        /// The look-ahead copy of the listed records (`GpuRecord[]`).
        LOOKAHEAD: StorageBuffer,
        /// The previous frame's instances (`GpuInstance[]`).
        PREVIOUS: StorageBuffer,
        /// Bounding spheres of the moving instances (`vec4[]`).
        MOVING: StorageBuffer,
    }
}

/// `shaders/shared/bindings.glsl`.
pub fn generated_glsl() -> String {
    let names = [
        ("FRAME", FRAME),
        ("TLAS", TLAS),
        ("VERTICES", VERTICES),
        ("INDICES", INDICES),
        ("INSTANCES", INSTANCES),
        ("TRI_MATERIALS", TRI_MATERIALS),
        ("MATERIALS", MATERIALS),
        ("TEXTURES", TEXTURES),
        ("TEXELS", TEXELS),
        ("EMITTERS", EMITTERS),
        ("EMITTER_ALIAS", EMITTER_ALIAS),
        ("LIGHTS", LIGHTS),
        ("ENV_TEXELS", ENV_TEXELS),
        ("ENV_ALIAS", ENV_ALIAS),
        ("TANGENTS", TANGENTS),
        ("TEXCOORDS1", TEXCOORDS1),
        ("PASS_BASE", PASS_BASE),
        ("GBUFFER_END", GBUFFER_END),
    ];
    let mut s = String::from(
        "// Generated by `cargo xtask codegen` from crates/radcache-render/src/bindings/mod.rs. Do not edit.\n\
         #ifndef RADCACHE_SHARED_BINDINGS_GLSL\n#define RADCACHE_SHARED_BINDINGS_GLSL\n\n// scene\n",
    );
    for (name, value) in names {
        s.push_str(&format!("#define B_{name} {value}\n"));
    }
    for table in [
        gbuffer::glsl(),
        gbuffer_pass::glsl(),
        aov::glsl(),
        composite::glsl(),
        direct::glsl(),
        direct_composite::glsl(),
        emission::glsl(),
        holes::glsl(),
        ic_counters::glsl(),
        neighbours::glsl(),
        path_trace::glsl(),
        record::glsl(),
        splat::glsl(),
        splat_glossy::glsl(),
        temporal::glsl(),
    ] {
        s.push('\n');
        s.push_str(&table);
    }
    s.push_str("\n#endif\n");
    s
}

#[cfg(test)]
mod tests;
