// passes/splat.frag — Rust: crates/radcache-render/src/passes/splat.rs
// Irradiance splatting, per pixel (docs/cache-frame.md §6.3): the record's weight at the pixel's
// G-buffer point (normal and in-front tests included), the gradient-extrapolated irradiance
// clamped to [0, 4·E_i] (docs/irradiance-cache.md §6.2), and (w·Ẽ, w) added into the RGBA32F target
// by (ONE, ONE) blending (and 1 into the record-count target). Weights are bounded (T&L ≤ 1,
// Ward ≤ 1/10⁻³), so the float sums cannot overflow.
// With SPLAT_COVERAGE (the cache phase's coverage splats, which hole selection reads for Σw
// alone): (0, 0, 0, w), the same weights without the irradiance and without marking records.
// The record-count target (the debug AOV) is drawn only with SPLAT_COUNT.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../common/gbuffer.glsl"
#include "../common/ircache_math.glsl"
#include "splat_common.glsl"

layout(location = 0) out vec4 o_sum;
#ifdef SPLAT_COUNT
layout(location = 1) out float o_count;  // records reaching the pixel (debug AOV)
#endif

void main() {
    GSample g = gbuffer_load(ivec2(gl_FragCoord.xy));
    if (!g.surface) {
        discard;
    }
    float w = splat_weight_at(g);
    if (!(w > pc.w_min)) {
        discard;
    }
#ifdef SPLAT_COVERAGE
    o_sum = vec4(0.0, 0.0, 0.0, w);
#else
    vec3 e = extrapolate_irradiance(v_irradiance, v_grad_r[0], v_grad_r[1], v_grad_r[2],
                                    v_grad_t[0], v_grad_t[1], v_grad_t[2], g.position, g.normal,
                                    v_zone.xyz, v_normal.xyz);
    // Every writer stores the same value: the race is benign. Only the first fragment of the
    // frame stores it (a store to a line other cores read makes them fetch it again).
    if (pc.mark_frame != 0u && last_used[v_record] != pc.mark_frame) {
        last_used[v_record] = pc.mark_frame;
    }
    o_sum = vec4(w * e, w);
#endif
#ifdef SPLAT_COUNT
    o_count = 1.0;
#endif
}
