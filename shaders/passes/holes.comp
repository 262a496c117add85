// passes/holes.comp — Rust: crates/radcache-render/src/passes/holes.rs
// Hole selection (docs/cache-frame.md §3.3): at level spacing S, each S×S block of the image with
// at least one hole (a surface pixel whose splatted weight sum is below the coverage threshold)
// requests one new record, at the block's hole with the smallest hash (a deterministic, unbiased
// pick); the number of hole pixels is counted. With `count_only`, holes are counted and nothing is
// requested.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../common/gbuffer.glsl"
#include "../common/hash.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = B_HOLES_SPLAT_SUM, rgba32f) readonly uniform image2D splat_sum;
layout(binding = B_HOLES_REQUESTS, std430) buffer Requests { uint requests[]; };
layout(binding = B_HOLES_COUNTERS, std430) buffer Counters { IcCounters counters; };

layout(push_constant) uniform Push { HolesPush pc; };

void main() {
    ivec2 size = imageSize(g_position);
    ivec2 origin = ivec2(gl_GlobalInvocationID.xy) * int(pc.spacing);
    if (any(greaterThanEqual(origin, size))) {
        return;
    }
    uint holes = 0u;
    uint best = 0xffffffffu;
    uint best_pixel = 0u;
    ivec2 end = min(origin + ivec2(pc.spacing), size);
    for (int y = origin.y; y < end.y; ++y) {
        for (int x = origin.x; x < end.x; ++x) {
            ivec2 p = ivec2(x, y);
            if (imageLoad(g_position, p).w < 0.5 || imageLoad(splat_sum, p).a >= pc.threshold) {
                continue;
            }
            holes++;
            uint index = uint(y * size.x + x);
            uint h = pcg_hash(index ^ pcg_hash(pc.seed));
            if (h <= best) {
                best = h;
                best_pixel = index;
            }
        }
    }
    if (holes == 0u) {
        return;
    }
    atomicAdd(counters.holes, holes);
    if (pc.count_only != 0u) {
        return;
    }
    uint slot = atomicAdd(counters.requested, 1u);
    if (slot < counters.request_capacity) {
        requests[slot] = best_pixel;
    } else {
        atomicAdd(counters.dropped_requests, 1u);
    }
}
