// passes/gbuffer.comp — Rust: crates/radcache-render/src/passes/gbuffer.rs
// The G-buffer by ray tracing (docs/cache-frame.md §2): one camera ray per pixel through
// p + 0.5 + jitter, its first hit (alpha-tested as every ray is) written to the images of
// shaders/common/gbuffer.glsl with the rules of the rasterized G-buffer (gbuffer.frag): normals
// toward the camera, the pinhole footprint from the view depth (clip w), the stored point moved
// a hair toward the camera, zero on the background and in the direct-light image. The hit is the
// surface the camera sees, so rasterization's edge snapping cannot arise.
//
// With GBUFFER_REPAIR, the guard of the rasterized G-buffer instead (docs/cache-frame.md §2):
// rasterization snaps edges to the sub-pixel grid, so a sample within that distance of the seam
// where a zero-thickness wall stands on a floor that runs on under it misses the wall and lands
// on the floor behind it, lit by the other side's lights (the stiff suite's `two_rooms`). Such a
// sample lies behind a surface edge: one of its 8 neighbours is nearer to the camera and off its
// plane. Stage 0 (pc.repair_stage) marks those samples in the direct-light image (cleared after
// the rasterization; the marks read only rasterized points, so the result does not depend on
// the order of the workgroups); stage 1 traces the camera ray to each marked sample, stopping
// 1e-5 of the distance short, writes a surface hit before it as the traced G-buffer writes a hit
// (it is what the camera sees), and clears the mark. Every other sample keeps its rasterized
// values.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/path.glsl"
#include "../common/ircache_math.glsl"
#include "../common/gbuffer_pack.glsl"
#include "gbuffer_push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
#include "../common/dispatch.glsl"

#ifdef GBUFFER_REPAIR
// The rasterized samples are read (the sample, its normal and footprint, its neighbours).
#define GBUFFER_READ
#else
#define GBUFFER_READ writeonly
#endif
layout(binding = B_GBUFFER_POSITION, rgba32f) GBUFFER_READ uniform image2D o_position;
layout(binding = B_GBUFFER_NORMAL, rgba32f) GBUFFER_READ uniform image2D o_normal;
layout(binding = B_GBUFFER_GEOMETRIC, rgba32f) GBUFFER_READ uniform image2D o_geometric;
layout(binding = B_GBUFFER_ALBEDO, rgba32f) writeonly uniform image2D o_albedo;
layout(binding = B_GBUFFER_EMISSION, rgba32f) writeonly uniform image2D o_emission;
layout(binding = B_GBUFFER_DIRECT, rgba32f) GBUFFER_READ uniform image2D o_direct;
// 1 where this sub-frame shades the pixel, 0 where per-pixel adaptive anti-aliasing has stopped
// it (docs/cache-frame.md §7.2): its position is written with w = −1 and nothing else, and the
// direct and composite passes leave it alone.
layout(binding = B_GBUFFER_PASS_ACTIVE, std430) readonly buffer Active { uint active_mask[]; };

#ifdef HAS_ALPHA
// The seed of this pixel's BLEND tests in this sub-frame, as gbuffer.frag draws it.
uint gbuffer_alpha_seed(uvec2 p) {
    uint h = pcg_hash(frame.resolution.w ^ pcg_hash(frame.resolution.z));
    h = pcg_hash(h ^ floatBitsToUint(pc.jitter.x));
    h = pcg_hash(h ^ floatBitsToUint(pc.jitter.y));
    h = pcg_hash(h ^ p.x);
    return pcg_hash(h ^ p.y);
}
#endif

#ifdef GBUFFER_REPAIR
// A neighbour off the sample's plane by more than this many footprints is another surface.
const float REPAIR_OFF_PLANE = 0.05;

// Whether the rasterized sample at `at` (point p, geometric normal n, footprint f) lies behind
// a surface edge: one of its 8 neighbours is a surface point nearer to the camera and more than
// REPAIR_OFF_PLANE footprints off p's plane.
bool behind_an_edge(ivec2 at, vec3 p, vec3 n, float f) {
    vec3 eye = frame.camera_position.xyz;
    float d = distance(p, eye);
    for (int k = 0; k < 9; ++k) {
        ivec2 q = at + ivec2(k % 3 - 1, k / 3 - 1);
        if (k == 4 || any(lessThan(q, ivec2(0))) ||
            any(greaterThanEqual(q, ivec2(frame.resolution.xy)))) {
            continue;
        }
        vec4 o = imageLoad(o_position, q);
        if (o.w > 0.5 && distance(o.xyz, eye) < d &&
            abs(dot(n, o.xyz - p)) > REPAIR_OFF_PLANE * f) {
            return true;
        }
    }
    return false;
}
#endif

