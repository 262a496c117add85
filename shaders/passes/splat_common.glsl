// passes/splat_common.glsl — Rust: crates/radcache-render/src/passes/splat.rs
// Declarations shared by the splat vertex and fragment shaders.
#ifndef RADCACHE_SPLAT_COMMON_GLSL
#define RADCACHE_SPLAT_COMMON_GLSL

#include "../shared/push.glsl"

layout(binding = B_FRAME) uniform Frame { FrameConstants frame; };
layout(binding = B_SPLAT_RECORDS, std430) readonly buffer Records { GpuRecord records[]; };
// Per record: the last frame in which it weighed on a pixel (eviction, crates/radcache-render/src/state.rs).
layout(binding = B_SPLAT_LAST_USED, std430) buffer LastUsed { uint last_used[]; };

layout(push_constant) uniform Push { SplatWeights pc; };

// The radius the weight uses: R_orig (shrunk by neighbour clamping after creation) clamped to
// the record's own [R⁻, R⁺].
float record_radius(GpuRecord rec) {
    return clamp_radius(rec.normal_rorig.w, rec.bounds.x, rec.bounds.y);
}

// World radius of the record's zone of influence.
float splat_extent(GpuRecord rec) {
    return splat_radius(pc.kind, record_radius(rec), pc.param, pc.w_min);
}

#ifdef RADCACHE_GBUFFER_GLSL
// The weight of record `rec` at the G-buffer sample g: the pass's weight with the normal and
// in-front tests (0 outside the record's zone; splat.frag and splat_glossy.frag discard at or
// below pc.w_min).
float splat_weight_at(GSample g, GpuRecord rec) {
    vec3 p_i = rec.position_radius.xyz;
    vec3 n_i = rec.normal_rorig.xyz;
    float r_i = record_radius(rec);
    float tol = pc.front_tol_px * g.footprint;
    return record_weight(pc.kind, g.position, g.normal, p_i, n_i, r_i, pc.param, tol);
}
#endif

#endif
