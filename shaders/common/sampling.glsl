// common/sampling.glsl — Rust: crates/radcache-cache/src/sampling.rs
// Sampling routines shared by the path tracer, direct lighting and record computation.
#ifndef RADCACHE_SAMPLING_GLSL
#define RADCACHE_SAMPLING_GLSL

const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;

// A right-handed orthonormal basis (t, b, n) with t × b = n (Duff et al., "Building an
// Orthonormal Basis, Revisited", JCGT 2017). `n` must be unit length.
void orthonormal_basis(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about +z (Malley's method: uniform disk lifted to the hemisphere).
// pdf = cos(theta) / pi.
vec3 sample_cosine_hemisphere(vec2 u) {
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

// A direction in world space, cosine-distributed about unit normal n.
vec3 sample_cosine_around(vec3 n, vec2 u) {
    vec3 t, b;
    orthonormal_basis(n, t, b);
    vec3 d = sample_cosine_hemisphere(u);
    return normalize(t * d.x + b * d.y + n * d.z);
}

// Uniform barycentrics (b1, b2) on a triangle (Turk 1990 / pbrt's sqrt parametrisation).
vec2 sample_triangle(vec2 u) {
    float su = sqrt(u.x);
    return vec2(1.0 - su, u.y * su);
}

// Balance of squares (power heuristic, beta = 2) for two strategies.
float power_heuristic(float pdf_a, float pdf_b) {
    float a = pdf_a * pdf_a;
    float b = pdf_b * pdf_b;
    return a + b > 0.0 ? a / (a + b) : 0.0;
}

// Rec. 709 luminance.
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

#endif
