// passes/direct_light.glsl — included by passes/direct.comp (crates/radcache-render/src/passes/direct.rs)
// The direct pass's estimators: the Kronecker sample sequences, the one-sample MIS of sampled
// sources (one_sample; one_sample_brdf with the full BRDF and per-pixel technique
// probabilities), the punctual lights, the specular lobe's path-traced indirect light and the
// sums of the emitters' ratio estimator. It reads what direct.comp declares before including it
// (the push constants, the shadow words, `Reuse`).
#ifndef RADCACHE_DIRECT_LIGHT_GLSL
#define RADCACHE_DIRECT_LIGHT_GLSL

const float ONE_MINUS_EPS = 0.99999994;

vec3 kronecker3(uint g, vec3 shift) {
    const vec3 alpha = vec3(0.8191725134, 0.6710436067, 0.5497004779);
    return min(fract(shift + float(g) * alpha), vec3(ONE_MINUS_EPS));
}

vec2 kronecker2(uint g, vec2 shift) {
    const vec2 alpha = vec2(0.7548776662, 0.5698402910);
    return min(fract(shift + float(g) * alpha), vec2(ONE_MINUS_EPS));
}

// The sky in the records (IC_SKY_IN_RECORDS, docs/cache-frame.md §8.3): a constant environment's
// light then reaches the frame through the records' gathers, which count it on a first-segment
// miss, and this pass leaves it out (it samples only emitters, the map and punctual lights).
#if defined(HAS_ENV_CONSTANT) && !defined(IC_SKY_IN_RECORDS)
#define DIRECT_ENV_CONSTANT
#endif

// The environment light this pass accounts for along direction d.
vec3 direct_environment(vec3 d) {
#ifdef IC_SKY_IN_RECORDS
    return environment_map_radiance(d);
#else
    return environment_radiance(d);
#endif
}

// One-sample MIS (Veach 1997, §9.2.4, balance heuristic): each sample picks ONE technique (a
// point on an emitter, a direction of the environment map, or a cosine-distributed BSDF
// direction) with probability c_t and casts one ray; its contribution f(x) / Σ_t c_t·p_t(x)
// (sum over the techniques that can produce x for that source) is unbiased and costs one ray per
// sample instead of one per technique. Probabilities are fixed by the plan: light sampling gets
// weight 1 per source kind, BSDF sampling 0.25 (1 when a constant environment, which only BSDF
// sampling finds, is present), normalized.
// With HAS_ANALYTIC_EMITTERS the emitters are outside the one-sample MIS (their own estimate is
// emitter_ratio_estimate) and BSDF sampling serves the environment alone — with HAS_SPECULAR at
// Lambertian pixels only: a pixel with a specular lobe keeps the emitters in its MIS
// (`Techniques`, chosen per pixel; docs/cache-frame.md §8.2).
#if defined(HAS_EMITTERS) && (!defined(HAS_ANALYTIC_EMITTERS) || defined(HAS_SPECULAR))
#define MIS_EMITTERS
const float W_EMITTER = 1.0;
#else
const float W_EMITTER = 0.0;
#endif
#ifdef HAS_ENV_MAP
const float W_ENV = 1.0;
#else
const float W_ENV = 0.0;
#endif
#if defined(DIRECT_ENV_CONSTANT) || defined(HAS_SPECULAR)
// A constant environment only BSDF sampling finds; a specular lobe, BSDF sampling finds best.
const float W_BSDF = 1.0;
#else
const float W_BSDF = 0.25;
#endif
// Without emitters or an environment there is nothing to sample (punctual lights only).
#if defined(MIS_EMITTERS) || defined(HAS_ENV_MAP) || defined(DIRECT_ENV_CONSTANT)
#define HAS_SAMPLED_SOURCES
#endif
// A specular lobe takes a constant sky here even when the records carry it (one_sample_brdf).
#if defined(HAS_SPECULAR) && defined(HAS_ENV_CONSTANT) && !defined(HAS_SAMPLED_SOURCES)
#define HAS_SAMPLED_SOURCES
#endif
// Sources the one-sample MIS finds besides the emitters (a closed-form pixel needs no loop
// without them).
#if defined(HAS_ENV_MAP) || defined(DIRECT_ENV_CONSTANT)
#define MIS_ENVIRONMENT
#endif
const float C_EMITTER = W_EMITTER / (W_EMITTER + W_ENV + W_BSDF);
const float C_ENV = W_ENV / (W_EMITTER + W_ENV + W_BSDF);
const float C_BSDF = W_BSDF / (W_EMITTER + W_ENV + W_BSDF);

