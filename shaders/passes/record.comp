// passes/record.comp — Rust: crates/radcache-render/src/passes/record.rs
// Irradiance records (docs/cache-frame.md §4; docs/irradiance-cache.md §2, §2.6, §3, §4, §7; bare
// §N below cite docs/irradiance-cache.md): one workgroup per requested pixel, dispatched indirectly
// from IcCounters.dispatch (crates/radcache-render/src/passes/record.rs).
//
// Request i (taken by workgroup x where i = interleaved_index(x, workgroups), common/dispatch.glsl)
// exists when i < min(requested, request_capacity); it creates record batch_first + i, or, past
// record_capacity, is dropped and counted in dropped_requests.
//
// Gather (§2.1, §2.4): the M×N stratified cosine-weighted directions (stratum_direction_local with
// the deterministic jitter stratum_jitter(record_seed, j·N + k), record_seed = ircache_hash(pixel ^
// ircache_hash(seed)), in the frame basis_from_normal of the SHADING normal) are traced in
// parallel from offset_ray_origin(p, n_geo). A direction below the geometric surface (possible
// only where the shading normal differs from the geometric one) is mirrored about the geometric
// tangent plane, so it stays above both (§2.4 folds them like pbrt's Faceforward; the mirror keeps
// the azimuth); it still counts for its stratum. Each ray returns the full indirect radiance
// arriving along it: next-event estimation at its first hit plus the path continued from there
// (MIS, Russian roulette from the path's second vertex: a record averages M·N paths, so early
// roulette costs little variance per ray saved; common/path.glsl, with path regeneration),
// WITHOUT the emission of the first hit and WITHOUT the environment on a first-segment miss (the
// direct pass accounts for both at the shading point) — except, with IC_SKY_IN_RECORDS, a constant
// environment's radiance on a first-segment miss (the sky in the records, docs/cache-frame.md §8.3).
// r_jk is the first hit's distance, IC_FAR on a miss. A non-finite sample counts as 0.
//
// Record (§2.6, §3, §4): one invocation sums the strata exactly as the CPU twin
// radcache_cache::compute_record does (E, rotational and Křivánek's translational gradients,
// harmonic-mean and elevation-restricted minimum distances; the same per-stratum functions of
// ircache_math.glsl, in the same order), takes R = max(R_harm, R_min_restricted), then
// finalize_radius with no neighbour (IC_FAR; the neighbour pass clamps later) and
// [R⁻, R⁺] = radius_bounds(footprint, min_px, max_px, v_scale). The translational gradient is
// stored unattenuated, its attenuation min(1, R_orig/R⁻) in irradiance.w.
//
// Hessian error control (§10, compiled in with the define IC_HESSIAN, IcParams::error_control):
// R = hessian_radius of the edge Hessians of the sample mesh instead of max(R_harm,
// R_min_restricted); each invocation sums a contiguous run of cells (the CPU twin
// radcache_cache::compute_hessian sums them all in index order) and invocation 0 adds the
// partial sums. The mesh uses the unfolded directions (a folded stratum keeps the direction its
// jitter gives).
//
// Guards (§2.7): irradiance that is not storable (irradiance_is_valid) or a requested pixel without
// a surface gives a REJECTED record: E = 0, no gradients, zero normal (every weight's normal test
// fails), R_orig = IC_FAR (it clamps no neighbour) and R⁻ = R⁺ = R_FLOOR (its splat is empty);
// it is flagged and counted in rejected_records. No field is ever NaN or Inf.
//
// Radiance records (HAS_RADIANCE_CACHE, docs/radiance-caching.md §6.1, §7): the same strata are
// projected a second time, onto the 16 real SH coefficients of the incoming radiance per channel
// (common/sh.glsl, world space), each stratum weighted by its solid angle stratum_solid_angle at
// its (folded) direction; strata that escaped are left out (radiance_sample: the light straight
// from the sky is the direct pass's for the specular lobe). The coefficients' translational
// gradients are the moving-walls sums of radcache_cache::radiance::compute_radiance
// (radiance_polar_wall_coeff, radiance_azimuthal_wall_coeff at the walls' midpoints). They go to
// B_RECORD_RADIANCE at RECORD_RADIANCE_VEC4S·index when that buffer is large enough: the
// RADIANCE_VEC4S vec4 of f32 coefficients (coefficient i's channel c at float 3i + c), the
// gradients' scale s (the largest |gradient|, f32), then the gradients along x, y and z divided
// by s, packed the same way as f16 pairs (radcache_shared::consts::RECORD_RADIANCE_VEC4S). A
// non-finite coefficient is stored as 0, with zero gradients; a non-finite gradient as 0.
//
// Radiance grid (PATH_GRID, docs/cache-frame.md §4.1; common/path_grid.glsl): with a nonzero
// grid_epoch, a gather path's vertex whose cell of the grid is ready (filled by earlier
// dispatches: of the frame, or of earlier frames where the grid is kept with the records,
// docs/temporal.md §3.8) ends the path with the cell's mean continuation radiance, and a path
// that continued from its first hit deposits what it found there into that hit's cell.
//
// Optional sample dump (tests): when the buffer bound at B_GBUFFER_END + 4 holds at least
// (i + 1)·M·N vec4, request i writes (L_jk, r_jk) of its strata at i·M·N + j·N + k.
#version 460
#extension GL_GOOGLE_include_directive : require
#ifdef PATH_GRID
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#endif

