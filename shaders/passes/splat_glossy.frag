// passes/splat_glossy.frag — Rust: crates/radcache-render/src/passes/splat_glossy.rs
// Glossy splatting, per pixel (docs/radiance-caching.md §6.2): where the pixel's lobe is rough
// enough for the radiance records (roughness ≥ GLOSSY_ROUGHNESS_MIN; the others keep the direct
// pass's per-pixel specular paths), the record's weight at the pixel's G-buffer point (the same
// weight as splat.frag) times the radiance its SH coefficients reflect towards the camera,
// Σ_i c_i ⊙ W_i with the pixel's world weights W (written by the direct pass), added with w into
// the RGBA32F target by (ONE, ONE) blending. The coefficients carry no gradients yet.
#version 460
#extension GL_GOOGLE_include_directive : require

// The pass runs in specular scenes only, whose G-buffer holds the roughness.
#ifndef HAS_SPECULAR
#define HAS_SPECULAR 1
#endif

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../common/gbuffer.glsl"
#include "../common/ircache_math.glsl"
#include "splat_common.glsl"

layout(binding = B_SPLAT_GLOSSY_RADIANCE, std430) readonly buffer Radiance { vec4 radiance[]; };
layout(binding = B_SPLAT_GLOSSY_GLOSSY_WEIGHTS, std430) readonly buffer Weights { vec4 glossy_w[]; };

layout(location = 0) flat in uint v_record;
layout(location = 0) out vec4 o_sum;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    GSample g = gbuffer_load(pixel);
    if (!g.surface || g.roughness < GLOSSY_ROUGHNESS_MIN) {
        discard;
    }
    GpuRecord rec = records[v_record];
    float w = splat_weight_at(g, rec);
    if (!(w > pc.w_min)) {
        discard;
    }
    uint pix = (uint(pixel.y) * frame.resolution.x + uint(pixel.x)) * RADIANCE_VEC4S;
    uint base = v_record * RADIANCE_VEC4S;
    // 48 packed floats each: coefficient i's channel c at 3i + c, so a vec4 product sums four
    // (coefficient, channel) terms; lane l of vec4 q is float 4q + l, channel (4q + l) % 3.
    vec3 l = vec3(0.0);
    for (uint q = 0u; q < RADIANCE_VEC4S; ++q) {
        vec4 t = radiance[base + q] * glossy_w[pix + q];
        uint c = (4u * q) % 3u;
        l[c] += t.x;
        l[(c + 1u) % 3u] += t.y;
        l[(c + 2u) % 3u] += t.z;
        l[c] += t.w;
    }
    o_sum = vec4(w * l, w);
}