// Solid-angle pdf of the environment-map technique for direction d (0 without a map).
float env_technique_pdf(vec3 d) {
#ifdef HAS_ENV_MAP
    return environment_pdf(d);
#else
    return 0.0;
#endif
}

// One sample of the irradiance-like estimate Σ L·cos/pdf: `u_pick` chooses the technique, `u3`
// drives light sampling, `u2` the BSDF direction.
vec3 one_sample(Surface s, vec3 origin, float u_pick, vec3 u3, vec2 u2) {
#ifdef MIS_EMITTERS
    if (u_pick < C_EMITTER) {
        vec3 dir, le;
        float dist, pdf;
        if (!sample_emitter(s.position, u3, dir, dist, le, pdf)) {
            return vec3(0.0);
        }
        float cos_s = dot(s.shading_normal, dir);
        if (cos_s <= 0.0 || dot(s.geometric_normal, dir) <= 0.0 ||
            !unoccluded_to(origin, s.position, dir, dist)) {
            return vec3(0.0);
        }
        return le * cos_s / (C_EMITTER * pdf + C_BSDF * cos_s * INV_PI);
    }
#endif
#ifdef HAS_ENV_MAP
    if (u_pick < C_EMITTER + C_ENV) {
        vec3 dir, le;
        float pdf;
        if (!sample_environment(u3, dir, le, pdf)) {
            return vec3(0.0);
        }
        float cos_s = dot(s.shading_normal, dir);
        if (cos_s <= 0.0 || dot(s.geometric_normal, dir) <= 0.0 || !unoccluded(origin, dir, 1e30)) {
            return vec3(0.0);
        }
        return direct_environment(dir) * cos_s / (C_ENV * pdf + C_BSDF * cos_s * INV_PI);
    }
#endif
    vec3 dir = sample_cosine_around(s.shading_normal, u2);
    float cos_s = dot(s.shading_normal, dir);
    if (cos_s <= 0.0 || dot(dir, s.geometric_normal) <= 0.0) {
        return vec3(0.0);
    }
    float pdf_bsdf = cos_s * INV_PI;
    rays_traced++;
    rayQueryEXT q;
    scene_trace(q, 0u, origin, dir, 1e30);
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        return direct_environment(dir) * cos_s /
               (C_ENV * env_technique_pdf(dir) + C_BSDF * pdf_bsdf);
    }
    Surface h = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                           uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                           rayQueryGetIntersectionBarycentricsEXT(q, true), dir);
#ifdef HAS_ANALYTIC_EMITTERS
    return vec3(0.0);  // an emitter: emitter_ratio_estimate accounts for it
#else
    vec3 le = material_emission(h.material, h.uv, h.front_face);
    if (all(equal(le, vec3(0.0)))) {
        return vec3(0.0);
    }
    float pdf_light = 0.0;
#ifdef MIS_EMITTERS
    float t = rayQueryGetIntersectionTEXT(q, true);
    pdf_light = emitter_hit_pdf(h.material, h.geometric_normal, dir, t);
#endif
    return le * cos_s / (C_EMITTER * pdf_light + C_BSDF * pdf_bsdf);
#endif
}

// Whether punctual light `i` reaches the sample: sub-frame 0's answer where `reuse` allows
// (lights below REUSED_LIGHTS), else a shadow ray, whose answer sets bit 2 + i of `seen`.
bool punctual_visible(uint i, vec3 origin, vec3 position, vec3 dir, float dist, Reuse reuse,
                      inout uint seen) {
    if (i < REUSED_LIGHTS && reuse.punctual) {
        return (reuse.frozen & (4u << i)) != 0u;
    }
    bool visible = unoccluded_to(origin, position, dir, dist);
    if (visible && i < REUSED_LIGHTS) {
        seen |= 4u << i;
    }
    return visible;
}

#ifdef HAS_SPECULAR
// The technique probabilities of one pixel's one-sample MIS: C_EMITTER, C_ENV and C_BSDF, or,
// at a pixel whose emitters' light is taken in closed form, the same without the emitters.
struct Techniques {
    float emitter;
    float env;
    float bsdf;
};

Techniques techniques(bool emitters) {
    float w_emitter = emitters ? W_EMITTER : 0.0;
    float total = w_emitter + W_ENV + W_BSDF;
    return Techniques(w_emitter / total, W_ENV / total, W_BSDF / total);
}

