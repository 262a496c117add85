// common/polygon.glsl — Rust: crates/radcache-material/src/polygon.rs (the CPU twin, function for
// function; compared on lavapipe by tests/tests/brdf_glsl.rs)
// The irradiance a uniformly emitting triangle sends to a Lambertian receiver, in closed form
// (docs/materials.md §7): Lambert's formula for the projected solid angle after clipping the
// triangle to the receiver's upper hemisphere.
#ifndef RADCACHE_POLYGON_GLSL
#define RADCACHE_POLYGON_GLSL

// `t` clipped to the half-space n·(x − p) ≥ 0, written to q as vectors from p in winding order;
// returns the vertex count (0, 3 or 4).
uint clip_to_hemisphere(vec3 p, vec3 n, vec3 t[3], out vec3 q[4]) {
    // Each corner's side is decided once, so an edge and its neighbour agree on it (at most 4
    // vertices come out; recomputing a distance could round differently and overflow q).
    // Every array index below is a constant once the fixed-count loops are unrolled (a vertex
    // goes to slot k == count), so the arrays live in registers: no indexed local memory.
    q[0] = vec3(0.0);
    q[1] = vec3(0.0);
    q[2] = vec3(0.0);
    q[3] = vec3(0.0);
    float d[3];
    for (uint i = 0u; i < 3u; ++i) {
        d[i] = dot(n, t[i] - p);
    }
    uint count = 0u;
    for (uint i = 0u; i < 3u; ++i) {
        uint j = i == 2u ? 0u : i + 1u;
        vec3 a = t[i] - p;
        vec3 b = t[j] - p;
        bool a_in = d[i] >= 0.0;
        bool b_in = d[j] >= 0.0;
        if (a_in && count < 4u) {
            for (uint k = 0u; k < 4u; ++k) {
                if (k == count) {
                    q[k] = a;
                }
            }
            count++;
        }
        if (a_in != b_in && count < 4u) {
            float s = d[i] / (d[i] - d[j]);
            vec3 c = a + (b - a) * s;
            for (uint k = 0u; k < 4u; ++k) {
                if (k == count) {
                    q[k] = c;
                }
            }
            count++;
        }
    }
    return count < 3u ? 0u : count;
}

// One term of Lambert's sum: the angle of the edge from unit a to unit b over |a × b|, times
// n·(a × b).
float edge_term(vec3 n, vec3 a, vec3 b) {
    vec3 c = cross(a, b);
    float s = length(c);
    float theta = atan(s, dot(a, b));
    float ratio = s > 1e-7 ? theta / s : 1.0;
    return dot(n, c) * ratio;
}

// ∫ cos θ dω of the triangle seen from p (unit normal n), over its part above the tangent plane:
// the irradiance per unit radiance of a uniformly emitting triangle facing p. In [0, π].
float triangle_projected_solid_angle(vec3 p, vec3 n, vec3 t[3]) {
    vec3 q[4];
    uint count = clip_to_hemisphere(p, n, t, q);
    float sum = 0.0;
    for (uint i = 0u; i < 4u; ++i) {
        if (i >= count) {
            break;
        }
        vec3 a = q[i];
        vec3 b = i + 1u < count ? q[(i + 1u) & 3u] : q[0];
        float la = length(a);
        float lb = length(b);
        if (la > 0.0 && lb > 0.0) {
            sum += edge_term(n, a / la, b / lb);
        }
    }
    return min(0.5 * abs(sum), 3.14159265358979);
}

#endif
