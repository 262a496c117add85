// common/brdf.glsl — Rust: crates/radcache-material/src/*.rs (its CPU twin)
// GLSL twin of the `radcache-material` crate: the glTF 2.0 metallic-roughness BRDF with
// KHR_materials_ior and KHR_materials_specular (docs/materials.md, cited as a bare §N): Fresnel
// (§2, fresnel.rs), GGX and Smith (§3, ggx.rs), the BRDF and the diffuse share (§4, §6, brdf.rs),
// sampling and pdfs (§5, sampling.rs). Each function has the same name, arguments (in order) and
// guards as its Rust reference, except `brdf_reflect` (Rust `reflect`; GLSL's built-in
// reflect(I, N) = I − 2(N·I)N is its negative). `Material`, `BrdfLobes` and `BrdfSample` are
// structs with the Rust fields. The Rust docs hold the formulas; comments here only name the
// section. Directions are unit vectors in the local frame, n = +Z. GLSL 4.60 core, no extension;
// include once (guarded). Tests: crates/radcache-material/tests/glsl.rs (every Rust function has a
// twin here, and this file compiles) and tests/tests/brdf_glsl.rs (values on lavapipe).

#ifndef RADCACHE_BRDF_GLSL
#define RADCACHE_BRDF_GLSL

// ALPHA_MIN, COS_MIN, SMITH_LAMBDA_MASKED, SCHLICK_MEAN_C0..C4: declared once in Rust
// (radcache_shared::consts).
#include "../shared/constants.glsl"

// Mathematical constants (f32 π and 1/π, as Rust's std::f32::consts).
const float BRDF_PI = 3.14159265358979;
const float BRDF_FRAC_1_PI = 0.318309886183791;

// glam's `normalize_or(Vec3::Z)`: v · (1/|v|) when that reciprocal is finite and positive, else +Z.
vec3 brdf_normalize_or_z(vec3 v) {
    float rcp = 1.0 / length(v);
    if (!isinf(rcp) && !isnan(rcp) && rcp > 0.0) {
        return v * rcp;
    }
    return vec3(0.0, 0.0, 1.0);
}

// ---- Fresnel (§2, fresnel.rs) ----

float schlick_weight(float cos_theta) {
    float m = clamp(1.0 - cos_theta, 0.0, 1.0);
    float m2 = m * m;
    return m2 * m2 * m;
}

vec3 fresnel_schlick(vec3 f0, float f90, float cos_theta) {
    return f0 + (vec3(f90) - f0) * schlick_weight(cos_theta);
}

float f0_from_ior(float ior) {
    float i = max(ior, 1.0);
    float r = (i - 1.0) / (i + 1.0);
    return r * r;
}

vec3 dielectric_f0(float ior, vec3 specular_colour) {
    return min(max(specular_colour, vec3(0.0)) * f0_from_ior(ior), vec3(1.0));
}

float max_component(vec3 c) { return max(max(c.x, c.y), c.z); }

float mean_component(vec3 c) { return (c.x + c.y + c.z) * (1.0 / 3.0); }

// ---- GGX and Smith (§3, ggx.rs) ----

float alpha_from_roughness(float roughness) {
    float r = clamp(roughness, 0.0, 1.0);
    return max(r * r, ALPHA_MIN);
}

float ggx_d(float alpha, vec3 m) {
    if (m.z <= 0.0) {
        return 0.0;
    }
    float a2 = alpha * alpha;
    float t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    return 1.0 / (BRDF_PI * a2 * t * t);
}

float smith_root(float alpha, float cos_theta) {
    float a2 = alpha * alpha;
    return sqrt(a2 + (1.0 - a2) * cos_theta * cos_theta);
}

float smith_lambda(float alpha, float cos_theta) {
    if (cos_theta <= 0.0) {
        return SMITH_LAMBDA_MASKED;
    }
    return 0.5 * (smith_root(alpha, cos_theta) / cos_theta - 1.0);
}

