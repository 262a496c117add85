// tests/normal_map_twin.comp — Rust: tests/tests/normal_maps.rs (harness tests/src/twin.rs)
// GPU side of the normal-map twin test: evaluates common/normal_map.glsl over a table of input
// rows, one invocation per row, for comparison with radcache_material::normal_map. Every row is
// 16 vec4 in and 16 vec4 out (the harness of tests/src/twin.rs); one mode (0).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/normal_map.glsl"

layout(local_size_x = 64) in;

struct Row {
    vec4 v[16];
};

layout(binding = 0, std430) readonly buffer Inputs { Row inputs[]; };
layout(binding = 1, std430) writeonly buffer Outputs { Row outputs[]; };
// Unused by this shader (the harness binds it for every twin shader).
layout(binding = 2, std430) readonly buffer Samples { vec4 samples[]; };

layout(push_constant) uniform Push {
    uint mode;
    uint count;
} pc;

// in: 0 (n, scale); 1 (ng, -); 2 tangent; 3 (texel, -).
// out: 0 (normal_map_normal(n, ng, tangent, texel, scale), -); 1 (normal_map_decode(texel,
// scale), -); 2 (normal_map_perpendicular(n), -).
void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) {
        return;
    }
    Row i = inputs[id];
    Row o;
    for (int c = 0; c < 16; ++c) {
        o.v[c] = vec4(0.0);
    }
    vec3 n = i.v[0].xyz, ng = i.v[1].xyz, texel = i.v[3].xyz;
    float scale = i.v[0].w;
    o.v[0] = vec4(normal_map_normal(n, ng, i.v[2], texel, scale), 0.0);
    o.v[1] = vec4(normal_map_decode(texel, scale), 0.0);
    o.v[2] = vec4(normal_map_perpendicular(n), 0.0);
    outputs[id] = o;
}
