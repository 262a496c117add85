// tests/busy.comp — Rust: tests/tests/foundation.rs
// Busy work for the profiler test: each invocation iterates a hash `iterations` times.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../common/hash.glsl"

layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Out { uint values[]; };
layout(push_constant) uniform Push {
    uint iterations;
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

void main() {
    uint x = gl_GlobalInvocationID.x;
    for (uint i = 0u; i < pc.iterations; ++i) {
        x = pcg_hash(x);
    }
    values[gl_GlobalInvocationID.x] = x;
}
