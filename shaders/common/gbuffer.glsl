// common/gbuffer.glsl: the G-buffer of crates/radcache-render/src/passes/gbuffer.rs as compute
// and fragment passes read it: storage images at B_GBUFFER_* (crates/radcache-render/src/bindings/mod.rs).
//
//   +0 position   xyz world position of the first hit; w = 1 on a surface, 0 on the background,
//                 −1 where per-pixel adaptive anti-aliasing has stopped the pixel (no sample in
//                 this sub-frame: docs/cache-frame.md §7.2; the other images are then stale)
//   +1 normal     xyz unit shading normal, turned toward the camera; w = pixel footprint (world
//                 size of one pixel at the point, ircache_math.glsl `pixel_footprint`)
//   +2 geometric  xyz unit geometric normal, turned toward the camera; w = material index
//   +3 albedo     rgb diffuse albedo (base colour × (1 − metallic), textured; with HAS_SPECULAR
//                 the textured base colour); w = the mesh instance (custom index; exact as a
//                 float below 2^24)
//   +4 emission   rgb radiance emitted toward the camera (front/back rule applied); w = 0, with
//                 HAS_SPECULAR metallic and roughness (common/gbuffer_pack.glsl)
//   +5 direct     rgb direct light reflected toward the camera (albedo/π × NEE, MIS; with
//                 HAS_SPECULAR the full BRDF's, plus the specular lobe's indirect light); w = 0
//
// Pass-specific resources start at B_GBUFFER_END (generated with the rest).
#ifndef RADCACHE_GBUFFER_GLSL
#define RADCACHE_GBUFFER_GLSL

#include "../shared/bindings.glsl"
#include "gbuffer_pack.glsl"

#ifndef GBUFFER_DIRECT_ACCESS
#define GBUFFER_DIRECT_ACCESS readonly
#endif

layout(binding = B_GBUFFER_POSITION, rgba32f) readonly uniform image2D g_position;
layout(binding = B_GBUFFER_NORMAL, rgba32f) readonly uniform image2D g_normal;
layout(binding = B_GBUFFER_GEOMETRIC, rgba32f) readonly uniform image2D g_geometric;
layout(binding = B_GBUFFER_ALBEDO, rgba32f) readonly uniform image2D g_albedo;
layout(binding = B_GBUFFER_EMISSION, rgba32f) readonly uniform image2D g_emission;
layout(binding = B_GBUFFER_DIRECT, rgba32f) GBUFFER_DIRECT_ACCESS uniform image2D g_direct;

struct GSample {
    bool surface;
    bool stopped;      // no sample in this sub-frame (position w = −1); `surface` is false
    vec3 position;
    vec3 normal;       // shading, toward the camera
    float footprint;   // world size of one pixel at `position`
    vec3 geometric;    // toward the camera
    uint material;
    uint instance;     // mesh instance (custom index)
    vec3 albedo;       // with HAS_SPECULAR: the base colour
    vec3 emission;
#ifdef HAS_SPECULAR
    float metallic;
    float roughness;
#endif
};

GSample gbuffer_load(ivec2 pixel) {
    vec4 p = imageLoad(g_position, pixel);
    vec4 n = imageLoad(g_normal, pixel);
    vec4 g = imageLoad(g_geometric, pixel);
    GSample s;
    s.surface = p.w > 0.5;
    s.stopped = p.w < -0.5;
    s.position = p.xyz;
    s.normal = n.xyz;
    s.footprint = n.w;
    s.geometric = g.xyz;
    s.material = uint(max(g.w, 0.0));
    vec4 a = imageLoad(g_albedo, pixel);
    s.albedo = a.rgb;
    s.instance = uint(max(a.w, 0.0));
    vec4 e = imageLoad(g_emission, pixel);
    s.emission = e.rgb;
#ifdef HAS_SPECULAR
    vec2 mr = gbuffer_unpack_metallic_roughness(e.w);
    s.metallic = mr.x;
    s.roughness = mr.y;
#endif
    return s;
}

#if defined(HAS_SPECULAR) && defined(RADCACHE_SCENE_GLSL)
// The BRDF parameters of a G-buffer sample: its base colour, metallic and roughness (textured,
// from the G-buffer), its material's index of refraction and specular layer.
Material gbuffer_material(GSample g) {
    GpuMaterial mat = materials[g.material];
    return Material(g.albedo, g.metallic, g.roughness, max(mat.params.w, 1.0),
                    clamp(mat.specular.w, 0.0, 1.0), max(mat.specular.rgb, vec3(0.0)));
}
#endif

#endif
