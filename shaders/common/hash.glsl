// common/hash.glsl — Rust: crates/radcache-cache/src/sampling.rs (ircache_hash)
// Integer hashing and uniform random numbers.
#ifndef RADCACHE_HASH_GLSL
#define RADCACHE_HASH_GLSL

// PCG-style integer hash (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020).
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A uniform float in [0, 1) from 24 random bits.
float uint_to_unit_float(uint v) {
    return float(v >> 8u) * (1.0 / 16777216.0);
}

#endif
