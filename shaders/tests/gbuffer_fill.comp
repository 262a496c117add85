// tests/gbuffer_fill.comp — Rust: tests/tests/ic_records.rs
// Test helper (tests/tests/ic_records.rs): writes given surface points into the G-buffer's
// position, shading-normal, geometric-normal and emission images (layout of common/gbuffer.glsl:
// the material index in geometric.w, the packed metallic and roughness in emission.w), one
// invocation per texel, so the record pass can be tested without the raster G-buffer pass.
// Bindings: 0-2 the position, normal and geometric images, 3 the texels, 4 the emission image.
#version 460

layout(local_size_x = 64) in;

layout(binding = 0, rgba32f) writeonly uniform image2D g_position;
layout(binding = 1, rgba32f) writeonly uniform image2D g_normal;
layout(binding = 2, rgba32f) writeonly uniform image2D g_geometric;
layout(binding = 4, rgba32f) writeonly uniform image2D g_emission;

struct Texel {
    uvec4 pixel;     // xy
    vec4 position;   // xyz (stored with w = 1: a surface); w: packed metallic and roughness
    vec4 normal;     // shading normal xyz, footprint w
    vec4 geometric;  // geometric normal xyz, material index w
};

layout(binding = 3, std430) readonly buffer Texels { Texel texels[]; };

layout(push_constant) uniform Push {
    uint count;
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    Texel t = texels[i];
    ivec2 pixel = ivec2(t.pixel.xy);
    imageStore(g_position, pixel, vec4(t.position.xyz, 1.0));
    imageStore(g_normal, pixel, t.normal);
    imageStore(g_geometric, pixel, t.geometric);
    imageStore(g_emission, pixel, vec4(0.0, 0.0, 0.0, t.position.w));
}
