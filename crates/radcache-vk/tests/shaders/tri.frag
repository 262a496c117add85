// Test shader of crates/radcache-vk/tests: every fragment takes the colour of binding 0.
#version 460
layout(binding = 0, std430) readonly buffer Colour { vec4 colour; };
layout(location = 0) out vec4 out_colour;
void main() {
    out_colour = colour;
}
