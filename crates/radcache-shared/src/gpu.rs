//! The plain-data structs that cross into GLSL. Rust is the source of truth; the GLSL side is
//! generated into `shaders/shared/layouts.glsl` by `cargo xtask codegen`.

use crate::gpu_struct;

gpu_struct! {
    /// One vertex (32 bytes). Positions come first so the vertex buffer is also the BLAS input
    /// (`R32G32B32_SFLOAT`, stride 32).
    pub struct GpuVertex {
        /// Object-space position (xyz) and texture coordinate u (w).
        pub position_u: [f32; 4] => "vec4",
        /// Object-space shading normal (xyz) and texture coordinate v (w).
        pub normal_v: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// Where a mesh lives in the shared vertex, index and triangle-material buffers.
    pub struct GpuMesh {
        /// First vertex, first index, first triangle, triangle count.
        pub ranges: [u32; 4] => "uvec4",
    }
}

gpu_struct! {
    /// One TLAS instance (indexed by the instance custom index).
    pub struct GpuInstance {
        /// Object-to-world transform.
        pub world_from_object: [[f32; 4]; 4] => "mat4",
        /// Inverse transpose of the upper 3×3, for normals.
        pub normal_to_world: [[f32; 4]; 4] => "mat4",
        /// Mesh index, first vertex, first index, first triangle of the mesh.
        pub mesh: [u32; 4] => "uvec4",
    }
}

gpu_struct! {
    /// How a material's texture reference maps texture coordinates (docs/materials.md §13): its
    /// set, then its `KHR_texture_transform` as the 2×3 matrix `T·R·S`, `uv' = (row_u·(u, v, 1),
    /// row_v·(u, v, 1))`. The identity and set 0 for a reference without them (and for none).
    pub struct GpuUvMap {
        /// First row of the matrix (xyz) and the texture coordinate set (w: 0 TEXCOORD_0, 1
        /// TEXCOORD_1).
        pub row_u: [f32; 4] => "vec4",
        /// Second row of the matrix (xyz); unused (w).
        pub row_v: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// A material (metallic-roughness).
    pub struct GpuMaterial {
        /// Base colour factor (linear RGBA).
        pub base_color: [f32; 4] => "vec4",
        /// Emitted radiance (rgb, factor × strength) and double-sidedness (w: 1 or 0).
        pub emission: [f32; 4] => "vec4",
        /// Texture indices: base colour, emissive, metallic-roughness (−1 for none); the alpha
        /// test (w): 0 none (opaque), 1 MASK, 2 BLEND (`ALPHA_*` in `radcache_shared::consts`).
        pub textures: [i32; 4] => "ivec4",
        /// Metallic, roughness, luminance of the mean emitted radiance (texture mean included; the
        /// emitter sampling table is built from it, so light-sampling pdfs use it), index of
        /// refraction.
        pub params: [f32; 4] => "vec4",
        /// The dielectric's specular colour (rgb, `KHR_materials_specular`) and specular factor (w).
        pub specular: [f32; 4] => "vec4",
        /// The MASK alpha cutoff (x); unused (yzw).
        pub alpha: [f32; 4] => "vec4",
        /// Normal map: texture index as a float (x, −1 for none), `normalTexture.scale` (y),
        /// unused (z, w).
        pub normal_map: [f32; 4] => "vec4",
        /// The base colour texture's coordinates.
        pub base_color_uv: GpuUvMap => struct,
        /// The emissive texture's coordinates.
        pub emissive_uv: GpuUvMap => struct,
        /// The metallic-roughness texture's coordinates.
        pub metallic_roughness_uv: GpuUvMap => struct,
        /// The normal map's coordinates.
        pub normal_uv: GpuUvMap => struct,
    }
}

gpu_struct! {
    /// A texture in the shared texel buffer (RGBA8 texels).
    pub struct GpuTexture {
        /// First texel, width, height, flags (bits 0–3 wrap S, 4–7 wrap T, bit 8 sRGB, bit 9 nearest).
        pub info: [u32; 4] => "uvec4",
    }
}

gpu_struct! {
    /// An emissive triangle in world space at the frame's time.
    pub struct GpuEmitter {
        /// Corner 0 (xyz) and area (w).
        pub p0: [f32; 4] => "vec4",
        /// Corner 1 (xyz).
        pub p1: [f32; 4] => "vec4",
        /// Corner 2 (xyz).
        pub p2: [f32; 4] => "vec4",
        /// Radiance factor (rgb, before textures) and two-sidedness (w: 1 or 0).
        pub radiance: [f32; 4] => "vec4",
        /// Texture coordinates (TEXCOORD_0) of corners 0 (xy) and 1 (zw).
        pub uvs: [f32; 4] => "vec4",
        /// Texture coordinates of corner 2 (xy), material index (z, exact in f32), unused (w).
        pub uv2_material: [f32; 4] => "vec4",
        /// TEXCOORD_1 of corners 0 (xy) and 1 (zw); zero unless the scene keeps TEXCOORD_1.
        pub uvs1: [f32; 4] => "vec4",
        /// TEXCOORD_1 of corner 2 (xy); unused (zw).
        pub uv1_2: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// One entry of an alias table (Walker/Vose).
    pub struct GpuAlias {
        /// Probability of keeping this entry.
        pub prob: f32 => "float",
        /// The entry taken otherwise.
        pub alias: u32 => "uint",
        /// Probability mass of this entry.
        pub pmf: f32 => "float",
        /// Unused.
        pub pad: u32 => "uint",
    }
}

gpu_struct! {
    /// A punctual light (KHR_lights_punctual units).
    pub struct GpuLight {
        /// World position (xyz) and type (w: 0 point, 1 spot, 2 directional).
        pub position: [f32; 4] => "vec4",
        /// World direction the light points to (xyz) and range (w; 0 = infinite).
        pub direction: [f32; 4] => "vec4",
        /// Colour × intensity (candela for point/spot, lux for directional).
        pub intensity: [f32; 4] => "vec4",
        /// Spot cone: angle scale, angle offset (glTF's falloff), unused, unused.
        pub spot: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// Per-frame constants.
    pub struct FrameConstants {
        /// World to clip (Vulkan clip space: y down; reversed depth, 1 at the near plane).
        pub clip_from_world: [[f32; 4]; 4] => "mat4",
        /// Clip to world.
        pub world_from_clip: [[f32; 4]; 4] => "mat4",
        /// Camera position (xyz), scene scale (w: bounding-box diagonal, for epsilons).
        pub camera_position: [f32; 4] => "vec4",
        /// Constant environment radiance (rgb) and scale of the environment map (w).
        pub environment: [f32; 4] => "vec4",
        /// Width, height, frame index, random seed.
        pub resolution: [u32; 4] => "uvec4",
        /// Emitter count, light count, instance count, environment map width (0 = none).
        pub counts: [u32; 4] => "uvec4",
        /// Total emitted power of the emitters, env map height, unused, unused.
        pub totals: [f32; 4] => "vec4",
    }
}

gpu_struct! {
    /// An irradiance record (docs/irradiance-cache.md §2.6), 176 bytes. Gradients are world-space
    /// tangent vectors, one per colour channel.
    pub struct GpuRecord {
        /// Position `p_i` (xyz) and the radius used by the weight, `R_i = clamp(R_orig, R⁻, R⁺)` (w).
        pub position_radius: [f32; 4] => "vec4",
        /// Unit normal `n_i` (xyz) and the unclamped radius `R_orig` (w), kept for neighbour clamping.
        pub normal_rorig: [f32; 4] => "vec4",
        /// Irradiance `E_i` (rgb) and the translational-gradient attenuation `min(1, R/R⁻)` (w).
        pub irradiance: [f32; 4] => "vec4",
        /// `R⁻` (x), `R⁺` (y), pixel footprint at creation (z), harmonic-mean distance (w).
        pub bounds: [f32; 4] => "vec4",
        /// Rotational gradient of the red channel (xyz); x of the geometric normal at creation
        /// (w; with the next two, what a refresh in place needs to draw the same rays again).
        pub grad_r_red: [f32; 4] => "vec4",
        /// Rotational gradient of the green channel (xyz); y of the geometric normal (w).
        pub grad_r_green: [f32; 4] => "vec4",
        /// Rotational gradient of the blue channel (xyz); z of the geometric normal (w).
        pub grad_r_blue: [f32; 4] => "vec4",
        /// Translational gradient of the red channel (xyz).
        pub grad_t_red: [f32; 4] => "vec4",
        /// Translational gradient of the green channel (xyz).
        pub grad_t_green: [f32; 4] => "vec4",
        /// Translational gradient of the blue channel (xyz).
        pub grad_t_blue: [f32; 4] => "vec4",
        /// Pixel index it was created at (x), creation level (y), sub-frame (z), flags (w).
        pub info: [u32; 4] => "uvec4",
    }
}

gpu_struct! {
    /// `VkDispatchIndirectCommand` (x, y, z) padded to 16 bytes.
    pub struct DispatchArgs {
        /// Workgroups along x.
        pub x: u32 => "uint",
        /// Workgroups along y.
        pub y: u32 => "uint",
        /// Workgroups along z.
        pub z: u32 => "uint",
        /// Unused (keeps the next field 16-byte aligned).
        pub pad: u32 => "uint",
    }
}

gpu_struct! {
    /// `VkDrawIndirectCommand`.
    pub struct DrawArgs {
        /// Vertices per instance.
        pub vertex_count: u32 => "uint",
        /// Instances.
        pub instance_count: u32 => "uint",
        /// First vertex.
        pub first_vertex: u32 => "uint",
        /// First instance (`gl_InstanceIndex` starts here).
        pub first_instance: u32 => "uint",
    }
}

impl DispatchArgs {
    /// `n` workgroups along x.
    pub const fn groups(n: u32) -> DispatchArgs {
        DispatchArgs {
            x: n,
            y: 1,
            z: 1,
            pad: 0,
        }
    }
}

impl DrawArgs {
    /// Vertices of one splat quad (two triangles).
    pub const QUAD_VERTICES: u32 = crate::consts::QUAD_VERTICES;

    /// `count` quads (one instance each) from instance `first`.
    pub const fn quads(count: u32, first: u32) -> DrawArgs {
        DrawArgs {
            vertex_count: Self::QUAD_VERTICES,
            instance_count: count,
            first_vertex: 0,
            first_instance: first,
        }
    }
}

gpu_struct! {
    /// Counters and indirect arguments of the irradiance cache, written by the GPU
    /// (`shaders/passes/ic_counters.comp` moves them from step to step).
    pub struct IcCounters {
        /// Records in the record buffer.
        pub record_count: u32 => "uint",
        /// Requests appended by the hole selection since the level began.
        pub requested: u32 => "uint",
        /// First record of the pending batch.
        pub batch_first: u32 => "uint",
        /// Hole pixels found by the last selection.
        pub holes: u32 => "uint",
        /// The record pass's indirect dispatch: one workgroup per request that fits.
        pub dispatch: DispatchArgs => struct,
        /// The splat of every record: one quad per record.
        pub draw: DrawArgs => struct,
        /// Record capacity.
        pub record_capacity: u32 => "uint",
        /// Request capacity of one batch.
        pub request_capacity: u32 => "uint",
        /// Requests dropped for lack of room (record or request capacity).
        pub dropped_requests: u32 => "uint",
        /// Records rejected as invalid (stored as black).
        pub rejected_records: u32 => "uint",
        /// The splat of the last batch only: one quad per record of the batch from its first
        /// record (no instance before a batch ends, none after a level that created nothing).
        pub batch_draw: DrawArgs => struct,
        /// Records whose used radius neighbour clamping lowered after they had been splatted
        /// into a coverage (outside the batch being clamped): a running count, compared before
        /// and after a cache pass (wraps).
        pub radii_shrunk: u32 => "uint",
    }
}

impl IcCounters {
    /// The counters after a reset (`CounterStep::Reset` in `shaders/passes/ic_counters.comp`): no
    /// records, no requests, nothing dropped, empty draws.
    pub const fn reset(record_capacity: u32, request_capacity: u32) -> IcCounters {
        IcCounters {
            record_count: 0,
            requested: 0,
            batch_first: 0,
            holes: 0,
            dispatch: DispatchArgs::groups(0),
            draw: DrawArgs::quads(0, 0),
            record_capacity,
            request_capacity,
            dropped_requests: 0,
            rejected_records: 0,
            batch_draw: DrawArgs::quads(0, 0),
            radii_shrunk: 0,
        }
    }
}

gpu_struct! {
    /// A record's temporal state (temporal radiance caching, docs/temporal.md §3.1), 96 bytes, kept
    /// beside its `GpuRecord` (same index). The record lives on its mesh instance: its point and
    /// normals are stored in the instance's object space and moved with it every frame.
    pub struct GpuRecordTemporal {
        /// Object-space position (xyz); lifespan `Δt_i` in frames (w).
        pub object_position: [f32; 4] => "vec4",
        /// Object-space shading normal (xyz); unused (w).
        pub object_normal: [f32; 4] => "vec4",
        /// Object-space geometric normal (xyz); unused (w).
        pub object_geometric: [f32; 4] => "vec4",
        /// The newest known irradiance `E_k` (rgb, exact at frame `t_k`); the share of the
        /// record's cosine-weighted hemisphere that the other moving instances covered then (w,
        /// the motion-aware expiry's reference, docs/temporal.md §3).
        pub birth_irradiance: [f32; 4] => "vec4",
        /// Rate `∂E_i/∂t` per frame over the span between the last two evaluations (rgb); that
        /// span in frames (w).
        pub gradient: [f32; 4] => "vec4",
        /// Instance (x), frame `t_k` of the newest known value (y), flags (z: bit 0 = adopted,
        /// `TEMPORAL_FLAG_ADOPTED`), unused (w).
        pub info: [u32; 4] => "uvec4",
    }
}

/// Every shared struct's GLSL, in dependency order, with the generated-file header.
pub fn generated_glsl() -> String {
    use crate::layout::glsl_struct;
    let mut s = String::from(
        "// Generated by `cargo xtask codegen` from crates/radcache-shared/src/gpu.rs. Do not edit.\n\
         #ifndef RADCACHE_SHARED_LAYOUTS_GLSL\n#define RADCACHE_SHARED_LAYOUTS_GLSL\n\n",
    );
    for text in [
        glsl_struct::<GpuVertex>(),
        glsl_struct::<GpuMesh>(),
        glsl_struct::<GpuInstance>(),
        glsl_struct::<GpuUvMap>(),
        glsl_struct::<GpuMaterial>(),
        glsl_struct::<GpuTexture>(),
        glsl_struct::<GpuEmitter>(),
        glsl_struct::<GpuAlias>(),
        glsl_struct::<GpuLight>(),
        glsl_struct::<FrameConstants>(),
        glsl_struct::<GpuRecord>(),
        glsl_struct::<DispatchArgs>(),
        glsl_struct::<DrawArgs>(),
        glsl_struct::<IcCounters>(),
        glsl_struct::<GpuRecordTemporal>(),
    ] {
        s.push_str(&text);
        s.push('\n');
    }
    s.push_str("#endif\n");
    s
}

/// One record's block of the radiance buffer (`consts::RECORD_RADIANCE_VEC4S` uvec4, 512
/// bytes, docs/radiance-caching.md §7.2): its SH coefficients as f32 bits, the gradients' scale
/// and the f16-packed translational gradients, as the record pass writes them. The host moves
/// blocks as opaque words (compaction, cache files).
pub type RadianceBlock = [[u32; 4]; crate::consts::RECORD_RADIANCE_VEC4S as usize];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::std430_violations;

    #[test]
    fn every_struct_matches_std430() {
        let mut errors = Vec::new();
        errors.extend(std430_violations::<GpuVertex>());
        errors.extend(std430_violations::<GpuMesh>());
        errors.extend(std430_violations::<GpuInstance>());
        errors.extend(std430_violations::<GpuUvMap>());
        errors.extend(std430_violations::<GpuMaterial>());
        errors.extend(std430_violations::<GpuTexture>());
        errors.extend(std430_violations::<GpuEmitter>());
        errors.extend(std430_violations::<GpuAlias>());
        errors.extend(std430_violations::<GpuLight>());
        errors.extend(std430_violations::<FrameConstants>());
        errors.extend(std430_violations::<GpuRecord>());
        errors.extend(std430_violations::<DispatchArgs>());
        errors.extend(std430_violations::<DrawArgs>());
        errors.extend(std430_violations::<IcCounters>());
        errors.extend(std430_violations::<GpuRecordTemporal>());
        assert_eq!(std::mem::size_of::<GpuRecord>(), 176);
        assert_eq!(std::mem::size_of::<GpuRecordTemporal>(), 96);
        assert_eq!(std::mem::size_of::<IcCounters>(), 84);
        assert_eq!(std::mem::size_of::<GpuMaterial>(), 240);
        assert_eq!(std::mem::size_of::<GpuEmitter>(), 128);
        assert!(errors.is_empty(), "{}", errors.join("\n"));
    }

    #[test]
    fn a_misaligned_struct_is_caught() {
        gpu_struct! {
            /// A float followed by a vec4: std430 puts the vec4 at 16, Rust at 4.
            pub struct Bad {
                /// A scalar.
                pub a: f32 => "float",
                /// A vector.
                pub b: [f32; 4] => "vec4",
            }
        }
        let errors = std430_violations::<Bad>();
        assert!(errors.iter().any(|e| e.contains("Bad.b")), "{errors:?}");
    }

    #[test]
    fn generated_glsl_is_up_to_date() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../shaders/shared/layouts.glsl"
        );
        let on_disk = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            on_disk == generated_glsl(),
            "shaders/shared/layouts.glsl is stale: run `cargo xtask codegen`"
        );
    }
}