// One sample of the reflected radiance Σ f·L·cos/pdf with the full BRDF: the one-sample MIS of
// one_sample with the probabilities `c`, with brdf_sample (docs/materials.md §5) as the BSDF
// technique; `u_pick` in the BSDF technique's share of [0, 1), rescaled, chooses its lobe. With
// c.emitter = 0 (HAS_ANALYTIC_EMITTERS: a Lambertian pixel) an emitter that BSDF sampling hits
// counts 0: the closed form accounts for it.
vec3 one_sample_brdf(Surface s, Bsdf f, vec3 origin, Techniques c, float u_pick, vec3 u3, vec2 u2) {
#ifdef MIS_EMITTERS
    if (u_pick < c.emitter) {
        vec3 dir, le;
        float dist, pdf;
        if (!sample_emitter(s.position, u3, dir, dist, le, pdf)) {
            return vec3(0.0);
        }
        vec3 fc = bsdf_f_cos(f, s, dir);
        if (all(equal(fc, vec3(0.0))) || !unoccluded_to(origin, s.position, dir, dist)) {
            return vec3(0.0);
        }
        return le * fc / (c.emitter * pdf + c.bsdf * bsdf_pdf_dir(f, dir));
    }
#endif
#ifdef HAS_ENV_MAP
    if (u_pick < c.emitter + c.env) {
        vec3 dir, le;
        float pdf;
        if (!sample_environment(u3, dir, le, pdf)) {
            return vec3(0.0);
        }
        vec3 fc = bsdf_f_cos(f, s, dir);
        if (all(equal(fc, vec3(0.0))) || !unoccluded(origin, dir, 1e30)) {
            return vec3(0.0);
        }
        return direct_environment(dir) * fc / (c.env * pdf + c.bsdf * bsdf_pdf_dir(f, dir));
    }
#endif
    float u_lobe = min((u_pick - (c.emitter + c.env)) / c.bsdf, ONE_MINUS_EPS);
    BrdfSample bs = brdf_sample(f.m, f.v, vec3(u2, max(u_lobe, 0.0)));
    vec3 dir = bsdf_world(f, bs.l);
    if (bs.pdf <= 0.0 || dot(dir, s.geometric_normal) <= 0.0) {
        return vec3(0.0);
    }
    vec3 fc = bs.weight * bs.pdf;  // f·cos
    rays_traced++;
    rayQueryEXT q;
    scene_trace(q, 0u, origin, dir, 1e30);
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        vec3 sky = direct_environment(dir) * fc / (c.env * env_technique_pdf(dir) + c.bsdf * bs.pdf);
#if defined(IC_SKY_IN_RECORDS) && defined(HAS_ENV_CONSTANT)
        // The records carry the constant sky for the diffuse lobe (its share is applied in
        // passes/composite.comp); the specular lobe takes it here, from the BSDF technique
        // alone (no other technique finds the constant).
        vec3 spec_fc = brdf_eval_lobes(f.m, f.v, bs.l).specular * bs.l.z;
        sky += frame.environment.rgb * spec_fc / (c.bsdf * bs.pdf);
#endif
        return sky;
    }
    Surface h = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                           uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                           rayQueryGetIntersectionBarycentricsEXT(q, true), dir);
    vec3 le = material_emission(h.material, h.uv, h.front_face);
    if (all(equal(le, vec3(0.0)))) {
        return vec3(0.0);
    }
#ifdef HAS_ANALYTIC_EMITTERS
    if (c.emitter == 0.0) {
        return vec3(0.0);  // an emitter of a closed-form pixel: emitter_ratio_sums accounts for it
    }
#endif
    float pdf_light = 0.0;
#ifdef MIS_EMITTERS
    float t = rayQueryGetIntersectionTEXT(q, true);
    pdf_light = emitter_hit_pdf(h.material, h.geometric_normal, dir, t);
#endif
    return le * fc / (c.emitter * pdf_light + c.bsdf * bs.pdf);
}

// The punctual lights reflected by the full BRDF (visibility as in `punctual`).
vec3 punctual_brdf(Surface s, Bsdf f, vec3 origin, Reuse reuse, inout uint seen) {
    vec3 sum = vec3(0.0);
#ifdef HAS_LIGHTS
    for (uint i = 0u; i < frame.counts.y; ++i) {
        vec3 dir;
        float dist;
        vec3 e = punctual_incident(lights[i], s.position, dir, dist);
        vec3 fc = bsdf_f_cos(f, s, dir);
        if (any(greaterThan(fc, vec3(0.0))) && any(greaterThan(e, vec3(0.0))) &&
            punctual_visible(i, origin, s.position, dir, dist, reuse, seen)) {
            sum += e * fc;
        }
    }
#endif
    return sum;
}

