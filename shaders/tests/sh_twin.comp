// tests/sh_twin.comp — Rust: tests/tests/sh_glsl.rs (harness tests/src/twin.rs)
// GPU side of the spherical-harmonics twin test: evaluates common/sh.glsl and common/glossy.glsl
// over a table of input rows, one invocation per row, for comparison with radcache-material's
// `sh` and `glossy`. Every row is 16 vec4 in and 16 vec4 out; the modes are
// radcache_shared::consts::ShTwinMode (SH_TWIN_* in constants.glsl). The harness's sample buffer
// (binding 2) holds the glossy table, read here as floats.
#version 460
#extension GL_GOOGLE_include_directive : require

#define GLOSSY_TABLE_BINDING 2
#include "../common/glossy.glsl"

layout(local_size_x = 64) in;

struct Row {
    vec4 v[16];
};

layout(binding = 0, std430) readonly buffer Inputs { Row inputs[]; };
layout(binding = 1, std430) writeonly buffer Outputs { Row outputs[]; };

layout(push_constant) uniform Push {
    uint mode;
    uint count;
} pc;

// 16 RGB coefficients packed as 48 floats in slots first..first+11.
void unpack_coeffs(Row r, int first, out vec3 c[SH_COEFFS]) {
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        int f = 3 * i;
        c[i] = vec3(r.v[first + (f / 4)][f % 4], r.v[first + ((f + 1) / 4)][(f + 1) % 4],
                    r.v[first + ((f + 2) / 4)][(f + 2) % 4]);
    }
}

void pack_coeffs(vec3 c[SH_COEFFS], int first, inout Row r) {
    for (int i = 0; i < int(SH_COEFFS); ++i) {
        for (int k = 0; k < 3; ++k) {
            int f = 3 * i + k;
            r.v[first + (f / 4)][f % 4] = c[i][k];
        }
    }
}

// in: 0 (d, weight); 1 (value, -); 4..15 coefficients c.
// out: 0..3 sh_basis(d) (16 floats); 4..15 c after sh_project_add(c, d, value, weight).
void basis(Row i, inout Row o) {
    vec3 d = i.v[0].xyz;
    float y[SH_COEFFS];
    sh_basis(d, y);
    for (int k = 0; k < int(SH_COEFFS); ++k) {
        o.v[k / 4][k % 4] = y[k];
    }
    vec3 c[SH_COEFFS];
    unpack_coeffs(i, 4, c);
    sh_project_add(c, d, i.v[1].xyz, i.v[0].w);
    pack_coeffs(c, 4, o);
}

// in: 0 (n, roughness); 1 (v, metallic); 2 (base colour, ior); 3 (specular colour, specular
// factor); 4..15 coefficients c.
// out: 0 (glossy_radiance(m, n, v, c), -); 1 (sh_view_frame's t, -); 2 (its b, -);
// 3 (sh_reconstruct(c, n), -); 4..15 sh_frame_values(c, t, b, n).
void glossy(Row i, inout Row o) {
    vec3 n = i.v[0].xyz, v = i.v[1].xyz;
    Material m = Material(i.v[2].xyz, i.v[1].w, i.v[0].w, i.v[2].w, i.v[3].w, i.v[3].xyz);
    vec3 c[SH_COEFFS];
    unpack_coeffs(i, 4, c);
    o.v[0] = vec4(glossy_radiance(m, n, v, c), 0.0);
    vec3 t, b;
    sh_view_frame(n, v, t, b);
    o.v[1] = vec4(t, 0.0);
    o.v[2] = vec4(b, 0.0);
    o.v[3] = vec4(sh_reconstruct(c, n), 0.0);
    vec3 values[SH_COEFFS];
    sh_frame_values(c, t, b, n, values);
    pack_coeffs(values, 4, o);
}

// in: as glossy(). out: 4..15 glossy_world_weights(m, n, v).
void weights(Row i, inout Row o) {
    vec3 n = i.v[0].xyz, v = i.v[1].xyz;
    Material m = Material(i.v[2].xyz, i.v[1].w, i.v[0].w, i.v[2].w, i.v[3].w, i.v[3].xyz);
    vec3 w[SH_COEFFS];
    glossy_world_weights(m, n, v, w);
    pack_coeffs(w, 4, o);
}

// in: 0 (d, -). out: 0..3 sh_basis_one(k, d) for k = 0..15; 4 (sh_basis_one(16, d), -).
void basis_one(Row i, inout Row o) {
    for (uint k = 0u; k < SH_COEFFS; ++k) {
        o.v[k / 4u][k % 4u] = sh_basis_one(k, i.v[0].xyz);
    }
    o.v[4].x = sh_basis_one(SH_COEFFS, i.v[0].xyz);
}

void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) {
        return;
    }
    Row i = inputs[id];
    Row o;
    for (int k = 0; k < 16; ++k) {
        o.v[k] = vec4(0.0);
    }
    if (pc.mode == SH_TWIN_BASIS) {
        basis(i, o);
    } else if (pc.mode == SH_TWIN_GLOSSY) {
        glossy(i, o);
    } else if (pc.mode == SH_TWIN_WEIGHTS) {
        weights(i, o);
    } else if (pc.mode == SH_TWIN_BASIS_ONE) {
        basis_one(i, o);
    }
    outputs[id] = o;
}
