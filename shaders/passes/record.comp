// Irradiance records (IC reference §3, §6, §7): one workgroup per requested pixel. The M×N
// stratified cosine-weighted gather rays (one jittered direction per cell of equal projected solid
// angle, in the frame of the shading normal) are traced in parallel; each returns the full
// indirect radiance arriving along it: NEE at its first hit plus the path continued from there
// (MIS, Russian roulette), without the emission of the first hit and without the environment on a
// first-segment miss, which the direct pass accounts for at the shading point. A direction that
// falls below the geometric surface is mirrored into it. One invocation then forms the record
// exactly as the CPU twin `radcache_cache::compute_record` does (E, rotational and Křivánek's
// translational gradients, harmonic-mean and restricted minimum distances), applies the
// gradient limit and the screen-space clamp [R⁻, R⁺] (`finalize_radius`; neighbour clamping is
// a separate pass) and writes the record. Invalid irradiance is stored as black and counted.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/path.glsl"
#include "../common/gbuffer.glsl"
#include "../common/ircache_math.glsl"

#define MAX_STRATA 1728u
#define GROUP 64u

layout(local_size_x = 64) in;

layout(binding = B_GBUFFER_END, std430) readonly buffer Requests { uint requests[]; };
layout(binding = B_GBUFFER_END + 1, std430) buffer Counters { IcCounters counters; };
layout(binding = B_GBUFFER_END + 2, std430) buffer Records { GpuRecord records[]; };
layout(binding = B_GBUFFER_END + 3, std430) buffer RayCount { uint ray_count; };

layout(push_constant) uniform Push {
    uint m;
    uint n;
    uint seed;
    uint level_subframe;   // level (low 16 bits), sub-frame (high 16 bits)
    float min_px;
    float max_px;
    float v_scale;
    float r_eps_rel;       // r_eps = r_eps_rel × scene scale
} pc;

// Radiance per stratum as three float arrays (vec3 arrays would pad to 16 bytes: 1728 strata
// must fit the 32 KiB of shared memory every device offers).
shared float s_lr[MAX_STRATA];
shared float s_lg[MAX_STRATA];
shared float s_lb[MAX_STRATA];
shared float s_r[MAX_STRATA];
shared uint s_rays;

vec3 stratum_l(uint i) {
    return vec3(s_lr[i], s_lg[i], s_lb[i]);
}

