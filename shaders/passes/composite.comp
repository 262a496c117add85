// passes/composite.comp — Rust: crates/radcache-render/src/passes/composite.rs
// Composite of one sub-frame (docs/cache-frame.md §6.4 normalisation): on surfaces
// L = direct + albedo/π · Σw·Ẽ / Σw (0 where no record reaches the pixel; with HAS_SPECULAR the
// albedo is the base colour times the diffuse lobe's share), on the background the
// environment along the camera ray; added with weight 1 to the frame accumulator (a = sub-frames
// so far). The emission seen at the sub-frame's sample goes to a separate accumulator: the
// emission pass replaces it by a finely supersampled box filter where emitters have edges.
// A non-finite value is dropped and counted. With IC_AA_MOMENTS (adaptive anti-aliasing,
// docs/cache-frame.md §7.1) the squares of the sub-frame's radiance go to a second accumulator, from
// which the host estimates the sampling error of the mean (radcache_render::frame::aa).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/path.glsl"
#include "../common/gbuffer.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = B_COMPOSITE_SPLAT_SUM, rgba32f) readonly uniform image2D splat_sum;
layout(binding = B_COMPOSITE_ACCUM, std430) buffer Accum { vec4 accum[]; };
layout(binding = B_COMPOSITE_NONFINITE, std430) buffer Bad { uint nonfinite; };
layout(binding = B_COMPOSITE_EMISSION_ACCUM, std430) buffer EmissionAccum { vec4 emission_accum[]; };
// Debug AOVs, two vec4 per pixel: indirect radiance (rgb) and Σw (a); records per pixel (x).
layout(binding = B_COMPOSITE_DEBUG_ACCUM, std430) buffer DebugAccum { vec4 debug_accum[]; };
layout(binding = B_COMPOSITE_SPLAT_COUNT, r32f) readonly uniform image2D splat_count;

#ifdef IC_AA_MOMENTS
layout(binding = B_COMPOSITE_ACCUM_SQ, std430) buffer AccumSq { vec4 accum_sq[]; };
#endif

layout(push_constant) uniform Push { CompositePush pc; };

#ifdef HAS_RADIANCE_CACHE
// Σw·L_glossy (rgb), Σw (a): the glossy splat (passes/splat_glossy.frag; pc.glossy set).
layout(binding = B_COMPOSITE_GLOSSY_SUM, rgba32f) readonly uniform image2D glossy_sum;
#endif

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, ivec2(frame.resolution.xy)))) {
        return;
    }
    uint index = uint(pixel.y) * frame.resolution.x + uint(pixel.x);
    GSample g = gbuffer_load(pixel);
    vec3 l;
    vec3 emitted = vec3(0.0);
    if (g.surface) {
        vec4 s = imageLoad(splat_sum, pixel);
        vec3 e = s.a > 0.0 ? s.rgb / s.a : vec3(0.0);
#ifdef HAS_SPECULAR
        // The cached irradiance lights the diffuse lobe alone, weighted by its share for this
        // view direction (docs/materials.md §6); the direct pass adds the specular lobe's light.
        vec3 to_camera = normalize(frame.camera_position.xyz - g.position);
        float share = diffuse_share(gbuffer_material(g), dot(g.normal, to_camera));
        vec3 indirect = g.albedo * (share * INV_PI) * e;
#else
        vec3 indirect = g.albedo * INV_PI * e;
#endif
#ifdef HAS_RADIANCE_CACHE
        // The specular lobe's indirect light from the radiance records, where the glossy splat
        // reached the pixel (its lobe rough enough: docs/radiance-caching.md §6.2); clamped at 0
        // as a truncated SH product can dip below it.
        if (pc.glossy != 0u) {
            vec4 gs = imageLoad(glossy_sum, pixel);
            if (gs.a > 0.0) {
                indirect += max(gs.rgb / gs.a, vec3(0.0));
            }
        }
#endif
        l = imageLoad(g_direct, pixel).rgb + indirect;
        emitted = g.emission;
        if (pc.debug != 0u && !any(isnan(indirect)) && !any(isinf(indirect))) {
            debug_accum[2u * index] += vec4(indirect, s.a);
            debug_accum[2u * index + 1u].x += imageLoad(splat_count, pixel).r;
        }
    } else {
        Ray r = camera_ray(uvec2(pixel), vec2(0.5) + pc.jitter);
        l = environment_radiance(r.dir);
    }
    if (any(isnan(l)) || any(isinf(l))) {
        l = vec3(0.0);
        atomicAdd(nonfinite, 1u);
    }
    if (any(isnan(emitted)) || any(isinf(emitted))) {
        emitted = vec3(0.0);
        atomicAdd(nonfinite, 1u);
    }
    accum[index] += vec4(l, 1.0);
#ifdef IC_AA_MOMENTS
    accum_sq[index] += vec4(l * l, 0.0);
#endif
    emission_accum[index] += vec4(emitted, 1.0);
}
