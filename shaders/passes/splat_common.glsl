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

// What a record's fragments need, handed from the vertex shader to every fragment of its quad as
// flat varyings: read from the records buffer per fragment, each field costs lavapipe a gather
// (the record index is not known to be uniform over a fragment block), which was 55 % of the
// final splat's time (docs/cache-frame.md §6.3).
#ifdef SPLAT_VERTEX
#define SPLAT_IO out
#else
#define SPLAT_IO in
#endif
layout(location = 0) flat SPLAT_IO uint v_record;
layout(location = 1) flat SPLAT_IO vec4 v_zone;        // p_i; w: the weight's radius (record_radius)
layout(location = 2) flat SPLAT_IO vec4 v_normal;      // n_i; w: the gradient attenuation
layout(location = 3) flat SPLAT_IO vec3 v_irradiance;  // E_i
layout(location = 4) flat SPLAT_IO mat3 v_grad_r;      // rotational gradients (red, green, blue)
layout(location = 7) flat SPLAT_IO mat3 v_grad_t;      // translational ones, attenuated

#ifdef SPLAT_VERTEX
// The varyings of record `r`.
void splat_varyings(uint r, GpuRecord rec) {
    float att = gradient_attenuation(rec.normal_rorig.w, rec.bounds.x);
    v_record = r;
    v_zone = vec4(rec.position_radius.xyz, record_radius(rec));
    v_normal = vec4(rec.normal_rorig.xyz, att);
    v_irradiance = rec.irradiance.rgb;
    v_grad_r = mat3(rec.grad_r_red.xyz, rec.grad_r_green.xyz, rec.grad_r_blue.xyz);
    v_grad_t = att * mat3(rec.grad_t_red.xyz, rec.grad_t_green.xyz, rec.grad_t_blue.xyz);
}
#endif

#ifdef RADCACHE_GBUFFER_GLSL
// The weight of the quad's record at the G-buffer sample g: the pass's weight with the normal and
// in-front tests (0 outside the record's zone; splat.frag and splat_glossy.frag discard at or
// below pc.w_min).
float splat_weight_at(GSample g) {
    float tol = pc.front_tol_px * g.footprint;
    return record_weight(pc.kind, g.position, g.normal, v_zone.xyz, v_normal.xyz, v_zone.w,
                         pc.param, tol);
}
#endif

#endif
