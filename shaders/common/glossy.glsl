// common/glossy.glsl — Rust: crates/radcache-material/src/glossy.rs (its CPU twin)
// GLSL twin of radcache-material's `glossy`: the lookup of the specular lobe's SH table and the
// radiance a glossy lobe reflects from world-space SH radiance (docs/radiance-caching.md §3).
// The table is not an argument here: the including shader defines GLOSSY_TABLE_BINDING, where
// this file declares the buffer `glossy_table`, the floats Rust's `glossy_table` built
// (GLOSSY_TABLE_ROUGHNESS × GLOSSY_TABLE_NV entries of 2·SH_COEFFS floats). Needs brdf.glsl
// (Material, dielectric_f0) and sh.glsl. Values compared on lavapipe by tests/tests/sh_glsl.rs.
#ifndef RADCACHE_GLOSSY_GLSL
#define RADCACHE_GLOSSY_GLSL

#include "brdf.glsl"
#include "sh.glsl"

#ifndef GLOSSY_TABLE_BINDING
#error "define GLOSSY_TABLE_BINDING (the glossy table's binding) before including glossy.glsl"
#endif
layout(binding = GLOSSY_TABLE_BINDING, std430) readonly buffer GlossyTable { float glossy_table[]; };

// Rust returns the entry; here it is the out parameter g (A's weights, then B's).
void glossy_lookup(float roughness, float n_dot_v, out float g[2 * SH_COEFFS]) {
    float nr = float(GLOSSY_TABLE_ROUGHNESS);
    float nn = float(GLOSSY_TABLE_NV);
    float x = clamp(clamp(roughness, 0.0, 1.0) * (nr - 1.0), 0.0, nr - 1.0);
    float y = clamp((clamp(n_dot_v, GLOSSY_NV_MIN, 1.0) - GLOSSY_NV_MIN) / (1.0 - GLOSSY_NV_MIN) *
                        (nn - 1.0),
                    0.0, nn - 1.0);
    uint j0 = min(uint(floor(x)), GLOSSY_TABLE_ROUGHNESS - 2u);
    uint i0 = min(uint(floor(y)), GLOSSY_TABLE_NV - 2u);
    float fx = x - float(j0);
    float fy = y - float(i0);
    uint stride = 2u * SH_COEFFS;
    uint e00 = (j0 * GLOSSY_TABLE_NV + i0) * stride;
    uint e01 = (j0 * GLOSSY_TABLE_NV + i0 + 1u) * stride;
    uint e10 = ((j0 + 1u) * GLOSSY_TABLE_NV + i0) * stride;
    uint e11 = ((j0 + 1u) * GLOSSY_TABLE_NV + i0 + 1u) * stride;
    for (int k = 0; k < int(2u * SH_COEFFS); ++k) {
        uint u = uint(k);
        float a = glossy_table[e00 + u] * (1.0 - fy) + glossy_table[e01 + u] * fy;
        float b = glossy_table[e10 + u] * (1.0 - fy) + glossy_table[e11 + u] * fy;
        g[k] = a * (1.0 - fx) + b * fx;
    }
}

// Rust returns (K0, K1); here K0 is returned and K1 is the out parameter k1.
vec3 glossy_weights(Material m, out float k1) {
    float metallic = clamp(m.metallic, 0.0, 1.0);
    float s = clamp(m.specular_factor, 0.0, 1.0);
    vec3 base = clamp(m.base_colour, vec3(0.0), vec3(1.0));
    vec3 f0_d = dielectric_f0(m.ior, m.specular_colour);
    k1 = metallic + (1.0 - metallic) * s;
    return base * metallic + f0_d * ((1.0 - metallic) * s);
}

void glossy_world_weights(Material m, vec3 n, vec3 v, out vec3 w[SH_COEFFS]) {
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        w[i] = vec3(0.0);
    }
    float nv = dot(n, v);
    if (!(nv > 0.0)) {
        return;
    }
    vec3 t, b;
    sh_view_frame(n, v, t, b);
    float g[2 * SH_COEFFS];
    glossy_lookup(m.roughness, nv, g);
    float k1;
    vec3 k0 = glossy_weights(m, k1);
    for (int k = 0; k < int(SH_COEFFS); ++k) {
        vec3 d = sh_frame_dir(k);
        float y[SH_COEFFS];
        sh_basis(t * d.x + b * d.y + n * d.z, y);
        vec3 gk = k0 * g[k] + vec3(k1 * g[int(SH_COEFFS) + k]);
        uint band = sh_band(uint(k));
        for (int i = 0; i < int(SH_COEFFS); ++i) {
            if (sh_band(uint(i)) == band) {
                w[i] += gk * y[i];
            }
        }
    }
}

vec3 glossy_radiance(Material m, vec3 n, vec3 v, vec3 c[SH_COEFFS]) {
    vec3 w[SH_COEFFS];
    glossy_world_weights(m, n, v, w);
    vec3 result = vec3(0.0);
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        result += c[i] * w[i];
    }
    return max(result, vec3(0.0));
}

#endif