#include "../common/path.glsl"
#include "../common/gbuffer.glsl"
#include "../common/ircache_math.glsl"
#include "../shared/push.glsl"

// info.w: flags (RECORD_FLAGS_MASK, the RECORD_FLAG_* of constants.glsl) and 1 + the record's
// mesh instance (from bit RECORD_INSTANCE_SHIFT up; 0 for a rejected record). MAX_STRATA and
// RECORD_GROUP (invocations per record) come from constants.glsl too.

layout(local_size_x = RECORD_GROUP) in;
#include "../common/dispatch.glsl"

layout(binding = B_RECORD_REQUESTS, std430) readonly buffer Requests { uint requests[]; };
layout(binding = B_RECORD_COUNTERS, std430) buffer Counters { IcCounters counters; };
layout(binding = B_RECORD_RECORDS, std430) buffer Records { GpuRecord records[]; };
layout(binding = B_RECORD_RAY_COUNT, std430) buffer RayCount { uint ray_count; };
layout(binding = B_RECORD_SAMPLES, std430) writeonly buffer Samples { vec4 samples[]; };

layout(push_constant) uniform Push { RecordPush pc; };

#ifdef HAS_RADIANCE_CACHE
#include "../common/sh.glsl"
layout(binding = B_RECORD_RADIANCE, std430) writeonly buffer Radiance { uvec4 radiance[]; };
#endif

// Level and sub-frame of the record being written (a refreshed record keeps its own).
uint g_level_subframe;
// 1 + its instance, shifted into place (a refreshed record keeps its own).
uint g_instance_bits = 0u;

// Radiance per stratum as three float arrays (vec3 arrays would pad to 16 bytes: 1728 strata
// must fit the 32 KiB of shared memory every device offers).
shared float s_lr[MAX_STRATA];
shared float s_lg[MAX_STRATA];
shared float s_lb[MAX_STRATA];
shared float s_r[MAX_STRATA];
shared uint s_rays;
shared uint s_folded;
shared uint s_next;  // the next stratum no invocation has taken

vec3 stratum_l(uint i) {
    return vec3(s_lr[i], s_lg[i], s_lb[i]);
}

#ifdef IC_HESSIAN
shared vec4 s_hessian[RECORD_GROUP];  // per-invocation partial sums

// Vertex (j, k) of the sample mesh (row m: the horizon), k wrapping, and its normalised luminance.
vec4 mesh_vertex(uint j, uint k, uint m, uint n, uint seed, float r_eps, float mean_y, out float y) {
    uint kk = k % n;
    uint js = min(j, m - 1u);
    uint i = stratum_index(js, kk, n);
    vec4 v = hessian_vertex(js, kk, m, n, seed, s_r[i], r_eps);
    y = hessian_luminance(luminance_rec709(stratum_l(i)), mean_y);
    return j >= m ? hessian_horizon_vertex(v) : v;
}