float smith_g1(float alpha, float cos_theta) {
    if (cos_theta <= 0.0) {
        return 0.0;
    }
    return 2.0 * cos_theta / (cos_theta + smith_root(alpha, cos_theta));
}

float smith_v_correlated(float alpha, float n_dot_l, float n_dot_v) {
    if (n_dot_l <= 0.0 || n_dot_v <= 0.0) {
        return 0.0;
    }
    float denom = n_dot_l * smith_root(alpha, n_dot_v) + n_dot_v * smith_root(alpha, n_dot_l);
    if (denom <= 0.0) {
        return 0.0;
    }
    return 0.5 / denom;
}

// ---- The BRDF (§4, §6, brdf.rs) ----

struct Material {
    vec3 base_colour;
    float metallic;
    float roughness;
    float ior;
    float specular_factor;
    vec3 specular_colour;
};

struct BrdfLobes {
    vec3 diffuse;
    vec3 specular;
};

BrdfLobes brdf_eval_lobes(Material m, vec3 v, vec3 l) {
    BrdfLobes zero = BrdfLobes(vec3(0.0), vec3(0.0));
    if (v.z < COS_MIN || l.z < COS_MIN) {
        return zero;
    }
    vec3 sum = v + l;
    float len = length(sum);
    if (len <= 0.0) {
        return zero;
    }
    vec3 h = sum / len;
    float v_dot_h = clamp(dot(v, h), 0.0, 1.0);
    float metallic = clamp(m.metallic, 0.0, 1.0);
    float s = clamp(m.specular_factor, 0.0, 1.0);
    vec3 base = max(m.base_colour, vec3(0.0));

    vec3 f_metal = fresnel_schlick(min(base, vec3(1.0)), 1.0, v_dot_h);
    vec3 f_diel = fresnel_schlick(dielectric_f0(m.ior, m.specular_colour), 1.0, v_dot_h);

    float alpha = alpha_from_roughness(m.roughness);
    float dv = ggx_d(alpha, h) * smith_v_correlated(alpha, l.z, v.z);

    vec3 diffuse = base * ((1.0 - metallic) * (1.0 - s * max_component(f_diel)) * BRDF_FRAC_1_PI);
    vec3 specular = (f_metal * metallic + f_diel * ((1.0 - metallic) * s)) * dv;
    return BrdfLobes(diffuse, specular);
}

vec3 brdf_eval(Material m, vec3 v, vec3 l) {
    BrdfLobes lobes = brdf_eval_lobes(m, v, l);
    return lobes.diffuse + lobes.specular;
}

float schlick_hemispherical_mean(float n_dot_v) {
    float t = 1.0 - clamp(n_dot_v, 0.0, 1.0);
    return SCHLICK_MEAN_C0 +
           t * (SCHLICK_MEAN_C1 + t * (SCHLICK_MEAN_C2 + t * (SCHLICK_MEAN_C3 + t * SCHLICK_MEAN_C4)));
}

float diffuse_share(Material m, float n_dot_v) {
    if (n_dot_v < COS_MIN) {
        return 0.0;
    }
    float metallic = clamp(m.metallic, 0.0, 1.0);
    float s = clamp(m.specular_factor, 0.0, 1.0);
    float f0 = max_component(dielectric_f0(m.ior, m.specular_colour));
    float mean_f = f0 + (1.0 - f0) * schlick_hemispherical_mean(n_dot_v);
    return (1.0 - metallic) * (1.0 - s * mean_f);
}

// ---- Sampling and pdfs (§5, sampling.rs) ----

vec3 sample_cosine_hemisphere(float u1, float u2) {
    float r = sqrt(clamp(u1, 0.0, 1.0));
    float phi = 2.0 * BRDF_PI * u2;
    return vec3(r * cos(phi), r * sin(phi), sqrt(clamp(1.0 - u1, 0.0, 1.0)));
}

float cosine_hemisphere_pdf(vec3 l) { return max(l.z, 0.0) * BRDF_FRAC_1_PI; }

