// Test shader of crates/radcache-vk/tests: data[i] = value + extra[0] for i < count.
#version 460
layout(local_size_x = 64) in;
layout(binding = 0, std430) buffer Data { uint data[]; };
layout(binding = 1, std430) readonly buffer Extra { uint extra[]; };
layout(push_constant) uniform Push { uint value; uint count; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < count) {
        data[i] = value + extra[0];
    }
}