// This invocation's share of radcache_cache::compute_hessian: (E', H_tt, H_tb, H_bb).
vec4 hessian_share(uint lid, uint m, uint n, uint seed, float r_eps) {
    uint count = m * n;
    float part = 0.0;
    for (uint i = lid; i < count; i += RECORD_GROUP) {
        part += luminance_rec709(stratum_l(i));
    }
    s_hessian[lid] = vec4(part, 0.0, 0.0, 0.0);
    barrier();
    float sum_y = 0.0;
    for (uint g = 0u; g < RECORD_GROUP; ++g) {
        sum_y += s_hessian[g].x;
    }
    barrier();
    float mean_y = sum_y / float(count);
    float cap_d = -1.0, y_cap = 1.0;
    for (uint k = 0u; k < n; ++k) {
        float y;
        vec4 v = mesh_vertex(0u, k, m, n, seed, r_eps, mean_y, y);
        float d = hessian_vertex_distance(v);
        if (d > cap_d) {
            cap_d = d;
            y_cap = y;
        }
    }
    // A contiguous run of cells, so that along a row cell (j, k−1)'s B, C, D are this cell's
    // BL, B, A and only C, D and AU are new.
    uint per = (count + RECORD_GROUP - 1u) / RECORD_GROUP;
    uint end = min(lid * per + per, count);
    vec4 acc = vec4(0.0);
    vec4 a = vec4(0.0), b = vec4(0.0), c = vec4(0.0), d = vec4(0.0), bl = vec4(0.0);
    float ya = 0.0, yb = 0.0, yc = 0.0, yd = 0.0, y_bl = 0.0;
    for (uint i = lid * per; i < end; ++i) {
        uint j = i / n, k = i % n;
        if (i != lid * per && k != 0u) {
            bl = b;
            y_bl = yb;
            a = d;
            ya = yd;
            b = c;
            yb = yc;
        } else {
            a = mesh_vertex(j, k, m, n, seed, r_eps, mean_y, ya);
            b = mesh_vertex(j + 1u, k, m, n, seed, r_eps, mean_y, yb);
            bl = mesh_vertex(j + 1u, k + n - 1u, m, n, seed, r_eps, mean_y, y_bl);
        }
        c = mesh_vertex(j + 1u, k + 1u, m, n, seed, r_eps, mean_y, yc);
        d = mesh_vertex(j, k + 1u, m, n, seed, r_eps, mean_y, yd);
        float y_au = 0.0;
        vec4 au = j > 0u ? mesh_vertex(j - 1u, k + 1u, m, n, seed, r_eps, mean_y, y_au) : vec4(0.0);
        acc += hessian_cell(a, b, c, d, bl, au, vec4(ya, yb, yc, yd), y_bl, y_au, y_cap, j == 0u, j + 1u == m);
    }
    return acc;
}
#endif

// Stratum i's gather direction, as begin_stratum draws it (folded above the geometric surface).
vec3 stratum_direction(uint i, uint n, uint m, vec3 t, vec3 b, vec3 nn, vec3 ng, uint record_seed) {
    float xi, psi;
    stratum_jitter(record_seed, i, xi, psi);
    vec3 dir = frame_to_world(stratum_direction_local(i / n, i % n, m, n, xi, psi), t, b, nn);
    float below = dot(dir, ng);
    return below <= 0.0 ? normalize(dir - 2.0 * below * ng) : dir;
}

#ifdef HAS_RADIANCE_CACHE
// The gradient sums of the wall invocations: part p (0 polar walls, 1 azimuthal walls) of
// coefficient i at (p·SH_COEFFS + i)·9, axis-major (x, y, z), RGB each.
shared float s_rgrad[2u * SH_COEFFS * 9u];
// The gradients' totals, axis-major (float 3i + c of axis a at 48a + 3i + c), and each
// coefficient's largest |total| (the block's scale is their maximum).
shared float s_gtot[3u * 3u * SH_COEFFS];
shared float s_gmax[SH_COEFFS];
// The coefficients as stored (0 where not finite), for the glossy gradient limit.
shared vec3 s_coeff[SH_COEFFS];

