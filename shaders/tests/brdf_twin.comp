// tests/brdf_twin.comp — Rust: tests/tests/brdf_glsl.rs (harness tests/src/twin.rs)
// GPU side of tests/tests/brdf_glsl.rs: evaluates the production GLSL twin of radcache-material
// (common/brdf.glsl, common/polygon.glsl) over a table of input rows, one invocation per row, and writes the results
// for comparison with the Rust functions. Every row is 16 vec4 in and 16 vec4 out (the harness of
// tests/src/twin.rs). The layout of each mode is documented at its function and mirrored by the
// Rust test.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/brdf.glsl"
#include "../common/polygon.glsl"

layout(local_size_x = 64) in;

struct Row {
    vec4 v[16];
};

layout(binding = 0, std430) readonly buffer Inputs { Row inputs[]; };
layout(binding = 1, std430) writeonly buffer Outputs { Row outputs[]; };
// Unused by this shader (the harness binds it for every twin shader).
layout(binding = 2, std430) readonly buffer Samples { vec4 samples[]; };

layout(push_constant) uniform Push {
    uint mode;
    uint count;
} pc;

// The modes are radcache_shared::consts::BrdfTwinMode (BRDF_TWIN_* in constants.glsl).

// in: 0 (f0, f90); 1 (cos_theta, ior, alpha, n_dot_l); 2 (specular_colour, n_dot_v);
// 3 (microfacet normal m, roughness); 4 (c, -) for max/mean_component.
// out: 0 (fresnel_schlick(f0, f90, cos_theta), schlick_weight(cos_theta));
// 1 (dielectric_f0(ior, specular_colour), f0_from_ior(ior));
// 2 (ggx_d(alpha, m), smith_lambda(alpha, cos_theta), smith_g1(alpha, cos_theta),
//    smith_v_correlated(alpha, n_dot_l, n_dot_v));
// 3 (alpha_from_roughness(roughness), max_component(c), mean_component(c),
//    schlick_hemispherical_mean(n_dot_v)).
void terms(Row i, inout Row o) {
    float cos_theta = i.v[1].x, ior = i.v[1].y, alpha = i.v[1].z, n_dot_l = i.v[1].w;
    float n_dot_v = i.v[2].w;
    o.v[0] = vec4(fresnel_schlick(i.v[0].xyz, i.v[0].w, cos_theta), schlick_weight(cos_theta));
    o.v[1] = vec4(dielectric_f0(ior, i.v[2].xyz), f0_from_ior(ior));
    o.v[2] = vec4(ggx_d(alpha, i.v[3].xyz), smith_lambda(alpha, cos_theta), smith_g1(alpha, cos_theta),
                  smith_v_correlated(alpha, n_dot_l, n_dot_v));
    o.v[3] = vec4(alpha_from_roughness(i.v[3].w), max_component(i.v[4].xyz), mean_component(i.v[4].xyz),
                  schlick_hemispherical_mean(n_dot_v));
}

// in: 0 (base_colour, metallic); 1 (roughness, ior, specular_factor, -); 2 (specular_colour, -);
// 3 v; 4 l; 5 u; 6 (microfacet normal m, alpha).
// out: 0 (brdf_eval_lobes.diffuse, diffuse_share(v.z)); 1 (brdf_eval_lobes.specular,
// specular_lobe_probability(v.z)); 2 (brdf_eval, brdf_pdf); 3 (sample_ggx_vndf(alpha, v, u.x, u.y),
// ggx_vndf_pdf(alpha, v, m)); 4 (brdf_reflect(v, m), ggx_reflection_pdf(alpha, v, l));
// 5 (sample_cosine_hemisphere(u.x, u.y), cosine_hemisphere_pdf(l)); 6 (brdf_sample.l,
// brdf_sample.pdf); 7 (brdf_sample.weight, -).
void brdf(Row i, inout Row o) {
    Material m = Material(i.v[0].xyz, i.v[0].w, i.v[1].x, i.v[1].y, i.v[1].z, i.v[2].xyz);
    vec3 v = i.v[3].xyz, l = i.v[4].xyz, u = i.v[5].xyz, mf = i.v[6].xyz;
    float alpha = i.v[6].w;
    BrdfLobes lobes = brdf_eval_lobes(m, v, l);
    o.v[0] = vec4(lobes.diffuse, diffuse_share(m, v.z));
    o.v[1] = vec4(lobes.specular, specular_lobe_probability(m, v.z));
    o.v[2] = vec4(brdf_eval(m, v, l), brdf_pdf(m, v, l));
    o.v[3] = vec4(sample_ggx_vndf(alpha, v, u.x, u.y), ggx_vndf_pdf(alpha, v, mf));
    o.v[4] = vec4(brdf_reflect(v, mf), ggx_reflection_pdf(alpha, v, l));
    o.v[5] = vec4(sample_cosine_hemisphere(u.x, u.y), cosine_hemisphere_pdf(l));
    BrdfSample s = brdf_sample(m, v, u);
    o.v[6] = vec4(s.l, s.pdf);
    o.v[7] = vec4(s.weight, 0.0);
}

// in: 0 (p, -); 1 (n, -); 2, 3, 4 the triangle's corners; 5, 6 unit vectors a, b.
// out: 0 (triangle_projected_solid_angle(p, n, t), clip_to_hemisphere's count,
// edge_term(n, a, b), -); 1..4 the clipped vertices (vectors from p; zero past the count).
void polygon(Row i, inout Row o) {
    vec3 t[3] = vec3[3](i.v[2].xyz, i.v[3].xyz, i.v[4].xyz);
    vec3 q[4];
    for (int k = 0; k < 4; ++k) {
        q[k] = vec3(0.0);
    }
    uint count = clip_to_hemisphere(i.v[0].xyz, i.v[1].xyz, t, q);
    float psa = triangle_projected_solid_angle(i.v[0].xyz, i.v[1].xyz, t);
    o.v[0] = vec4(psa, float(count), edge_term(i.v[1].xyz, i.v[5].xyz, i.v[6].xyz), 0.0);
    for (uint k = 0u; k < count; ++k) {
        o.v[1u + k] = vec4(q[k], 0.0);
    }
}

void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) {
        return;
    }
    Row i = inputs[id];
    Row o;
    for (int c = 0; c < 16; ++c) {
        o.v[c] = vec4(0.0);
    }
    if (pc.mode == BRDF_TWIN_TERMS) {
        terms(i, o);
    } else if (pc.mode == BRDF_TWIN_BRDF) {
        brdf(i, o);
    } else if (pc.mode == BRDF_TWIN_POLYGON) {
        polygon(i, o);
    }
    outputs[id] = o;
}
