// passes/splat.vert — Rust: crates/radcache-render/src/passes/splat.rs
// Irradiance splatting (Gautron et al. 2005, docs/cache-frame.md §6.2;
// docs/irradiance-cache.md §5.6): one screen-aligned quad per record (instance = record index),
// covering the projection of its zone of influence. Every weight needs ‖Δ‖ + |Δ·n_i| < ρ
// (Δ = p − p_i, ρ = splat_radius(R_i); docs/irradiance-cache.md §5.6). With h = Δ·n̂ the height
// above the record's tangent plane and t its part along the plane, ‖Δ‖ ≥ max(|h|, |t|) gives
// |h| < H = ρ/(1 + |n_i|) (ρ/2 for a unit normal) and |t| < ρ − |n_i|·|h|: the zone lies in two
// square frusta on the tangent plane, of half-side ρ at h = 0 and H at h = ±H (a cube of
// half-side ρ, which holds the ball ‖Δ‖ < ρ, where the normal is zero or not finite). The bound is
// conservative: the 12 corners are projected and their screen rectangle taken; a corner behind
// the camera (clip w ≤ 0) or a zone too large to project gets the full viewport.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../common/gbuffer.glsl"
#include "../common/ircache_math.glsl"
#define SPLAT_VERTEX 1
#include "splat_common.glsl"

void main() {
    uint r = uint(gl_InstanceIndex);
    GpuRecord rec = records[r];
    float rho = splat_extent(rec);
    vec3 c = rec.position_radius.xyz;
    // The frusta's axes: n_i and a tangent basis whose first axis is the screen's x (else y)
    // axis laid onto the plane, so that the squares' screen rectangle hugs the zone's (a square
    // turned 45° on screen would reach √2 further).
    vec3 n_i = rec.normal_rorig.xyz;
    float n_len = length(n_i);
    bool oriented = n_len > 0.0 && n_len < 2.0;
    vec3 n = oriented ? n_i / n_len : vec3(0.0, 0.0, 1.0);
    vec3 screen_x = vec3(frame.clip_from_world[0][0], frame.clip_from_world[1][0],
                         frame.clip_from_world[2][0]);
    vec3 screen_y = vec3(frame.clip_from_world[0][1], frame.clip_from_world[1][1],
                         frame.clip_from_world[2][1]);
    vec3 along_x = screen_x - n * dot(n, screen_x);
    vec3 along_y = screen_y - n * dot(n, screen_y);
    vec3 tangent;
    vec3 bitangent;
    if (dot(along_x, along_x) > 0.25 * dot(screen_x, screen_x)) {
        tangent = normalize(along_x);
    } else if (dot(along_y, along_y) > 0.0) {
        tangent = normalize(along_y);
    } else {
        basis_from_normal(n, tangent, bitangent);
    }
    bitangent = cross(n, tangent);
    // The frusta's height, also the squares' half-side at h = ±height.
    float height = oriented ? rho / (1.0 + n_len) : rho;
    vec2 lo = vec2(1.0);
    vec2 hi = vec2(-1.0);
    bool full = !(rho < 1.0e6 * frame.camera_position.w);
    for (int i = 0; i < 12 && !full; ++i) {
        int level = i >> 2;  // 0: h = 0, 1: h = +height, 2: h = −height
        float side = level == 0 ? rho : height;
        float h = level == 0 ? 0.0 : (level == 1 ? height : -height);
        float st = (i & 1) != 0 ? side : -side;
        float sb = (i & 2) != 0 ? side : -side;
        vec3 corner = c + st * tangent + sb * bitangent + h * n;
        vec4 clip = frame.clip_from_world * vec4(corner, 1.0);
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
    splat_varyings(r, rec);
}