void main() {
    uvec2 pixel = interleaved_pixel();
    if (any(greaterThanEqual(pixel, frame.resolution.xy))) {
        return;
    }
    ivec2 at = ivec2(pixel);
#ifdef HAS_ALPHA
    uint alpha_seed = gbuffer_alpha_seed(pixel);
#else
    uint alpha_seed = 0u;
#endif
    rayQueryEXT q;
#ifdef GBUFFER_REPAIR
    vec4 sample_position = imageLoad(o_position, at);
    if (pc.repair_stage == 0u) {
        if (sample_position.w > 0.5 &&
            behind_an_edge(at, sample_position.xyz, imageLoad(o_geometric, at).xyz,
                           imageLoad(o_normal, at).w)) {
            imageStore(o_direct, at, vec4(1.0, 0.0, 0.0, 0.0));
        }
        return;
    }
    // Stage 1 reads no neighbour: a stopped pixel may be marked now.
    if (active_mask[pixel.y * frame.resolution.x + pixel.x] == 0u) {
        imageStore(o_position, at, vec4(0.0, 0.0, 0.0, -1.0));
        imageStore(o_direct, at, vec4(0.0));
        return;
    }
    if (imageLoad(o_direct, at).x == 0.0) {
        return;
    }
    imageStore(o_direct, at, vec4(0.0));
    Ray r;
    r.origin = frame.camera_position.xyz;
    vec3 to_sample = sample_position.xyz - r.origin;
    float sample_dist = length(to_sample);
    if (!(sample_dist > 0.0)) {
        return;
    }
    r.dir = to_sample / sample_dist;
    scene_trace_seeded(q, 0u, r.origin, r.dir, sample_dist * (1.0 - 1e-5), alpha_seed);
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        return;
    }
#else
    imageStore(o_direct, at, vec4(0.0));
    if (active_mask[pixel.y * frame.resolution.x + pixel.x] == 0u) {
        imageStore(o_position, at, vec4(0.0, 0.0, 0.0, -1.0));
        return;
    }
    Ray r = camera_ray(pixel, vec2(0.5) + pc.jitter);
    scene_trace_seeded(q, 0u, r.origin, r.dir, IC_FAR, alpha_seed);
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        imageStore(o_position, at, vec4(0.0));
        imageStore(o_normal, at, vec4(0.0));
        imageStore(o_geometric, at, vec4(0.0));
        imageStore(o_albedo, at, vec4(0.0));
        imageStore(o_emission, at, vec4(0.0));
        return;
    }
#endif
    uint instance = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true));
    Surface s = surface_at(instance, uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                           rayQueryGetIntersectionBarycentricsEXT(q, true), r.dir);
    vec3 position = s.position;
    vec3 to_camera = frame.camera_position.xyz - position;
    vec3 ng = s.geometric_normal;
    // View depth = clip w. The y row of clip_from_world is the projection's ±1/tan(fov_y/2)
    // times a row of the view rotation (a unit vector).
    float view_depth = (frame.clip_from_world * vec4(position, 1.0)).w;
    vec3 row_y = vec3(frame.clip_from_world[0][1], frame.clip_from_world[1][1],
                      frame.clip_from_world[2][1]);
    float dist = length(to_camera);
    float cos_view = dist > 0.0 ? dot(ng, to_camera) / dist : 1.0;
    float footprint = pixel_footprint(view_depth, 1.0 / length(row_y),
                                      float(frame.resolution.y), cos_view);
    // A hair toward the camera, as gbuffer.frag explains (the stiff suite's `inside_object`).
    float step_len = min(max(1e-5 * dist, 1e-6 * max(abs(position.x), max(abs(position.y),
                                                                        abs(position.z)))),
                         0.5 * dist);
    position += dist > 0.0 ? to_camera * (step_len / dist) : vec3(0.0);
    imageStore(o_position, at, vec4(position, 1.0));
    imageStore(o_normal, at, vec4(s.shading_normal, footprint));
    imageStore(o_geometric, at, vec4(ng, float(s.material)));
#ifdef HAS_SPECULAR
    Material m = material_at(s.material, s.uv);
    imageStore(o_albedo, at, vec4(m.base_colour, float(instance)));
    imageStore(o_emission, at, vec4(material_emission(s.material, s.uv, s.front_face),
                                    gbuffer_pack_metallic_roughness(m.metallic, m.roughness)));
#else
    imageStore(o_albedo, at, vec4(material_albedo(s.material, s.uv), float(instance)));
    imageStore(o_emission, at, vec4(material_emission(s.material, s.uv, s.front_face), 0.0));
#endif
}