// The radiance of stratum i as the projection sees it (radiance_sample: 0 where it escaped).
vec3 stratum_radiance(uint i) {
    return radiance_sample(stratum_l(i), s_r[i]);
}

// Adds wall (coefficient `coeff`, midpoint direction `dir`, both local) times basis function
// `ci` to the gradient g: g[axis] += d · coeff_world[axis] · Y_ci(dir_world).
void add_wall(inout vec3 g[3], uint ci, vec3 coeff, vec3 dir, vec3 d, vec3 t, vec3 b, vec3 nn) {
    vec3 cw = frame_to_world(coeff, t, b, nn);
    float y = sh_basis_one(ci, frame_to_world(dir, t, b, nn));
    for (int a = 0; a < 3; ++a) {
        g[a] += d * (cw[a] * y);
    }
}

// Record `index`'s radiance coefficients and their gradients (see the header), reduced by 3 ·
// SH_COEFFS invocations: invocation lid sums part lid / SH_COEFFS (0 the projection, 1 the polar
// walls, 2 the azimuthal walls) of coefficient lid % SH_COEFFS; after a barrier the projection's
// invocation adds the two wall parts and stores all. Called by every invocation of the group;
// returns to invocation 0 the record's glossy gradient limit (also stored in lane 0 of the
// block's last vec4; docs/radiance-caching.md §9), IC_FAR to the others and when nothing is
// written.
float project_radiance(uint lid, uint index, uint m, uint n, vec3 t, vec3 b, vec3 nn, vec3 ng,
                      uint record_seed, float r_eps) {
    if (uint(radiance.length()) < (index + 1u) * RECORD_RADIANCE_VEC4S) {
        return IC_FAR;  // uniform over the group
    }
    uint ci = lid % SH_COEFFS;
    uint part = lid / SH_COEFFS;
    vec3 acc = vec3(0.0);
    vec3 g[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
    if (part == 0u) {
        for (uint j = 0u; j < m; ++j) {
            float omega = stratum_solid_angle(j, m, n);
            for (uint k = 0u; k < n; ++k) {
                uint i = stratum_index(j, k, n);
                if (s_r[i] >= IC_FAR) {
                    continue;
                }
                vec3 dir = stratum_direction(i, n, m, t, b, nn, ng, record_seed);
                acc += stratum_l(i) * (omega * sh_basis_one(ci, dir));
            }
        }
    } else if (part == 1u) {
        for (uint j = 1u; j < m; ++j) {
            for (uint k = 0u; k < n; ++k) {
                uint i = stratum_index(j, k, n), ip = stratum_index(j - 1u, k, n);
                vec3 d = wall_term(stratum_radiance(i), stratum_radiance(ip), s_r[i], s_r[ip], r_eps);
                vec3 dir = stratum_direction_local(j, k, m, n, 0.0, 0.5);
                add_wall(g, ci, radiance_polar_wall_coeff(j, k, m, n), dir, d, t, b, nn);
            }
        }
    } else if (part == 2u) {
        for (uint j = 0u; j < m; ++j) {
            for (uint k = 0u; k < n; ++k) {
                uint i = stratum_index(j, k, n);
                uint ip = stratum_index(j, k == 0u ? n - 1u : k - 1u, n);
                vec3 d = wall_term(stratum_radiance(i), stratum_radiance(ip), s_r[i], s_r[ip], r_eps);
                vec3 dir = stratum_direction_local(j, k, m, n, 0.5, 0.0);
                add_wall(g, ci, radiance_azimuthal_wall_coeff(j, k, m, n), dir, d, t, b, nn);
            }
        }
    }
    if (part == 1u || part == 2u) {
        uint at = ((part - 1u) * SH_COEFFS + ci) * 9u;
        for (uint a = 0u; a < 3u; ++a) {
            for (uint c = 0u; c < 3u; ++c) {
                s_rgrad[at + 3u * a + c] = g[a][c];
            }
        }
    }
    barrier();
    uint base = index * RECORD_RADIANCE_VEC4S;
    if (part == 0u) {
        bool finite = !(any(isnan(acc)) || any(isinf(acc)));
        for (uint c = 0u; c < 3u; ++c) {
            uint f = 3u * ci + c;
            radiance[base + f / 4u][f % 4u] = floatBitsToUint(finite ? acc[c] : 0.0);
        }
        s_coeff[ci] = finite ? acc : vec3(0.0);
        float largest = 0.0;
        for (uint a = 0u; a < 3u; ++a) {
            vec3 ga;
            for (uint c = 0u; c < 3u; ++c) {
                ga[c] = s_rgrad[ci * 9u + 3u * a + c] + s_rgrad[(SH_COEFFS + ci) * 9u + 3u * a + c];
            }
            // A gradient is kept only beside a finite coefficient, and only when finite itself.
            bool ok = finite && !(any(isnan(ga)) || any(isinf(ga)));
            for (uint c = 0u; c < 3u; ++c) {
                float v = ok ? ga[c] : 0.0;
                s_gtot[3u * SH_COEFFS * a + 3u * ci + c] = v;
                largest = max(largest, abs(v));
            }
        }
        s_gmax[ci] = largest;
    }
    barrier();
    // The scale s: the largest |gradient| of the record; the gradients are stored as f16 of
    // g/s (in [−1, 1]), so neither the scene's scale nor its radiance can overflow them.
    float scale = 0.0;
    for (uint i = 0u; i < SH_COEFFS; ++i) {
        scale = max(scale, s_gmax[i]);
    }
    scale = scale > 1.0e-30 ? scale : 0.0;
    float inv = scale > 0.0 ? 1.0 / scale : 0.0;
    if (lid == 0u) {
        radiance[base + RADIANCE_VEC4S] = uvec4(floatBitsToUint(scale), 0u, 0u, 0u);
    }
    // Word w of the gradients (axis w / 24, floats 2(w % 24) and 2(w % 24) + 1 of that axis).
    uint words = 3u * 3u * SH_COEFFS / 2u;
    for (uint w = lid; w < words; w += RECORD_GROUP) {
        uint a = w / (words / 3u), pair = w % (words / 3u);
        uint at = 3u * SH_COEFFS * a + 2u * pair;
        vec2 h = clamp(vec2(s_gtot[at], s_gtot[at + 1u]) * inv, vec2(-1.0), vec2(1.0));
        radiance[base + RADIANCE_VEC4S + 1u + w / 4u][w % 4u] = packHalf2x16(h);
    }
    if (lid != 0u) {
        return IC_FAR;
    }
    vec3 coeff_sq = vec3(0.0), grad_sq = vec3(0.0);
    for (uint i = 0u; i < SH_COEFFS; ++i) {
        coeff_sq += s_coeff[i] * s_coeff[i];
    }
    for (uint f = 0u; f < 3u * 3u * SH_COEFFS; ++f) {
        grad_sq[f % 3u] += s_gtot[f] * s_gtot[f];
    }
    float limit = glossy_gradient_limit_from_sums(coeff_sq, grad_sq);
    radiance[base + RECORD_RADIANCE_VEC4S - 1u] = uvec4(floatBitsToUint(limit), 0u, 0u, 0u);
    return limit;
}
#endif

uvec4 record_info(uint pixel_index, uint flags) {
    return uvec4(pixel_index, g_level_subframe & 0xffffu, g_level_subframe >> 16u, flags);
}

uvec4 record_info_instance(uint pixel_index, uint flags) {
    return record_info(pixel_index, flags | g_instance_bits);
}

// A record that can never weigh anything (see the header), counted in rejected_records.
void write_rejected(uint index, vec3 position, float footprint, uint pixel_index, uint flags) {
    GpuRecord rec;
    rec.position_radius = vec4(position, R_FLOOR);
    rec.normal_rorig = vec4(0.0, 0.0, 0.0, IC_FAR);
    rec.irradiance = vec4(0.0);
    rec.bounds = vec4(R_FLOOR, R_FLOOR, footprint, IC_FAR);
    rec.grad_r_red = vec4(0.0);
    rec.grad_r_green = vec4(0.0);
    rec.grad_r_blue = vec4(0.0);
    rec.grad_t_red = vec4(0.0);
    rec.grad_t_green = vec4(0.0);
    rec.grad_t_blue = vec4(0.0);
    rec.info = record_info(pixel_index, flags);
    records[index] = rec;
    atomicAdd(counters.rejected_records, 1u);
}

// Stratum i's gather path: its direction (folded above the geometric surface when the shading
// normal sends it below) from `origin`, with its own random stream. The path is
// trace_path_from's with nothing counted on its first segment and Russian roulette from its second
// vertex on: next-event estimation at the first hit plus the continuation, i.e. the full indirect
// radiance arriving along the ray.
PathState begin_stratum(uint i, uint n, uint m, vec3 origin, vec3 t, vec3 b, vec3 nn, vec3 ng,
                        uint record_seed, uint pass_seed, out Rng rng) {
    float xi, psi;
    stratum_jitter(record_seed, i, xi, psi);
    vec3 dir = frame_to_world(stratum_direction_local(i / n, i % n, m, n, xi, psi), t, b, nn);
    float below = dot(dir, ng);
    if (below <= 0.0) {
        dir = normalize(dir - 2.0 * below * ng);
        atomicOr(s_folded, 1u);
    }
    rng = rng_init(record_seed, i, pass_seed);
    Ray ray;
    ray.origin = origin;
    ray.dir = dir;
    return path_begin(ray, 0.0, false, 1u);
}

void main() {
    uint lid = gl_LocalInvocationID.x;
    // Workgroups take the requests in classes spread over the list (common/dispatch.glsl):
    // lavapipe gives each thread one block of workgroups.
    uint request = interleaved_index(gl_WorkGroupID.x, gl_NumWorkGroups.x);
    // Everything up to the barrier is uniform over the workgroup.
    if (request >= min(counters.requested, counters.request_capacity)) {
        return;
    }
    uint index;
    uint pixel_index;
    uint pass_seed = pc.seed;
    GSample g;
    // The record serves a glossy lobe from the cache (RECORD_FLAG_GLOSSY).
    bool glossy = false;
    g_level_subframe = pc.level_subframe;
#ifdef PATH_GRID
    path_grid_begin(pc.grid_epoch);
#endif
    if (pc.source == RECORD_SOURCE_RECORDS) {
        // Refresh in place: the surface point, normal and footprint are the record's own, and
        // so are its pixel, level and sub-frame, hence its seeds (creation_seed, passes/record.rs): under
        // unchanged lighting the refreshed record reproduces its value.
        index = requests[request];
        if (index >= counters.record_count) {
            return;
        }
        GpuRecord old = records[index];
        if (dot(old.normal_rorig.xyz, old.normal_rorig.xyz) == 0.0) {
            return;  // a rejected record stays rejected
        }
        g_instance_bits = old.info.w & ~RECORD_FLAGS_MASK;
        pixel_index = old.info.x;
        g_level_subframe = old.info.y | (old.info.z << 16u);
        pass_seed = (pc.seed * SEED_SUB_FRAME_MUL) ^ old.info.z;
        g.surface = true;
        g.position = old.position_radius.xyz;
        g.normal = old.normal_rorig.xyz;
        g.geometric = vec3(old.grad_r_red.w, old.grad_r_green.w, old.grad_r_blue.w);
        g.footprint = old.bounds.z;
        glossy = (old.info.w & RECORD_FLAG_GLOSSY) != 0u;
    } else {
        index = counters.batch_first + request;
        if (index >= counters.record_capacity) {
            if (lid == 0u) {
                atomicAdd(counters.dropped_requests, 1u);
            }
            return;
        }
        pixel_index = requests[request];
        ivec2 size = imageSize(g_position);
        uint width = uint(max(size.x, 1));
        uint row = pixel_index / width;
        if (row >= uint(max(size.y, 0))) {
            if (lid == 0u) {
                write_rejected(index, vec3(0.0), 0.0, pixel_index, RECORD_FLAG_NO_SURFACE);
            }
            return;
        }
        g = gbuffer_load(ivec2(pixel_index % width, row));
#if defined(HAS_SPECULAR) && defined(HAS_RADIANCE_CACHE)
        // As the plan counts glossy materials: not Lambertian, and rough enough for the records.
        Material gm = gbuffer_material(g);
        glossy = gm.roughness >= GLOSSY_ROUGHNESS_MIN
                 && (gm.metallic > 0.0 || gm.specular_factor > 0.0);
#endif
        g_instance_bits = (g.instance + 1u) << RECORD_INSTANCE_SHIFT;
        if (!g.surface) {
            if (lid == 0u) {
                write_rejected(index, g.position, g.footprint, pixel_index, RECORD_FLAG_NO_SURFACE);
            }
            return;
        }
    }

    // Records requested at a level no wider than R⁻ gather with the fine strata, unless they
    // were made for a glossy lobe (RECORD_FLAG_GLOSSY), whose radiance coefficients want the
    // samples, and with strata_falloff half the rays per level below the first of those
    // (IcParams::strata_at; docs/irradiance-cache.md §2.8). A refresh takes the record's own
    // level and flag, hence its own strata.
    uint level = g_level_subframe & 0xffffu;
    bool fine = level >= pc.fine_level && !glossy;
    uint m = clamp(fine ? pc.fine_m : pc.m, 1u, MAX_STRATA / 3u);
    uint n = clamp(fine ? pc.fine_n : pc.n, 3u, MAX_STRATA / m);
    if (fine && pc.strata_falloff != 0u) {
        uint fine_m = m, fine_n = n;
        falloff_strata(fine_m, fine_n, level - pc.fine_level, m, n);
    }
    uint count = m * n;
    // The test hook's stride per request: the larger strata, whichever a record took.
    uint stride = max(pc.m * pc.n, pc.fine_m * pc.fine_n);
    vec3 nn = normalize_or_z(g.normal);
    vec3 ng = dot(g.geometric, g.geometric) > 0.0 ? normalize(g.geometric) : nn;
    vec3 t, b;
    basis_from_normal(nn, t, b);
    vec3 origin = offset_ray_origin(g.position, ng);
    uint record_seed = ircache_hash(pixel_index ^ ircache_hash(pass_seed));
    bool dump = uint(samples.length()) >= (request + 1u) * stride;
    if (lid == 0u) {
        s_rays = 0u;
        s_folded = 0u;
        s_next = 0u;
    }
    barrier();

    // Path regeneration: an invocation takes the next untaken stratum whenever its path ends
    // (its first one too), so the invocations of a SIMD group stay busy although their paths have
    // different lengths, and finish together; groups that run ahead take more strata (lavapipe
    // runs a workgroup's SIMD groups one after another between barriers: fixed shares of strata
    // made the draft preset's record pass, 3 strata per invocation, 15 % slower). A stratum's
    // random numbers come from its own index, so the record does not depend on which invocation
    // traced what.
    uint i = atomicAdd(s_next, 1u);
    Rng rng;
    PathState st;
    if (i < count) {
        st = begin_stratum(i, n, m, origin, t, b, nn, ng, record_seed, pass_seed, rng);
    }
    while (i < count) {
        path_step(st, rng);
        if (st.done) {
#ifdef PATH_GRID
            path_grid_finish(st);
#endif
            vec3 l = path_radiance(st);
#ifdef IC_SKY_IN_RECORDS
            // The sky in the records (docs/cache-frame.md §8.3): a first segment that escapes
            // brings the constant environment's radiance, which the direct pass leaves out.
            if (st.first_t >= IC_PATH_MISS) {
                l += frame.environment.rgb;
            }
#endif
            float r = min(st.first_t, IC_FAR);
            s_lr[i] = l.r;
            s_lg[i] = l.g;
            s_lb[i] = l.b;
            s_r[i] = r;
            if (dump) {
                samples[request * stride + i] = vec4(l, r);
            }
            i = atomicAdd(s_next, 1u);
            if (i < count) {
                st = begin_stratum(i, n, m, origin, t, b, nn, ng, record_seed, pass_seed, rng);
            }
        }
    }
    atomicAdd(s_rays, rays_traced);
    barrier();
#ifdef HAS_RADIANCE_CACHE
    float glossy_limit = project_radiance(lid, index, m, n, t, b, nn, ng, record_seed,
                                          pc.r_eps_rel * frame.camera_position.w);
#endif
#ifdef IC_HESSIAN
    vec4 share = hessian_share(lid, m, n, record_seed, pc.r_eps_rel * frame.camera_position.w);
    s_hessian[lid] = share;
    barrier();
#endif
    if (lid != 0u) {
        return;
    }
    atomicAdd(ray_count, s_rays);

    // The sums, as radcache_cache::compute_record (same functions, same order).
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
            uint ip = stratum_index(j, k == 0u ? n - 1u : k - 1u, n);
            vec3 d = wall_term(lc, stratum_l(ip), rc, s_r[ip], r_eps);
            vec3 ca = frame_to_world(azimuthal_wall_coeff(j, k, m, n), t, b, nn);
            for (int c = 0; c < 3; ++c) {
                gr[c] += cr * lc[c];
                gt[c] += trans[c] + ca * d[c];
            }
        }
    }
    vec3 e = sum_l * stratum_projected_solid_angle(m, n);
    uint flags = s_folded != 0u ? RECORD_FLAG_FOLDED : 0u;
    if (!irradiance_is_valid(e)) {
        write_rejected(index, g.position, g.footprint, pixel_index, flags | RECORD_FLAG_INVALID_IRRADIANCE);
        return;
    }

    // Radius (§4.7 steps 1, 3-5; step 2, neighbour clamping, is the neighbour pass).
    float r_harm = harmonic_mean_distance(sum_inv, float(valid));
