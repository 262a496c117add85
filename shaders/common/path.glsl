// Path tracing shared by the reference path tracer, the IC direct-lighting pass and the IC
// record (gather-ray) pass: next-event estimation at a diffuse vertex, and the continuation of a
// path with MIS and Russian roulette.
//
// At each diffuse vertex: next-event estimation of emissive triangles (MIS with BSDF sampling,
// power heuristic), punctual lights (no MIS: delta lights) and the environment map (MIS);
// emission hit by BSDF sampling is counted with the complementary MIS weight, so every light path
// is counted once. Russian roulette from the fourth vertex on, with continuation probability the
// throughput's largest component capped at 0.99; a safety cap of 4096 vertices (reached with
// probability < 0.99^4093, invisible).
#ifndef RADCACHE_PATH_GLSL
#define RADCACHE_PATH_GLSL

#include "random.glsl"
#include "lights.glsl"

const uint MAX_VERTICES = 4096u;
const uint RR_START = 3u;

struct Ray {
    vec3 origin;
    vec3 dir;
};

// The camera ray through sub-pixel position `jitter` of `pixel`. Clip space is Vulkan's (y down)
// with reversed depth (1 at the near plane), so unprojecting depth 1 gives a point on the near
// plane; the ray starts at the camera position (a pinhole).
Ray camera_ray(uvec2 pixel, vec2 jitter) {
    vec2 res = vec2(frame.resolution.xy);
    vec2 ndc = (vec2(pixel) + jitter) / res * 2.0 - 1.0;
    vec4 near_p = frame.world_from_clip * vec4(ndc, 1.0, 1.0);
    Ray r;
    r.origin = frame.camera_position.xyz;
    r.dir = normalize(near_p.xyz / near_p.w - r.origin);
    return r;
}

// Next-event estimate at surface s from all plan-enabled sources: the irradiance-like sum
// Σ L·cos/pdf (MIS-weighted where a BSDF sample could also find the source); multiply by
// albedo/π for the reflected radiance (Lambertian).
vec3 direct_light(Surface s, inout Rng rng) {
    vec3 sum = vec3(0.0);
    vec3 origin = offset_ray_origin(s.position, s.geometric_normal);
#ifdef HAS_EMITTERS
    {
        vec3 dir, le;
        float dist, pdf;
        vec3 u = vec3(rng_next(rng), rng_next2(rng));
        if (sample_emitter(s.position, u, dir, dist, le, pdf)) {
            float cos_s = dot(s.shading_normal, dir);
            if (cos_s > 0.0 && dot(s.geometric_normal, dir) > 0.0 &&
                unoccluded(origin, dir, dist * (1.0 - 1e-4))) {
                float w = power_heuristic(pdf, cos_s * INV_PI);
                sum += le * cos_s * w / pdf;
            }
        }
    }
#endif
#ifdef HAS_LIGHTS
    for (uint i = 0u; i < frame.counts.y; ++i) {
        vec3 dir;
        float dist;
        vec3 e = punctual_incident(lights[i], s.position, dir, dist);
        float cos_s = dot(s.shading_normal, dir);
        if (cos_s > 0.0 && dot(s.geometric_normal, dir) > 0.0 && any(greaterThan(e, vec3(0.0))) &&
            unoccluded(origin, dir, dist * (1.0 - 1e-4))) {
            sum += e * cos_s;
        }
    }
#endif
#ifdef HAS_ENV_MAP
    {
        vec3 dir, le;
        float pdf;
        vec3 u = vec3(rng_next(rng), rng_next2(rng));
        if (sample_environment(u, dir, le, pdf)) {
            float cos_s = dot(s.shading_normal, dir);
            if (cos_s > 0.0 && dot(s.geometric_normal, dir) > 0.0 && unoccluded(origin, dir, 1e30)) {
                float w = power_heuristic(pdf, cos_s * INV_PI);
                sum += le * cos_s * w / pdf;
            }
        }
    }
#endif
    return sum;
}

// Radiance arriving along `ray`. With `count_first_segment` false, light that arrives along the
// first segment straight from a source (emission at the first hit, the environment on a miss) is
// left out: that is the indirect radiance a gather ray must return when the shading point's direct
// light is computed separately. `bsdf_pdf` is the solid-angle pdf with which `ray` was sampled by
// the BSDF (0 for camera rays: no MIS on the first segment).
vec3 trace_path_from(Ray ray, float bsdf_pdf, bool count_first_segment, inout Rng rng) {
    vec3 radiance = vec3(0.0);
    vec3 throughput = vec3(1.0);
    for (uint depth = 0u; depth < MAX_VERTICES; ++depth) {
        bool count_sources = depth > 0u || count_first_segment;
        rays_traced++;
        rayQueryEXT q;
        rayQueryInitializeEXT(q, tlas, gl_RayFlagsOpaqueEXT, 0xFF, ray.origin, 0.0, ray.dir, 1e30);
        while (rayQueryProceedEXT(q)) {
        }
        if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
            if (!count_sources) {
                break;
            }
            vec3 le = environment_radiance(ray.dir);
            float w = 1.0;
#ifdef HAS_ENV_MAP
            if (bsdf_pdf > 0.0) {
                w = power_heuristic(bsdf_pdf, environment_pdf(ray.dir));
            }
#endif
            radiance += throughput * le * w;
            break;
        }
        Surface s = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                               uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                               rayQueryGetIntersectionBarycentricsEXT(q, true), ray.dir);
        vec3 le = count_sources ? material_emission(s.material, s.uv, s.front_face) : vec3(0.0);
        if (any(greaterThan(le, vec3(0.0)))) {
            float w = 1.0;
#ifdef HAS_EMITTERS
            if (bsdf_pdf > 0.0) {
                GpuMaterial m = materials[s.material];
                float t = rayQueryGetIntersectionTEXT(q, true);
                float cos_l = abs(dot(s.geometric_normal, ray.dir));
                float pdf_light = emitter_area_pdf(m.params.z, m.emission.w != 0.0) * t * t /
                                  max(cos_l, 1e-8);
                w = power_heuristic(bsdf_pdf, pdf_light);
            }
#endif
            radiance += throughput * le * w;
        }
        vec3 albedo = material_albedo(s.material, s.uv);
        radiance += throughput * albedo * INV_PI * direct_light(s, rng);

        throughput *= albedo;
        if (depth >= RR_START) {
            float p = min(max(throughput.r, max(throughput.g, throughput.b)), 0.99);
            if (rng_next(rng) >= p) {
                break;
            }
            throughput /= p;
        }
        if (all(equal(throughput, vec3(0.0)))) {
            break;
        }
        ray.dir = sample_cosine_around(s.shading_normal, rng_next2(rng));
        if (dot(ray.dir, s.geometric_normal) <= 0.0) {
            break;  // the shading normal sent the sample below the surface: no contribution
        }
        bsdf_pdf = dot(ray.dir, s.shading_normal) * INV_PI;
        ray.origin = offset_ray_origin(s.position, s.geometric_normal);
    }
    // Guard at the source: a non-finite sample is dropped, never accumulated.
    if (any(isnan(radiance)) || any(isinf(radiance))) {
        return vec3(0.0);
    }
    return radiance;
}

// Radiance arriving along a camera ray (everything counted).
vec3 trace_path(Ray ray, inout Rng rng) {
    return trace_path_from(ray, 0.0, true, rng);
}

#endif
