// common/scene.glsl — Rust: crates/radcache-render/src/scene/mod.rs
// The scene as every scene-reading pass sees it: bindings 0-15 (see shared/bindings.glsl),
// surface reconstruction at a ray-query hit, materials, textures and emission, and the traversal
// every ray query of the passes goes through (scene_trace, with the alpha test under HAS_ALPHA). With
// HAS_NORMAL_MAPS, the vertex tangents and the normal maps (common/normal_map.glsl). Every texture
// lookup takes its coordinates from its reference's GpuUvMap (texture_uv): TEXCOORD_1 with
// HAS_TEXCOORD1, KHR_texture_transform with HAS_UV_TRANSFORM (docs/materials.md §13); without
// them every lookup samples TEXCOORD_0 as it is.
#ifndef RADCACHE_SCENE_GLSL
#define RADCACHE_SCENE_GLSL

#extension GL_EXT_ray_query : require
#extension GL_EXT_nonuniform_qualifier : enable

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "sampling.glsl"

layout(binding = B_FRAME) uniform Frame { FrameConstants frame; };
layout(binding = B_TLAS) uniform accelerationStructureEXT tlas;
layout(binding = B_VERTICES, std430) readonly buffer Vertices { GpuVertex vertices[]; };
layout(binding = B_INDICES, std430) readonly buffer Indices { uint indices[]; };
layout(binding = B_INSTANCES, std430) readonly buffer Instances { GpuInstance instances[]; };
layout(binding = B_TRI_MATERIALS, std430) readonly buffer TriMaterials { uint tri_materials[]; };
layout(binding = B_MATERIALS, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(binding = B_TEXTURES, std430) readonly buffer Textures { GpuTexture textures[]; };
layout(binding = B_TEXELS, std430) readonly buffer Texels { uint texels[]; };
layout(binding = B_EMITTERS, std430) readonly buffer Emitters { GpuEmitter emitters[]; };
layout(binding = B_EMITTER_ALIAS, std430) readonly buffer EmitterAlias { GpuAlias emitter_alias[]; };
layout(binding = B_LIGHTS, std430) readonly buffer Lights { GpuLight lights[]; };
layout(binding = B_ENV_TEXELS, std430) readonly buffer EnvTexels { vec4 env_texels[]; };
layout(binding = B_ENV_ALIAS, std430) readonly buffer EnvAlias { GpuAlias env_alias[]; };
#ifdef HAS_TEXCOORD1
layout(binding = B_TEXCOORDS1, std430) readonly buffer Texcoords1 { vec2 texcoords1[]; };
#endif

// The texture coordinates of a point: TEXCOORD_0, with HAS_TEXCOORD1 followed by TEXCOORD_1
// (zw). Interpolated like any vector; a lookup picks its set in texture_uv.
#ifdef HAS_TEXCOORD1
#define TexCoords vec4
#else
#define TexCoords vec2
#endif

// The texture coordinates of vertex v (global index i).
TexCoords vertex_texcoords(GpuVertex v, uint i) {
#ifdef HAS_TEXCOORD1
    return vec4(v.position_u.w, v.normal_v.w, texcoords1[i]);
#else
    return vec2(v.position_u.w, v.normal_v.w);
#endif
}

// Where a texture reference samples at a point of coordinates uv (GpuUvMap, docs/materials.md
// §13): its set (row_u.w), then its KHR_texture_transform T·R·S as two rows,
// uv' = (row_u·(u, v, 1), row_v·(u, v, 1)).
vec2 texture_uv(GpuUvMap map, TexCoords uv) {
#ifdef HAS_TEXCOORD1
    vec2 t = map.row_u.w != 0.0 ? uv.zw : uv.xy;
#else
    vec2 t = uv;
#endif
#ifdef HAS_UV_TRANSFORM
    vec3 h = vec3(t, 1.0);
    t = vec2(dot(map.row_u.xyz, h), dot(map.row_v.xyz, h));
#endif
    return t;
}

#ifdef HAS_NORMAL_MAPS
#include "normal_map.glsl"
layout(binding = B_TANGENTS, std430) readonly buffer Tangents { vec4 tangents[]; };

vec4 texture_sample(int index, vec2 uv);

// An object-space tangent in world space: xyz by the instance's linear part, w (handedness)
// flipped by a mirroring transform, as the bitangent n × t is.
vec4 world_tangent(GpuInstance inst, vec4 t) {
    vec3 xyz = (inst.world_from_object * vec4(t.xyz, 0.0)).xyz;
    return vec4(xyz, inst.normal_to_world[3][3] < 0.0 ? -t.w : t.w);
}

// The shading normal of material m at uv (docs/materials.md §12) from the unit interpolated
// normal n, the unit geometric normal ng (both outward) and the world tangent: n itself where the
// material has no normal map or the primitive no tangents (w = 0).
vec3 material_shading_normal(uint m, TexCoords uv, vec4 tangent, vec3 n, vec3 ng) {
    vec4 map = materials[m].normal_map;
    if (map.x < 0.0 || tangent.w == 0.0) {
        return n;
    }
    vec3 texel = texture_sample(int(map.x), texture_uv(materials[m].normal_uv, uv)).rgb;
    return normal_map_normal(n, ng, tangent, texel, map.y);
}
#endif

// A reconstructed surface point.
struct Surface {
    vec3 position;
    vec3 geometric_normal;  // unit, facing the incoming ray
    vec3 shading_normal;    // unit, on the same side as geometric_normal
    TexCoords uv;
    uint material;
    bool front_face;        // the ray hit the counter-clockwise (front) side
};

// Offsets a ray origin off a surface along its geometric normal by a few ulps of the position's
// magnitude (Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray
// Tracing Gems, 2019). Near the origin, where ulps vanish, the method switches to a fixed offset;
// its constants (below 1/32 → 1/65536) assume a scene of size about 1, so here both are scaled by
// the scene scale (frame.camera_position.w, the bounding-box diagonal): in the Cornell box scaled
// by 1e-3 the fixed 1/65536 was 3 % of the box, lifted shadow-ray origins past the light's 3 µm
// gap under the ceiling and darkened the image by 18 % (stiff suite, `cornell_1e-3`).
vec3 offset_ray_origin(vec3 p, vec3 n) {
    float scale = frame.camera_position.w > 0.0 ? frame.camera_position.w : 1.0;
    float origin = scale / 32.0;
    float float_scale = scale / 65536.0;
    const float INT_SCALE = 256.0;
    ivec3 of_i = ivec3(INT_SCALE * n);
    vec3 p_i = vec3(intBitsToFloat(floatBitsToInt(p.x) + (p.x < 0.0 ? -of_i.x : of_i.x)),
                    intBitsToFloat(floatBitsToInt(p.y) + (p.y < 0.0 ? -of_i.y : of_i.y)),
                    intBitsToFloat(floatBitsToInt(p.z) + (p.z < 0.0 ? -of_i.z : of_i.z)));
    return vec3(abs(p.x) < origin ? p.x + float_scale * n.x : p_i.x,
                abs(p.y) < origin ? p.y + float_scale * n.y : p_i.y,
                abs(p.z) < origin ? p.z + float_scale * n.z : p_i.z);
}

// Surface at a committed triangle hit of instance `instance` (custom index), primitive `prim`,
// barycentrics `bary`, for a ray travelling along `dir`.
Surface surface_at(uint instance, uint prim, vec2 bary, vec3 dir) {
    GpuInstance inst = instances[instance];
    uint first_vertex = inst.mesh.y;
    uint first_index = inst.mesh.z + 3u * prim;
    uint i0 = indices[first_index] + first_vertex;
    uint i1 = indices[first_index + 1u] + first_vertex;
    uint i2 = indices[first_index + 2u] + first_vertex;
    GpuVertex v0 = vertices[i0];
    GpuVertex v1 = vertices[i1];
    GpuVertex v2 = vertices[i2];
    vec3 w = vec3(1.0 - bary.x - bary.y, bary.x, bary.y);
    vec3 p_obj = w.x * v0.position_u.xyz + w.y * v1.position_u.xyz + w.z * v2.position_u.xyz;
    vec3 n_obj = w.x * v0.normal_v.xyz + w.y * v1.normal_v.xyz + w.z * v2.normal_v.xyz;
    vec3 e1 = (inst.world_from_object * vec4(v1.position_u.xyz - v0.position_u.xyz, 0.0)).xyz;
    vec3 e2 = (inst.world_from_object * vec4(v2.position_u.xyz - v0.position_u.xyz, 0.0)).xyz;

    Surface s;
    s.position = (inst.world_from_object * vec4(p_obj, 1.0)).xyz;
    vec3 ng = cross(e1, e2);
    float len = length(ng);
    ng = len > 0.0 ? ng / len : vec3(0.0, 0.0, 1.0);
    // A mirroring instance transform (w.w < 0) turns counter-clockwise into clockwise: glTF keeps
    // the front face on the side the transformed normals point to.
    if (inst.normal_to_world[3][3] < 0.0) {
        ng = -ng;
    }
    s.front_face = dot(ng, dir) < 0.0;
    s.geometric_normal = s.front_face ? ng : -ng;
    vec3 ns = (inst.normal_to_world * vec4(n_obj, 0.0)).xyz;
    float ns_len = length(ns);
    ns = (ns_len > 0.0 && !isnan(ns_len)) ? ns / ns_len : ng;
    s.uv = w.x * vertex_texcoords(v0, i0) + w.y * vertex_texcoords(v1, i1) +
           w.z * vertex_texcoords(v2, i2);
    s.material = tri_materials[inst.mesh.w + prim];
#ifdef HAS_NORMAL_MAPS
    // The map acts on the outward normals (the flip below turns its result with them); the
    // handedness is the first corner's, as the G-buffer's flat varying has it.
    vec3 t_obj = w.x * tangents[i0].xyz + w.y * tangents[i1].xyz + w.z * tangents[i2].xyz;
    vec4 tangent = world_tangent(inst, vec4(t_obj, tangents[i0].w));
    ns = material_shading_normal(s.material, s.uv, tangent, ns, ng);
#endif
    if (!s.front_face) {
        ns = -ns;
    }
    // A shading normal on the far side of the geometric one (inward-facing vertex normals, or
    // interpolation across a crease) would send rays into the surface: fall back.
    s.shading_normal = dot(ns, s.geometric_normal) > 0.0 ? ns : s.geometric_normal;
    return s;
}

// One texel of texture `tex` (integer coordinates already wrapped), linear RGBA.
vec4 texel_fetch(GpuTexture tex, int x, int y) {
    uint v = texels[tex.info.x + uint(y) * tex.info.y + uint(x)];
    vec4 c = unpackUnorm4x8(v);
    if ((tex.info.w & 0x100u) != 0u) {
        // sRGB EOTF (IEC 61966-2-1).
        bvec3 lo = lessThanEqual(c.rgb, vec3(0.04045));
        c.rgb = mix(pow((c.rgb + 0.055) / 1.055, vec3(2.4)), c.rgb / 12.92, lo);
    }
    return c;
}

// Wraps integer coordinate i into [0, n) with glTF wrap mode (0 repeat, 1 clamp, 2 mirror).
int wrap_coord(int i, int n, uint mode) {
    if (mode == 1u) {
        return clamp(i, 0, n - 1);
    }
    if (mode == 2u) {
        int period = 2 * n;
        int m = ((i % period) + period) % period;
        return m < n ? m : period - 1 - m;
    }
    return ((i % n) + n) % n;
}

// Bilinear texture lookup with the texture's wrap modes; the texel uv falls in where the sampler's
// magFilter is NEAREST (flag bit 9).
vec4 texture_sample(int index, vec2 uv) {
    GpuTexture tex = textures[index];
    int w = int(tex.info.y);
    int h = int(tex.info.z);
    if ((tex.info.w & 0x200u) != 0u) {
        ivec2 t = ivec2(floor(uv * vec2(w, h)));
        return texel_fetch(tex, wrap_coord(t.x, w, tex.info.w & 0xFu),
                           wrap_coord(t.y, h, (tex.info.w >> 4u) & 0xFu));
    }
    vec2 p = uv * vec2(w, h) - 0.5;
    ivec2 i = ivec2(floor(p));
    vec2 f = p - vec2(i);
    uint ws = tex.info.w & 0xFu;
    uint wt = (tex.info.w >> 4u) & 0xFu;
    int x0 = wrap_coord(i.x, w, ws), x1 = wrap_coord(i.x + 1, w, ws);
    int y0 = wrap_coord(i.y, h, wt), y1 = wrap_coord(i.y + 1, h, wt);
    vec4 a = mix(texel_fetch(tex, x0, y0), texel_fetch(tex, x1, y0), f.x);
    vec4 b = mix(texel_fetch(tex, x0, y1), texel_fetch(tex, x1, y1), f.x);
    return mix(a, b, f.y);
}

// Diffuse albedo: base colour × (1 − metallic).
vec3 material_albedo(uint m, TexCoords uv) {
    GpuMaterial mat = materials[m];
    vec3 base = mat.base_color.rgb;
    if (mat.textures.x >= 0) {
        base *= texture_sample(mat.textures.x, texture_uv(mat.base_color_uv, uv)).rgb;
    }
    return clamp(base * (1.0 - mat.params.x), 0.0, 1.0);
}

#ifdef HAS_SPECULAR
#include "brdf.glsl"

// The metallic-roughness BRDF parameters of material m at uv (docs/materials.md §1): factors ×
// textures (base colour sRGB, metallic from the blue and roughness from the green channel of the
// metallic-roughness texture), clamped to their ranges.
Material material_at(uint m, TexCoords uv) {
    GpuMaterial mat = materials[m];
    vec3 base = mat.base_color.rgb;
    if (mat.textures.x >= 0) {
        base *= texture_sample(mat.textures.x, texture_uv(mat.base_color_uv, uv)).rgb;
    }
    float metallic = mat.params.x;
    float roughness = mat.params.y;
    if (mat.textures.z >= 0) {
        vec4 mr = texture_sample(mat.textures.z, texture_uv(mat.metallic_roughness_uv, uv));
        roughness *= mr.g;
        metallic *= mr.b;
    }
    return Material(clamp(base, 0.0, 1.0), clamp(metallic, 0.0, 1.0), clamp(roughness, 0.0, 1.0),
                    max(mat.params.w, 1.0), clamp(mat.specular.w, 0.0, 1.0),
                    max(mat.specular.rgb, vec3(0.0)));
}
#endif

#ifdef HAS_ALPHA
#include "hash.glsl"
#include "../shared/constants.glsl"

// The alpha test of a material (GpuMaterial.textures.w; crates/radcache-render/src/scene/pack.rs):
// ALPHA_NONE, ALPHA_MASK or ALPHA_BLEND (constants.glsl, from radcache_shared::consts).

// Alpha of material `mat` at uv: base colour factor alpha × base colour texture alpha (bilinear,
// at the base colour reference's coordinates).
float material_alpha(GpuMaterial mat, TexCoords uv) {
    float a = mat.base_color.a;
    if (mat.textures.x >= 0) {
        a *= texture_sample(mat.textures.x, texture_uv(mat.base_color_uv, uv)).a;
    }
    return a;
}

// Whether the point at uv of material m, on primitive `prim` of instance `instance`, is there for
// the ray or fragment that `seed` names (docs/materials.md §11): MASK when alpha ≥ the cutoff;
// BLEND when a uniform number hashed from the seed, the instance and the primitive is below alpha
// (probability alpha; the same answer every time the same ray meets the same triangle).
bool alpha_keep(uint m, TexCoords uv, uint instance, uint prim, uint seed) {
    GpuMaterial mat = materials[m];
    if (mat.textures.w == ALPHA_NONE) {
        return true;
    }
    float a = material_alpha(mat, uv);
    if (mat.textures.w == ALPHA_MASK) {
        return a >= mat.alpha.x;
    }
    return uint_to_unit_float(pcg_hash(seed ^ pcg_hash(prim ^ pcg_hash(instance)))) < a;
}

// The expected coverage of material m at uv: MASK 0 or 1, BLEND alpha, 1 without an alpha test
// (what light sampling of an emitter weighs its radiance by: the mean of what hits see).
float material_coverage(uint m, TexCoords uv) {
    GpuMaterial mat = materials[m];
    if (mat.textures.w == ALPHA_NONE) {
        return 1.0;
    }
    float a = material_alpha(mat, uv);
    if (mat.textures.w == ALPHA_MASK) {
        return a >= mat.alpha.x ? 1.0 : 0.0;
    }
    return clamp(a, 0.0, 1.0);
}

// The seed of a ray's BLEND tests: a hash of its origin and direction, so it is new for every
// sample's ray and the same for the same ray.
uint alpha_ray_seed(vec3 origin, vec3 dir) {
    uint h = pcg_hash(floatBitsToUint(origin.x));
    h = pcg_hash(h ^ floatBitsToUint(origin.y));
    h = pcg_hash(h ^ floatBitsToUint(origin.z));
    h = pcg_hash(h ^ floatBitsToUint(dir.x));
    h = pcg_hash(h ^ floatBitsToUint(dir.y));
    return pcg_hash(h ^ floatBitsToUint(dir.z));
}

// The alpha test of a candidate triangle hit of instance `instance` (custom index), primitive
// `prim`, barycentrics `bary`, for the ray that `seed` names.
bool alpha_passes(uint instance, uint prim, vec2 bary, uint seed) {
    uvec4 mesh = instances[instance].mesh;
    uint m = tri_materials[mesh.w + prim];
    if (materials[m].textures.w == ALPHA_NONE) {
        return true;  // an opaque material in a mesh that also has alpha-tested ones
    }
    uint first_index = mesh.z + 3u * prim;
    uint i0 = indices[first_index] + mesh.y;
    uint i1 = indices[first_index + 1u] + mesh.y;
    uint i2 = indices[first_index + 2u] + mesh.y;
    TexCoords uv = (1.0 - bary.x - bary.y) * vertex_texcoords(vertices[i0], i0) +
                   bary.x * vertex_texcoords(vertices[i1], i1) +
                   bary.y * vertex_texcoords(vertices[i2], i2);
    return alpha_keep(m, uv, instance, prim, seed);
}

// Without an alpha-tested material every ray query is opaque; with one, each BLAS geometry's own
// flag decides (crates/radcache-vk/src/accel.rs) and the non-opaque ones' candidates are tested.
const uint SCENE_RAY_FLAGS = gl_RayFlagsNoneEXT;
#else
const uint SCENE_RAY_FLAGS = gl_RayFlagsOpaqueEXT;
#endif

// Traces ray query q through the scene from `origin` along unit `dir` over [0, tmax], with ray
// flags SCENE_RAY_FLAGS | `flags`, to the end of its traversal. With HAS_ALPHA each candidate
// triangle is committed when it passes alpha_passes for `seed`. (A ray query parameter refers to
// the caller's object.)
void scene_trace_seeded(rayQueryEXT q, uint flags, vec3 origin, vec3 dir, float tmax, uint seed) {
    rayQueryInitializeEXT(q, tlas, SCENE_RAY_FLAGS | flags, 0xFF, origin, 0.0, dir, tmax);
    while (rayQueryProceedEXT(q)) {
#ifdef HAS_ALPHA
        uint kind = rayQueryGetIntersectionTypeEXT(q, false);
        if (kind == gl_RayQueryCandidateIntersectionTriangleEXT &&
            alpha_passes(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, false)),
                         uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, false)),
                         rayQueryGetIntersectionBarycentricsEXT(q, false), seed)) {
            rayQueryConfirmIntersectionEXT(q);
        }
#endif
    }
}

// scene_trace_seeded with the ray's own seed (alpha_ray_seed).
void scene_trace(rayQueryEXT q, uint flags, vec3 origin, vec3 dir, float tmax) {
#ifdef HAS_ALPHA
    uint seed = alpha_ray_seed(origin, dir);
#else
    uint seed = 0u;
#endif
    scene_trace_seeded(q, flags, origin, dir, tmax, seed);
}

// Emitted radiance toward the viewer: front face only, or both when double-sided.
vec3 material_emission(uint m, TexCoords uv, bool front_face) {
    GpuMaterial mat = materials[m];
    if (!front_face && mat.emission.w == 0.0) {
        return vec3(0.0);
    }
    vec3 e = mat.emission.rgb;
    if (mat.textures.y >= 0 && any(greaterThan(e, vec3(0.0)))) {
        e *= texture_sample(mat.textures.y, texture_uv(mat.emissive_uv, uv)).rgb;
    }
    return e;
}

#endif
