// passes/ic_counters.comp — Rust: crates/radcache-render/src/state/ic_counters.rs
// Bookkeeping of the irradiance cache's counters and indirect arguments (one invocation), so the
// host never reads counts back to size the next dispatch or draw:
//   COUNTERS_RESET        no records, no requests (capacities from the push constants)
//   COUNTERS_BEGIN_LEVEL  no requests, hole count 0
//   COUNTERS_BEGIN_BATCH  batch_first = record_count; dispatch = one workgroup per request that fits
//   COUNTERS_END_BATCH    record_count += dispatched; the splat draw covers every record, the batch
//                         draw the batch's records
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../shared/constants.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 1) in;

layout(binding = B_IC_COUNTERS_COUNTERS, std430) buffer Counters { IcCounters counters; };

layout(push_constant) uniform Push { IcCountersPush pc; };

void main() {
    if (pc.step == COUNTERS_RESET) {
        counters.record_count = 0u;
        counters.requested = 0u;
        counters.batch_first = 0u;
        counters.holes = 0u;
        counters.dispatch = DispatchArgs(0u, 1u, 1u, 0u);
        counters.draw = DrawArgs(QUAD_VERTICES, 0u, 0u, 0u);
        counters.record_capacity = pc.record_capacity;
        counters.request_capacity = pc.request_capacity;
        counters.dropped_requests = 0u;
        counters.rejected_records = 0u;
        counters.batch_draw = DrawArgs(QUAD_VERTICES, 0u, 0u, 0u);
        counters.radii_shrunk = 0u;
    } else if (pc.step == COUNTERS_BEGIN_LEVEL) {
        counters.requested = 0u;
        counters.holes = 0u;
    } else if (pc.step == COUNTERS_BEGIN_BATCH) {
        uint room = counters.record_capacity - min(counters.record_count, counters.record_capacity);
        uint requested = min(counters.requested, counters.request_capacity);
        uint n = min(requested, room);
        counters.dropped_requests += requested - n;
        counters.batch_first = counters.record_count;
        counters.dispatch = DispatchArgs(n, 1u, 1u, 0u);
        counters.batch_draw = DrawArgs(QUAD_VERTICES, 0u, 0u, 0u);
    } else if (pc.step == COUNTERS_END_BATCH) {
        counters.record_count += counters.dispatch.x;
        counters.draw = DrawArgs(QUAD_VERTICES, counters.record_count, 0u, 0u);
        counters.batch_draw = DrawArgs(QUAD_VERTICES, counters.dispatch.x, 0u, counters.batch_first);
    }
}
