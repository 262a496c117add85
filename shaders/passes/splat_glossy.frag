// passes/splat_glossy.frag — Rust: crates/radcache-render/src/passes/splat_glossy.rs
// Glossy splatting, per pixel (docs/radiance-caching.md §6.2): where the pixel's lobe is rough
// enough for the radiance records (roughness ≥ GLOSSY_ROUGHNESS_MIN; the others keep the direct
// pass's per-pixel specular paths), the record's weight at the pixel's G-buffer point (the same
// weight as splat.frag) times the radiance its SH coefficients reflect towards the camera,
// Σ_i c_i ⊙ W_i with the pixel's world weights W (written by the direct pass), added with w into
// the RGBA32F target by (ONE, ONE) blending. With GLOSSY_GRADIENTS (the default build,
// docs/radiance-caching.md §7.3) each coefficient is first extrapolated to the pixel's point by
// its translational gradient (stored as f16 of ∇c_i/s with the record's scale s),
// c_i + att·∇c_i·(p − p_i), att the irradiance's own gradient
// attenuation (gradient_attenuation), and the record's result is guarded as the irradiance's
// extrapolation is: clamp_extrapolation(L_extrapolated, L_at_record), so it is never negative and
// at most EXTRAPOLATION_MAX_FACTOR times the record's own value.
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

// The records' blocks (radcache_shared::consts::RECORD_RADIANCE_VEC4S): f32 coefficients, the
// gradients' scale, f16 gradients.
layout(binding = B_SPLAT_GLOSSY_RADIANCE, std430) readonly buffer Radiance { uvec4 radiance[]; };
layout(binding = B_SPLAT_GLOSSY_GLOSSY_WEIGHTS, std430) readonly buffer Weights { vec4 glossy_w[]; };

layout(location = 0) out vec4 o_sum;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    GSample g = gbuffer_load(pixel);
    if (!g.surface || g.roughness < GLOSSY_ROUGHNESS_MIN) {
        discard;
    }
    float w = splat_weight_at(g);
    if (!(w > pc.w_min)) {
        discard;
    }
    uint pix = (uint(pixel.y) * frame.resolution.x + uint(pixel.x)) * RADIANCE_VEC4S;
    uint base = v_record * RECORD_RADIANCE_VEC4S;
    // 48 packed floats each: coefficient i's channel c at 3i + c, so a vec4 product sums four
    // (coefficient, channel) terms; lane l of vec4 q is float 4q + l, channel (4q + l) % 3.
#ifdef GLOSSY_GRADIENTS
    float scale = uintBitsToFloat(radiance[base + RADIANCE_VEC4S].x);
    vec3 dp = (g.position - v_zone.xyz) * (v_normal.w * scale);
    uint grads = base + RADIANCE_VEC4S + 1u;
#endif
    vec3 l0 = vec3(0.0);
    vec3 l = vec3(0.0);
    for (uint q = 0u; q < RADIANCE_VEC4S; ++q) {
        vec4 gw = glossy_w[pix + q];
        vec4 t0 = uintBitsToFloat(radiance[base + q]) * gw;
        uint ch = (4u * q) % 3u;
        l0[ch] += t0.x + t0.w;
        l0[(ch + 1u) % 3u] += t0.y;
        l0[(ch + 2u) % 3u] += t0.z;
#ifdef GLOSSY_GRADIENTS
        // Floats 4q..4q+3 of axis a: words 24a + 2q and 24a + 2q + 1.
        vec4 dc = vec4(0.0);
        for (uint a = 0u; a < 3u; ++a) {
            uvec4 u = radiance[grads + 6u * a + q / 2u];
            uvec2 pair = (q & 1u) == 0u ? u.xy : u.zw;
            dc += dp[a] * vec4(unpackHalf2x16(pair.x), unpackHalf2x16(pair.y));
        }
        vec4 t = dc * gw;
        l[ch] += t.x + t.w;
        l[(ch + 1u) % 3u] += t.y;
        l[(ch + 2u) % 3u] += t.z;
#endif
    }
#ifdef GLOSSY_GRADIENTS
    l = clamp_extrapolation(l0 + l, l0);
#else
    l = l0;
#endif
    o_sum = vec4(w * l, w);
}
