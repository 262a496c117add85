// common/random.glsl — Rust: crates/radcache-cache/src/sampling.rs
// Per-sample random numbers: a counter-based generator seeded by (pixel or record, sample, seed),
// so every sample is reproducible and independent of dispatch order.
#ifndef RADCACHE_RANDOM_GLSL
#define RADCACHE_RANDOM_GLSL

#include "hash.glsl"

struct Rng {
    uint state;
};

// A generator for stream `stream` (e.g. the pixel index), sample `sample_index` and a global seed.
Rng rng_init(uint stream, uint sample_index, uint seed) {
    Rng r;
    r.state = pcg_hash(stream ^ pcg_hash(sample_index + pcg_hash(seed)));
    return r;
}

// The next uniform float in [0, 1).
float rng_next(inout Rng r) {
    r.state = pcg_hash(r.state);
    return uint_to_unit_float(r.state);
}

vec2 rng_next2(inout Rng r) {
    float a = rng_next(r);
    return vec2(a, rng_next(r));
}

#endif
