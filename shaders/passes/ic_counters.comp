// Bookkeeping of the irradiance cache's counters and indirect arguments (one invocation), so the
// host never reads counts back to size the next dispatch or draw:
//   mode 0  reset: no records, no requests (capacities from the push constants)
//   mode 1  begin level: no requests, hole count 0
//   mode 2  begin batch: record_base = record_count; dispatch = one workgroup per request that fits
//   mode 3  end batch: record_count += dispatched; the splat draw covers every record, the batch
//           draw the batch's records
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"

layout(local_size_x = 1) in;

layout(binding = B_PASS_BASE, std430) buffer Counters { IcCounters counters; };

layout(push_constant) uniform Push {
    uint mode;
    uint record_capacity;
    uint request_capacity;
    uint pad;
} pc;

void main() {
    if (pc.mode == 0u) {
        counters.counts = uvec4(0u);
        counters.dispatch = uvec4(0u, 1u, 1u, 0u);
        counters.draw = uvec4(6u, 0u, 0u, 0u);
        counters.limits = uvec4(pc.record_capacity, pc.request_capacity, 0u, 0u);
        counters.batch_draw = uvec4(6u, 0u, 0u, 0u);
    } else if (pc.mode == 1u) {
        counters.counts.y = 0u;
        counters.counts.w = 0u;
    } else if (pc.mode == 2u) {
        uint room = counters.limits.x - min(counters.counts.x, counters.limits.x);
        uint requested = min(counters.counts.y, counters.limits.y);
        uint n = min(requested, room);
        counters.limits.z += requested - n;
        counters.counts.z = counters.counts.x;
        counters.dispatch = uvec4(n, 1u, 1u, 0u);
        counters.batch_draw = uvec4(6u, 0u, 0u, 0u);
    } else {
        counters.counts.x += counters.dispatch.x;
        counters.draw = uvec4(6u, counters.counts.x, 0u, 0u);
        counters.batch_draw = uvec4(6u, counters.dispatch.x, 0u, counters.counts.z);
    }
}
