// Direct lighting of the cache's frame (compute, ray queries): per surface pixel, `samples`
// next-event estimates (emissive triangles and the environment map with MIS, punctual lights)
// plus, per sample, one cosine-sampled BSDF ray that finds emission and the environment with the
// complementary MIS weight (weight 1 for a constant environment, which has no light sampling).
// Written: albedo/π × the mean estimate (emission itself is in the G-buffer's emission image).
#version 460
#extension GL_GOOGLE_include_directive : require

#define GBUFFER_DIRECT_ACCESS writeonly
#include "../common/path.glsl"
#include "../common/gbuffer.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = B_GBUFFER_END, std430) buffer RayCount { uint ray_count; };

layout(push_constant) uniform Push {
    uint samples;
    uint seed;
    uint pad0;
    uint pad1;
} pc;

// Emission or environment found by a cosine-sampled ray from s, MIS-weighted; times cos/pdf = π.
vec3 bsdf_sample(Surface s, vec3 origin, inout Rng rng) {
    vec3 dir = sample_cosine_around(s.shading_normal, rng_next2(rng));
    if (dot(dir, s.geometric_normal) <= 0.0) {
        return vec3(0.0);
    }
    float pdf = dot(dir, s.shading_normal) * INV_PI;
    rays_traced++;
    rayQueryEXT q;
    rayQueryInitializeEXT(q, tlas, gl_RayFlagsOpaqueEXT, 0xFF, origin, 0.0, dir, 1e30);
    while (rayQueryProceedEXT(q)) {
    }
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        float w = 1.0;
#ifdef HAS_ENV_MAP
        w = power_heuristic(pdf, environment_pdf(dir));
#endif
        return environment_radiance(dir) * w * PI;
    }
    Surface h = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                           uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                           rayQueryGetIntersectionBarycentricsEXT(q, true), dir);
    vec3 le = material_emission(h.material, h.uv, h.front_face);
    if (all(equal(le, vec3(0.0)))) {
        return vec3(0.0);
    }
    float w = 1.0;
#ifdef HAS_EMITTERS
    GpuMaterial m = materials[h.material];
    float t = rayQueryGetIntersectionTEXT(q, true);
    float cos_l = abs(dot(h.geometric_normal, dir));
    float pdf_light = emitter_area_pdf(m.params.z, m.emission.w != 0.0) * t * t / max(cos_l, 1e-8);
    w = power_heuristic(pdf, pdf_light);
#endif
    return le * w * PI;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, ivec2(frame.resolution.xy)))) {
        return;
    }
    GSample g = gbuffer_load(pixel);
    if (!g.surface) {
        imageStore(g_direct, pixel, vec4(0.0));
        return;
    }
    Surface s;
    s.position = g.position;
    s.geometric_normal = g.geometric;
    s.shading_normal = g.normal;
    s.uv = vec2(0.0);
    s.material = g.material;
    s.front_face = true;
    vec3 origin = offset_ray_origin(s.position, s.geometric_normal);
    uint index = uint(pixel.y) * frame.resolution.x + uint(pixel.x);
    vec3 sum = vec3(0.0);
    uint n = max(pc.samples, 1u);
    for (uint k = 0u; k < n; ++k) {
        Rng rng = rng_init(index, k, pc.seed);
        vec3 e = direct_light(s, rng) + bsdf_sample(s, origin, rng);
        if (!any(isnan(e)) && !any(isinf(e))) {
            sum += e;
        }
    }
    imageStore(g_direct, pixel, vec4(g.albedo * INV_PI * sum / float(n), 0.0));
    atomicAdd(ray_count, rays_traced);
}
