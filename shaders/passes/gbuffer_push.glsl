// passes/gbuffer_push.glsl: included by gbuffer.vert and gbuffer.frag (crates/radcache-render/src/passes/gbuffer.rs).
// The push constants of the G-buffer rasterization (`GBufferPush`, generated from Rust).
#ifndef RADCACHE_GBUFFER_PUSH_GLSL
#define RADCACHE_GBUFFER_PUSH_GLSL
#include "../shared/push.glsl"
layout(push_constant) uniform Push { GBufferPush pc; };
#endif
