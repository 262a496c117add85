// Push constants of the G-buffer rasterization.
#ifndef RADCACHE_GBUFFER_PUSH_GLSL
#define RADCACHE_GBUFFER_PUSH_GLSL
layout(push_constant) uniform Push {
    uint instance;  // custom index of the drawn instance
    uint pad;
    vec2 jitter;    // sub-pixel offset in pixels
} pc;
#endif
