// common/normal_map.glsl — Rust: crates/radcache-material/src/normal_map.rs
// Normal mapping (docs/materials.md §12): the shading normal from a tangent-space normal-map
// texel, with its guards. Used by surface_at (common/scene.glsl) and the G-buffer
// (passes/gbuffer.frag); the Rust functions of the same names are the reference.
#ifndef RADCACHE_NORMAL_MAP_GLSL
#define RADCACHE_NORMAL_MAP_GLSL

#include "../shared/constants.glsl"

// A unit vector perpendicular to the unit vector n: n × x, or n × y when n is near the x axis.
vec3 normal_map_perpendicular(vec3 n) {
    vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    return normalize(cross(n, a));
}

// 2·texel − 1 with x and y times scale (glTF normalTexture.scale); not normalized.
vec3 normal_map_decode(vec3 texel, float scale) {
    vec3 m = texel * 2.0 - 1.0;
    return vec3(m.x * scale, m.y * scale, m.z);
}

// The shading normal from unit interpolated normal n, unit geometric normal ng (same side),
// tangent (xyz any length, w the handedness with the instance's mirroring applied) and a linear
// texel: n falls back to ng past its horizon; the tangent is made perpendicular to n (a fallback
// where nothing is left); b = (n × t)·sign(w); ns = normalize(t·x + b·y + n·z) (n when that is
// zero or not finite); a cosine c to ng below NORMAL_MAP_COS_MIN (ε) is bent toward ng:
// normalize(ns + (ε − c)·ng), cosine ε/√(1 − c² + ε²).
vec3 normal_map_normal(vec3 n, vec3 ng, vec4 tangent, vec3 texel, float scale) {
    n = dot(n, ng) > 0.0 ? n : ng;
    vec3 t_in = tangent.xyz;
    vec3 t = t_in - n * dot(n, t_in);
    float len = length(t);
    t = len > 1e-6 * length(t_in) ? t / len : normal_map_perpendicular(n);
    float sign_w = tangent.w < 0.0 ? -1.0 : 1.0;
    vec3 b = cross(n, t) * sign_w;
    vec3 m = normal_map_decode(texel, scale);
    vec3 mapped = t * m.x + b * m.y + n * m.z;
    float l = length(mapped);
    vec3 ns = (l > 0.0 && !isinf(l) && !isnan(l)) ? mapped / l : n;
    float c = dot(ns, ng);
    if (c < NORMAL_MAP_COS_MIN) {
        vec3 bent = ns + ng * (NORMAL_MAP_COS_MIN - c);
        return bent / length(bent);
    }
    return ns;
}

#endif
