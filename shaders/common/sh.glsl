// common/sh.glsl — Rust: crates/radcache-material/src/sh.rs (its CPU twin)
// GLSL twin of radcache-material's `sh`: real spherical harmonics of bands 0–3 (16 functions,
// index l² + l + m, no Condon–Shortley phase), projection and reconstruction of RGB coefficient
// vectors, and the change of frame by evaluation (docs/radiance-caching.md §2–§3). Same names,
// arguments and guards as the Rust functions; arrays are `float[SH_COEFFS]` / `vec3[SH_COEFFS]`
// passed as in/out parameters, indexed only with loop counters of constant bounds (unrolled).
// GLSL 4.60 core; include once (guarded). Values compared on lavapipe by tests/tests/sh_glsl.rs.
#ifndef RADCACHE_SH_GLSL
#define RADCACHE_SH_GLSL

// SH_BANDS, SH_COEFFS, SH_K00..SH_K32B: declared once in Rust (radcache_shared::consts).
#include "../shared/constants.glsl"

void sh_basis(vec3 d, out float y[SH_COEFFS]) {
    float x = d.x, yy = d.y, z = d.z;
    float z2 = z * z;
    y[0] = SH_K00;
    y[1] = SH_K1 * yy;
    y[2] = SH_K1 * z;
    y[3] = SH_K1 * x;
    y[4] = SH_K2 * x * yy;
    y[5] = SH_K2 * yy * z;
    y[6] = SH_K20 * (3.0 * z * z - 1.0);
    y[7] = SH_K2 * x * z;
    y[8] = SH_K22 * (x * x - yy * yy);
    y[9] = SH_K33 * yy * (3.0 * x * x - yy * yy);
    y[10] = SH_K32 * x * yy * z;
    y[11] = SH_K31 * yy * (5.0 * z2 - 1.0);
    y[12] = SH_K30 * z * (5.0 * z2 - 3.0);
    y[13] = SH_K31 * x * (5.0 * z2 - 1.0);
    y[14] = SH_K32B * z * (x * x - yy * yy);
    y[15] = SH_K33 * x * (x * x - 3.0 * yy * yy);
}

// A switch rather than an index into sh_basis's array: no local array indexed at run time.
float sh_basis_one(uint i, vec3 d) {
    float x = d.x, yy = d.y, z = d.z;
    switch (i) {
    case 0u: return SH_K00;
    case 1u: return SH_K1 * yy;
    case 2u: return SH_K1 * z;
    case 3u: return SH_K1 * x;
    case 4u: return SH_K2 * x * yy;
    case 5u: return SH_K2 * yy * z;
    case 6u: return SH_K20 * (3.0 * z * z - 1.0);
    case 7u: return SH_K2 * x * z;
    case 8u: return SH_K22 * (x * x - yy * yy);
    case 9u: return SH_K33 * yy * (3.0 * x * x - yy * yy);
    case 10u: return SH_K32 * x * yy * z;
    case 11u: return SH_K31 * yy * (5.0 * z * z - 1.0);
    case 12u: return SH_K30 * z * (5.0 * z * z - 3.0);
    case 13u: return SH_K31 * x * (5.0 * z * z - 1.0);
    case 14u: return SH_K32B * z * (x * x - yy * yy);
    case 15u: return SH_K33 * x * (x * x - 3.0 * yy * yy);
    default: return 0.0;
    }
}

uint sh_band(uint i) {
    uint l = 0u;
    while ((l + 1u) * (l + 1u) <= i) {
        l += 1u;
    }
    return l;
}

void sh_project_add(inout vec3 c[SH_COEFFS], vec3 d, vec3 value, float weight) {
    float y[SH_COEFFS];
    sh_basis(d, y);
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        c[i] += value * (weight * y[i]);
    }
}

vec3 sh_reconstruct(vec3 c[SH_COEFFS], vec3 d) {
    float y[SH_COEFFS];
    sh_basis(d, y);
    vec3 acc = vec3(0.0);
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        acc += c[i] * y[i];
    }
    return acc;
}

// The fixed local directions of the frame change, one per coefficient (Rust SH_FRAME_DIRS).
vec3 sh_frame_dir(int k) {
    const float H = 0.70710678;
    const float T = 0.57735026;
    const vec3 dirs[SH_COEFFS] = vec3[SH_COEFFS](
        vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0),
        vec3(H, H, 0.0), vec3(0.0, H, H), vec3(0.0, 0.0, 1.0), vec3(H, 0.0, H), vec3(1.0, 0.0, 0.0),
        vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(H, H, 0.0),
        vec3(H, 0.0, H), vec3(0.0, H, -H), vec3(T, T, T));
    return dirs[k];
}

vec3 sh_band_value(vec3 c[SH_COEFFS], uint band, vec3 d) {
    float y[SH_COEFFS];
    sh_basis(d, y);
    vec3 acc = vec3(0.0);
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        if (sh_band(uint(i)) == band) {
            acc += c[i] * y[i];
        }
    }
    return acc;
}

void sh_frame_values(vec3 c[SH_COEFFS], vec3 t, vec3 b, vec3 n, out vec3 values[SH_COEFFS]) {
    for (int k = 0; k < int(SH_COEFFS); ++k) {
        vec3 d = sh_frame_dir(k);
        values[k] = sh_band_value(c, sh_band(uint(k)), t * d.x + b * d.y + n * d.z);
    }
}

// Rust returns the frame (t, b, n); here t and b are out parameters (n is the input).
void sh_view_frame(vec3 n, vec3 v, out vec3 t, out vec3 b) {
    vec3 tv = v - n * dot(n, v);
    float len = length(tv);
    if (len > 1e-6) {
        t = tv / len;
    } else {
        vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        t = normalize(a - n * dot(n, a));
    }
    b = cross(n, t);
}

#endif
