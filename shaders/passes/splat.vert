// passes/splat.vert — Rust: crates/radcache-render/src/passes/splat.rs
// Irradiance splatting (Gautron et al. 2005, docs/cache-frame.md §6.2;
// docs/irradiance-cache.md §5.6): one screen-aligned quad per record (instance = record index),
// covering the projection of its zone of influence, a ball of radius splat_radius(R_i) around p_i.
// The bound is conservative: the 8 corners of the ball's world-space box are projected and their
// screen rectangle taken; a box reaching behind the camera (clip w ≤ 0) or a ball too large to
// project gets the full viewport.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../common/gbuffer.glsl"
#include "../common/ircache_math.glsl"
#include "splat_common.glsl"

layout(location = 0) flat out uint v_record;

void main() {
    uint r = uint(gl_InstanceIndex);
    GpuRecord rec = records[r];
    float rho = splat_extent(rec);
    vec3 c = rec.position_radius.xyz;
    vec2 lo = vec2(1.0);
    vec2 hi = vec2(-1.0);
    bool full = !(rho < 1.0e6 * frame.camera_position.w);
    for (int i = 0; i < 8 && !full; ++i) {
        vec3 s = vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
        vec4 clip = frame.clip_from_world * vec4(c + rho * s, 1.0);
        if (clip.w <= 0.0) {
            full = true;
        } else {
            vec2 ndc = clip.xy / clip.w;
            lo = min(lo, ndc);
            hi = max(hi, ndc);
        }
    }
    if (full) {
        lo = vec2(-1.0);
        hi = vec2(1.0);
    }
    // One pixel of margin against rounding, then clip to the viewport.
    vec2 px = 2.0 / vec2(frame.resolution.xy);
    lo = max(lo - px, vec2(-1.0));
    hi = min(hi + px, vec2(1.0));
    const vec2 corners[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(0, 1), vec2(1, 0), vec2(1, 1));
    vec2 t = corners[gl_VertexIndex % 6];
    // An empty rectangle (the ball projects outside the view) collapses to a point: no fragments.
    vec2 xy = any(greaterThanEqual(lo, hi)) ? vec2(-2.0) : mix(lo, hi, t);
    gl_Position = vec4(xy, 0.5, 1.0);
    v_record = r;
}
