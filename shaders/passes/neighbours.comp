// Neighbour clamping (Křivánek et al. 2006; IC reference §7.5) for the batch of records just
// created, records [record_base, record_count): for every pair (i new, j any) the radii must satisfy
// R_i ≤ R_j + ‖p_i − p_j‖ and R_j ≤ R_i + ‖p_i − p_j‖. One workgroup per new record; its
// invocations scan all records. R_orig only decreases, so the updates are atomic minimums on the
// float bits (IEEE order equals integer order for non-negative floats) and their order does not
// matter. R_used is derived from R_orig and the record's own bounds where it is used (the splat).
// Cost O(new × all) per batch.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../common/ircache_math.glsl"

layout(local_size_x = 64) in;

layout(binding = B_PASS_BASE, std430) readonly buffer Counters { IcCounters counters; };
layout(binding = B_PASS_BASE + 1, std430) buffer Records { GpuRecord records[]; };
// The same buffer as 32-bit words, for the atomic minimum on R_orig (word 7 of 44 per record).
layout(binding = B_PASS_BASE + 2, std430) buffer RecordWords { uint record_words[]; };

const uint RECORD_WORDS = 44u;
const uint R_ORIG_WORD = 7u;

shared float group_min[64];

void main() {
    uint i = counters.counts.z + gl_WorkGroupID.x;
    if (i >= counters.counts.x) {
        return;
    }
    vec3 p_i = records[i].position_radius.xyz;
    float r_i = sanitize_radius(records[i].normal_rorig.w);
    float local_min = IC_FAR;
    for (uint j = gl_LocalInvocationID.x; j < counters.counts.x; j += 64u) {
        if (j == i) {
            continue;
        }
        vec3 p_j = records[j].position_radius.xyz;
        float d = distance(p_i, p_j);
        float r_j = sanitize_radius(uintBitsToFloat(record_words[j * RECORD_WORDS + R_ORIG_WORD]));
        local_min = min(local_min, neighbour_clamp(IC_FAR, r_j, d));
        float shrunk = neighbour_clamp(r_j, r_i, d);
        if (shrunk < r_j) {
            atomicMin(record_words[j * RECORD_WORDS + R_ORIG_WORD], floatBitsToUint(shrunk));
        }
    }
    group_min[gl_LocalInvocationID.x] = local_min;
    barrier();
    for (uint s = 32u; s > 0u; s >>= 1u) {
        if (gl_LocalInvocationID.x < s) {
            group_min[gl_LocalInvocationID.x] =
                min(group_min[gl_LocalInvocationID.x], group_min[gl_LocalInvocationID.x + s]);
        }
        barrier();
    }
    if (gl_LocalInvocationID.x == 0u && group_min[0] < r_i) {
        atomicMin(record_words[i * RECORD_WORDS + R_ORIG_WORD], floatBitsToUint(group_min[0]));
    }
}