void main() {
    uint request = gl_WorkGroupID.x;
    uint index = counters.counts.z + request;
    if (request >= counters.dispatch.x || index >= counters.limits.x) {
        return;
    }
    uint pixel_index = requests[request];
    uint width = frame.resolution.x;
    ivec2 pixel = ivec2(pixel_index % width, pixel_index / width);
    GSample g = gbuffer_load(pixel);
    uint m = clamp(pc.m, 1u, MAX_STRATA / 3u);
    uint n = clamp(pc.n, 3u, MAX_STRATA / m);
    uint count = m * n;
    vec3 nn = normalize_or_z(g.normal);
    vec3 t, b;
    basis_from_normal(nn, t, b);
    vec3 origin = offset_ray_origin(g.position, g.geometric);
    uint record_seed = ircache_hash(pixel_index ^ ircache_hash(pc.seed));
    if (gl_LocalInvocationID.x == 0u) {
        s_rays = 0u;
    }
    barrier();

    for (uint i = gl_LocalInvocationID.x; i < count; i += GROUP) {
        uint j = i / n;
        uint k = i % n;
        float xi, psi;
        stratum_jitter(record_seed, i, xi, psi);
        vec3 dir = frame_to_world(stratum_direction_local(j, k, m, n, xi, psi), t, b, nn);
        float below = dot(dir, g.geometric);
        if (below <= 0.0) {
            dir = normalize(dir - 2.0 * below * g.geometric);
        }
        vec3 l = vec3(0.0);
        float r = IC_FAR;
        rays_traced++;
        rayQueryEXT q;
        rayQueryInitializeEXT(q, tlas, gl_RayFlagsOpaqueEXT, 0xFF, origin, 0.0, dir, 1e30);
        while (rayQueryProceedEXT(q)) {
        }
        if (rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
            r = rayQueryGetIntersectionTEXT(q, true);
            Surface h = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                                   uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                                   rayQueryGetIntersectionBarycentricsEXT(q, true), dir);
            vec3 albedo = material_albedo(h.material, h.uv);
            if (any(greaterThan(albedo, vec3(0.0)))) {
                Rng rng = rng_init(record_seed, i, pc.seed);
                vec3 nee = direct_light(h, rng);
                Ray bounce;
                bounce.dir = sample_cosine_around(h.shading_normal, rng_next2(rng));
                bounce.origin = offset_ray_origin(h.position, h.geometric_normal);
                vec3 further = vec3(0.0);
                if (dot(bounce.dir, h.geometric_normal) > 0.0) {
                    float pdf = dot(bounce.dir, h.shading_normal) * INV_PI;
                    further = trace_path_from(bounce, pdf, true, rng);
                }
                l = albedo * (INV_PI * nee + further);
            }
        }
        if (any(isnan(l)) || any(isinf(l))) {
            l = vec3(0.0);
        }
        s_lr[i] = l.r;
        s_lg[i] = l.g;
        s_lb[i] = l.b;
        s_r[i] = r;
    }
    atomicAdd(s_rays, rays_traced);
    barrier();
    if (gl_LocalInvocationID.x != 0u) {
        return;
    }
    atomicAdd(ray_count, s_rays);

    // The record, as radcache_cache::compute_record.
    float r_eps = pc.r_eps_rel * frame.camera_position.w;
    vec3 sum_l = vec3(0.0);
    vec3 gr[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
    vec3 gt[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
    float sum_inv = 0.0;
    uint valid = 0u;
    float r_min_restricted = IC_FAR;
    for (uint j = 0u; j < m; ++j) {
        bool elevation_ok = stratum_elevation_ok(j, m);
        for (uint k = 0u; k < n; ++k) {
            uint i = stratum_index(j, k, n);
            vec3 lc = stratum_l(i);
            float rc = s_r[i];
            sum_l += lc;
            if (is_valid_sample(rc, r_eps)) {
                valid++;
                sum_inv += inverse_distance(rc, r_eps);
                if (elevation_ok) {
                    r_min_restricted = min(r_min_restricted, rc);
                }
            }
            vec3 cr = frame_to_world(rotational_gradient_coeff(j, k, m, n), t, b, nn);
            vec3 trans[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
            if (j > 0u) {
                uint ip = stratum_index(j - 1u, k, n);
                vec3 d = wall_term(lc, stratum_l(ip), rc, s_r[ip], r_eps);
                vec3 cw = frame_to_world(polar_wall_coeff(j, k, m, n), t, b, nn);
                trans[0] = cw * d.x;
                trans[1] = cw * d.y;
                trans[2] = cw * d.z;
            }
            uint kp = k == 0u ? n - 1u : k - 1u;
            uint ip = stratum_index(j, kp, n);
            vec3 d = wall_term(lc, stratum_l(ip), rc, s_r[ip], r_eps);
            vec3 ca = frame_to_world(azimuthal_wall_coeff(j, k, m, n), t, b, nn);
            for (int c = 0; c < 3; ++c) {
                gr[c] += cr * lc[c];
                gt[c] += trans[c] + ca * d[c];
            }
        }
    }
    vec3 e = sum_l * stratum_projected_solid_angle(m, n);
    uint flags = 0u;
    if (!irradiance_is_valid(e)) {
        e = vec3(0.0);
        gr[0] = gr[1] = gr[2] = vec3(0.0);
        gt[0] = gt[1] = gt[2] = vec3(0.0);
        flags |= 1u;
        atomicAdd(counters.limits.w, 1u);
    }
    float r_harm = harmonic_mean_distance(sum_inv, float(valid));
    float r_raw = max(r_harm, min(r_min_restricted, IC_FAR));
    float r_lo, r_hi;
    radius_bounds(g.footprint, pc.min_px, pc.max_px, pc.v_scale, r_lo, r_hi);
    float r_orig, r_used, lo, hi, att;
    finalize_radius(r_raw, e, gt[0], gt[1], gt[2], IC_FAR, r_lo, r_hi, r_orig, r_used, lo, hi, att);

    GpuRecord rec;
    rec.position_radius = vec4(g.position, r_used);
    rec.normal_rorig = vec4(nn, r_orig);
    rec.irradiance = vec4(e, att);
    rec.bounds = vec4(lo, hi, g.footprint, r_harm);
    rec.grad_r_red = vec4(gr[0], 0.0);
    rec.grad_r_green = vec4(gr[1], 0.0);
    rec.grad_r_blue = vec4(gr[2], 0.0);
    rec.grad_t_red = vec4(gt[0], 0.0);
    rec.grad_t_green = vec4(gt[1], 0.0);
    rec.grad_t_blue = vec4(gt[2], 0.0);
    rec.info = uvec4(pixel_index, pc.level_subframe & 0xffffu, pc.level_subframe >> 16u, flags);
    records[index] = rec;
}
