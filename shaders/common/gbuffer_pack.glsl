// common/gbuffer_pack.glsl — Rust: crates/radcache-render/src/passes/gbuffer.rs
// Metallic and roughness in one float of the G-buffer (the emission image's w, scenes with
// specular materials only): each quantised to 10 bits (steps of 1/1023), stored as the integer
// metallic·1024 + roughness, exact in f32 (below 2^20) and never a NaN or denormal pattern.
#ifndef RADCACHE_GBUFFER_PACK_GLSL
#define RADCACHE_GBUFFER_PACK_GLSL

float gbuffer_pack_metallic_roughness(float metallic, float roughness) {
    float m = floor(clamp(metallic, 0.0, 1.0) * 1023.0 + 0.5);
    float r = floor(clamp(roughness, 0.0, 1.0) * 1023.0 + 0.5);
    return m * 1024.0 + r;
}

// (metallic, roughness) of a packed value.
vec2 gbuffer_unpack_metallic_roughness(float packed) {
    float p = clamp(floor(packed + 0.5), 0.0, 1048575.0);
    float m = floor(p / 1024.0);
    return vec2(m, p - m * 1024.0) * (1.0 / 1023.0);
}

#endif