vec3 sample_ggx_vndf(float alpha, vec3 v, float u1, float u2) {
    vec3 vs = brdf_normalize_or_z(vec3(alpha * v.x, alpha * v.y, v.z));
    float phi = 2.0 * BRDF_PI * u1;
    float z = (1.0 - u2) * (1.0 + vs.z) - vs.z;
    float sin_theta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    vec3 c = vec3(sin_theta * cos(phi), sin_theta * sin(phi), z);
    vec3 hs = c + vs;
    return brdf_normalize_or_z(vec3(alpha * hs.x, alpha * hs.y, max(hs.z, 0.0)));
}

float ggx_vndf_pdf(float alpha, vec3 v, vec3 m) {
    if (v.z < COS_MIN) {
        return 0.0;
    }
    return smith_g1(alpha, v.z) * max(dot(v, m), 0.0) * ggx_d(alpha, m) / v.z;
}

// Rust `reflect(v, m) = 2(v·m)m − v`.
vec3 brdf_reflect(vec3 v, vec3 m) { return m * (2.0 * dot(v, m)) - v; }

float ggx_reflection_pdf(float alpha, vec3 v, vec3 l) {
    if (v.z < COS_MIN) {
        return 0.0;
    }
    vec3 sum = v + l;
    float len = length(sum);
    if (len <= 0.0) {
        return 0.0;
    }
    vec3 h = sum / len;
    float a2 = alpha * alpha;
    float root = sqrt(a2 + (1.0 - a2) * v.z * v.z);
    return 0.5 * ggx_d(alpha, h) / (v.z + root);
}

float specular_lobe_probability(Material m, float n_dot_v) {
    float metallic = clamp(m.metallic, 0.0, 1.0);
    float s = clamp(m.specular_factor, 0.0, 1.0);
    float c = clamp(n_dot_v, 0.0, 1.0);
    vec3 base = max(m.base_colour, vec3(0.0));
    vec3 f_metal = fresnel_schlick(min(base, vec3(1.0)), 1.0, c);
    float f_diel = max_component(fresnel_schlick(dielectric_f0(m.ior, m.specular_colour), 1.0, c));
    float w_s = metallic * mean_component(f_metal) + (1.0 - metallic) * s * f_diel;
    float w_d = (1.0 - metallic) * (1.0 - s * f_diel) * mean_component(base);
    float total = w_s + w_d;
    if (total > 0.0) {
        return clamp(w_s / total, 0.0, 1.0);
    }
    return 0.5;
}

float brdf_pdf(Material m, vec3 v, vec3 l) {
    if (v.z < COS_MIN) {
        return 0.0;
    }
    float p = specular_lobe_probability(m, v.z);
    float alpha = alpha_from_roughness(m.roughness);
    return p * ggx_reflection_pdf(alpha, v, l) + (1.0 - p) * cosine_hemisphere_pdf(l);
}

struct BrdfSample {
    vec3 l;
    float pdf;
    vec3 weight;
};

BrdfSample brdf_sample(Material m, vec3 v, vec3 u) {
    if (v.z < COS_MIN) {
        return BrdfSample(vec3(0.0, 0.0, 1.0), 0.0, vec3(0.0));
    }
    float p = specular_lobe_probability(m, v.z);
    vec3 l;
    if (u.z < p) {
        float alpha = alpha_from_roughness(m.roughness);
        l = brdf_normalize_or_z(brdf_reflect(v, sample_ggx_vndf(alpha, v, u.x, u.y)));
    } else {
        l = sample_cosine_hemisphere(u.x, u.y);
    }
    float pdf = brdf_pdf(m, v, l);
    vec3 weight = vec3(0.0);
    if (!(l.z < COS_MIN || pdf <= 0.0)) {
        weight = brdf_eval(m, v, l) * (l.z / pdf);
    }
    return BrdfSample(l, pdf, weight);
}

#endif
