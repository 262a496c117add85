// Declarations shared by the splat vertex and fragment shaders.
#ifndef RADCACHE_SPLAT_COMMON_GLSL
#define RADCACHE_SPLAT_COMMON_GLSL

layout(binding = B_FRAME) uniform Frame { FrameConstants frame; };
layout(binding = B_GBUFFER_END, std430) readonly buffer Records { GpuRecord records[]; };
// Per record: the last frame in which it weighed on a pixel (eviction, ic_state.rs).
layout(binding = B_GBUFFER_END + 1, std430) buffer LastUsed { uint last_used[]; };

layout(push_constant) uniform Push {
    uint kind;           // WEIGHT_WARD or WEIGHT_TL
    float param;         // a (Ward) or κ (T&L)
    float w_min;         // weights at or below this are rejected
    float front_tol_px;  // in-front tolerance, in pixel footprints
    uint mark_frame;     // written to last_used of every record that weighs (0: none)
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

// The radius the weight uses: R_orig (shrunk by neighbour clamping after creation) clamped to
// the record's own [R⁻, R⁺].
float record_radius(GpuRecord rec) {
    return clamp_radius(rec.normal_rorig.w, rec.bounds.x, rec.bounds.y);
}

// World radius of the record's zone of influence.
float splat_extent(GpuRecord rec) {
    return splat_radius(pc.kind, record_radius(rec), pc.param, pc.w_min);
}

#endif
