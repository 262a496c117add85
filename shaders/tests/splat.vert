// tests/splat.vert — Rust: tests/tests/foundation.rs
// Instanced screen-space quads for the blending test: quad i covers the pixel rectangle
// quads[i].rect at depth quads[i].depth and carries quads[i].color.
#version 460

struct Quad {
    vec4 rect;   // x0, y0, x1, y1 in pixels
    vec4 color;
    vec4 depth;  // x: NDC depth
};

layout(binding = 0, std430) readonly buffer Quads { Quad quads[]; };

layout(push_constant) uniform Push {
    vec2 viewport;
    vec2 pad;
} pc;

layout(location = 0) out vec4 v_color;

const vec2 CORNERS[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(0, 1), vec2(1, 0), vec2(1, 1));

void main() {
    Quad q = quads[gl_InstanceIndex];
    vec2 p = mix(q.rect.xy, q.rect.zw, CORNERS[gl_VertexIndex % 6]);
    gl_Position = vec4(p / pc.viewport * 2.0 - 1.0, q.depth.x, 1.0);
    v_color = q.color;
}