// One path of the specular lobe's indirect light (path traced per pixel, unbiased; pc.specular_paths
// paths per sub-frame, passes/direct.rs `specular_paths`): a direction from the GGX visible
// normals, written to `sample_dir` (world, xyz) with its density (w; 0 where the draw left the
// lobe or the surface: a sample worth 0), and the radiance `radiance` the path that continues
// from it brings back, with nothing counted on its first segment (the light straight from a
// source, a constant sky in the records included, is one_sample_brdf's). `specular_pooled` weighs
// it by the lobe's f·cos/pdf. The diffuse lobe's indirect light is the cache's
// (passes/composite.comp).
void specular_path(Surface s, Bsdf f, vec3 origin, inout Rng rng, out vec4 sample_dir,
                   out vec3 radiance) {
    sample_dir = vec4(0.0);
    radiance = vec3(0.0);
    float alpha = alpha_from_roughness(f.m.roughness);
    vec2 u = rng_next2(rng);
    vec3 l = brdf_normalize_or_z(brdf_reflect(f.v, sample_ggx_vndf(alpha, f.v, u.x, u.y)));
    float pdf = ggx_reflection_pdf(alpha, f.v, l);
    if (l.z < COS_MIN || !(pdf > 0.0)) {
        return;
    }
    Ray ray;
    ray.origin = origin;
    ray.dir = bsdf_world(f, l);
    if (dot(ray.dir, s.geometric_normal) <= 0.0) {
        return;
    }
    PathState st = path_begin(ray, 0.0, false, 2u);
    while (!st.done) {
        path_step(st, rng);
    }
    sample_dir = vec4(ray.dir, pdf);
    radiance = path_radiance(st);
}
#endif

#ifdef HAS_ANALYTIC_EMITTERS
// The sums of the ratio estimator of the emitters' direct light (Heitz, Hill, McGuire 2018,
// "Combining analytic direct illumination and stochastic shadows"; docs/cache-frame.md §8.2):
// over `count` light samples (g = first .. first + count of the pixel's R3 sequence), Σ f/p and
// Σ V·f/p with f the unshadowed integrand. The estimate is the closed-form unshadowed irradiance
// times their ratio, the visible fraction (the same samples above and below: exact where the
// emitters are wholly visible or wholly hidden, noisy only in penumbrae; consistent, biased by
// O(1/count) there).
void emitter_ratio_sums(Surface s, vec3 origin, uint first, uint count, vec3 shift,
                        inout vec3 sum_all, inout vec3 sum_visible) {
    for (uint k = 0u; k < count; ++k) {
        vec3 dir, le;
        float dist, pdf;
        if (!sample_emitter(s.position, kronecker3(first + k, shift), dir, dist, le, pdf)) {
            continue;
        }
        float cos_s = dot(s.shading_normal, dir);
        if (cos_s <= 0.0 || dot(s.geometric_normal, dir) <= 0.0) {
            continue;
        }
        vec3 f = le * cos_s / pdf;
        if (any(isnan(f)) || any(isinf(f))) {
            continue;
        }
        sum_all += f;
        if (unoccluded_to(origin, s.position, dir, dist)) {
            sum_visible += f;
        }
    }
}
#endif

// Punctual lights (delta lights: no sampling, one shadow ray each, the same for every sample):
// the light's visibility from the sample, or sub-frame 0's where `reuse` allows; a traced
// answer for a reused light sets its bit in `seen`.
vec3 punctual(Surface s, vec3 origin, Reuse reuse, inout uint seen) {
    vec3 sum = vec3(0.0);
#ifdef HAS_LIGHTS
    for (uint i = 0u; i < frame.counts.y; ++i) {
        vec3 dir;
        float dist;
        vec3 e = punctual_incident(lights[i], s.position, dir, dist);
        float cos_s = dot(s.shading_normal, dir);
        if (cos_s > 0.0 && dot(s.geometric_normal, dir) > 0.0 && any(greaterThan(e, vec3(0.0))) &&
            punctual_visible(i, origin, s.position, dir, dist, reuse, seen)) {
            sum += e * cos_s;
        }
    }
#endif
    return sum;
}

#endif