#ifdef IC_HESSIAN
    vec4 hessian = vec4(0.0);
    for (uint gi = 0u; gi < RECORD_GROUP; ++gi) {
        hessian += s_hessian[gi];
    }
    float r_raw = hessian_radius(hessian, g.footprint);
#else
    float r_raw = max(r_harm, min(r_min_restricted, IC_FAR));
#endif
#ifdef HAS_RADIANCE_CACHE
    // Records for glossy lobes from the cache are flagged, and with GLOSSY_DENSITY also obey
    // the glossy gradient limit (§9 of docs/radiance-caching.md): density follows the incoming
    // radiance's directional detail there, and only there. A refresh keeps the flag its
    // creation set.
    if (glossy) {
        flags |= RECORD_FLAG_GLOSSY;
#ifdef GLOSSY_DENSITY
        r_raw = min(r_raw, glossy_limit);
#endif
    }
#endif
    float r_lo, r_hi;
    radius_bounds(g.footprint, pc.min_px, pc.max_px, pc.v_scale, r_lo, r_hi);
    float r_orig, r_used, lo, hi, att;
    finalize_radius(r_raw, e, gt[0], gt[1], gt[2], IC_FAR, r_lo, r_hi, r_orig, r_used, lo, hi, att);
    flags |= r_orig < lo ? RECORD_FLAG_CLAMPED_UP : 0u;
    flags |= r_orig > hi ? RECORD_FLAG_CLAMPED_DOWN : 0u;

    GpuRecord rec;
    rec.position_radius = vec4(g.position, r_used);
    rec.normal_rorig = vec4(nn, r_orig);
    rec.irradiance = vec4(e, att);
    rec.bounds = vec4(lo, hi, g.footprint, r_harm);
    rec.grad_r_red = vec4(gr[0], ng.x);
    rec.grad_r_green = vec4(gr[1], ng.y);
    rec.grad_r_blue = vec4(gr[2], ng.z);
    rec.grad_t_red = vec4(gt[0], 0.0);
    rec.grad_t_green = vec4(gt[1], 0.0);
    rec.grad_t_blue = vec4(gt[2], 0.0);
    rec.info = record_info_instance(pixel_index, flags);
    records[index] = rec;
}
