// common/path.glsl — Rust: crates/radcache-render/src/passes/path_trace.rs and record.rs
// Path tracing shared by the reference path tracer, the IC direct-lighting pass and the IC
// record (gather-ray) pass: next-event estimation at a diffuse vertex, and the continuation of a
// path with MIS and Russian roulette.
//
// At each diffuse vertex: next-event estimation of emissive triangles (MIS with BSDF sampling,
// power heuristic), punctual lights (no MIS: delta lights) and the environment map (MIS);
// emission hit by BSDF sampling is counted with the complementary MIS weight, so every light path
// is counted once. In the cache's gathers of a Lambertian scene with few emitters
// (PATH_CLOSED_FORM_EMITTERS), the emissive triangles' light at a vertex is instead their
// closed-form unshadowed irradiance less a one-sample estimate of its hidden part (a control
// variate, unbiased), and emission hit by BSDF sampling counts nothing. Russian roulette from
// the fourth vertex on (camera paths; the cache's gather paths from their second vertex), with
// continuation probability the throughput's largest component capped at 0.99; a safety cap of
// 4096 vertices (reached with probability < 0.99^4093, invisible).
#ifndef RADCACHE_PATH_GLSL
#define RADCACHE_PATH_GLSL

#include "random.glsl"
#include "lights.glsl"
#ifdef PATH_GRID
#include "path_grid.glsl"
#endif

// Gathers (record.comp, PATH_CLOSED_FORM_EMITTERS) in a Lambertian scene whose few emitters have a
// closed form take the emitters' light at each vertex as a control variate (direct_light).
#if defined(PATH_CLOSED_FORM_EMITTERS) && defined(HAS_EMITTERS) && !defined(HAS_SPECULAR)
#define PATH_EMITTERS_IN_CLOSED_FORM 1
#endif

#if defined(HAS_ANALYTIC_EMITTERS) || defined(PATH_EMITTERS_IN_CLOSED_FORM)
#include "polygon.glsl"

// The unshadowed irradiance of every emissive triangle at `origin` (normal n), in closed form
// (common/polygon.glsl). The plan compiles this in only for a few untextured emitters
// (radcache_scene::ScenePlan::analytic_emitters), so the radiance is the material's constant.
vec3 analytic_emitter_irradiance(vec3 origin, vec3 n) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < frame.counts.x; ++i) {
        GpuEmitter e = emitters[i];
        vec3 ng = cross(e.p1.xyz - e.p0.xyz, e.p2.xyz - e.p0.xyz);
        bool front = dot(origin - e.p0.xyz, ng) > 0.0;
        vec3 le = material_emission(uint(e.uv2_material.z), TexCoords(0.0), front);
        if (any(greaterThan(le, vec3(0.0)))) {
            vec3 t[3] = vec3[3](e.p0.xyz, e.p1.xyz, e.p2.xyz);
            sum += le * triangle_projected_solid_angle(origin, n, t);
        }
    }
    return sum;
}
#endif

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
#if defined(PATH_EMITTERS_IN_CLOSED_FORM)
    {
        // The unshadowed light in closed form less a one-sample estimate of what is hidden:
        // E − f(x)(1 − V(x))/p(x) has the expectation ∫ f·V, exact (no noise) wherever the
        // emitters are wholly visible; emission that a BSDF sample hits counts nothing
        // (path_step). docs/cache-frame.md §4.
        sum += analytic_emitter_irradiance(origin, s.shading_normal);
        vec3 dir, le;
        float dist, pdf;
        vec3 u = vec3(rng_next(rng), rng_next2(rng));
        if (sample_emitter(s.position, u, dir, dist, le, pdf)) {
            float cos_s = dot(s.shading_normal, dir);
            if (cos_s > 0.0 && (dot(s.geometric_normal, dir) <= 0.0 ||
                                !unoccluded_to(origin, s.position, dir, dist))) {
                vec3 f = le * cos_s / pdf;
                if (!any(isnan(f)) && !any(isinf(f))) {
                    sum -= f;
                }
            }
        }
    }
#elif defined(HAS_EMITTERS)
    {
        vec3 dir, le;
        float dist, pdf;
        vec3 u = vec3(rng_next(rng), rng_next2(rng));
        if (sample_emitter(s.position, u, dir, dist, le, pdf)) {
            float cos_s = dot(s.shading_normal, dir);
            if (cos_s > 0.0 && dot(s.geometric_normal, dir) > 0.0 &&
                unoccluded_to(origin, s.position, dir, dist)) {
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
            unoccluded_to(origin, s.position, dir, dist)) {
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

#ifdef HAS_SPECULAR
// The metallic-roughness BRDF at a surface point, in its shading frame (t, b, n), for the view
// direction `v` (local, toward the viewer). Where the interpolated shading normal faces away from
// the viewer (v·n ≤ 0 although the geometric normal faces it: silhouettes of smooth-shaded
// meshes) the geometric normal takes its place, so the surface never turns black there.
struct Bsdf {
    vec3 t;
    vec3 b;
    vec3 n;
    vec3 v;
    Material m;
};

Bsdf bsdf_at(Surface s, Material m, vec3 to_viewer) {
    Bsdf f;
    f.n = dot(s.shading_normal, to_viewer) > COS_MIN ? s.shading_normal : s.geometric_normal;
    orthonormal_basis(f.n, f.t, f.b);
    f.v = vec3(dot(to_viewer, f.t), dot(to_viewer, f.b), dot(to_viewer, f.n));
    f.m = m;
    return f;
}

vec3 bsdf_local(Bsdf f, vec3 dir) { return vec3(dot(dir, f.t), dot(dir, f.b), dot(dir, f.n)); }

vec3 bsdf_world(Bsdf f, vec3 l) { return normalize(f.t * l.x + f.b * l.y + f.n * l.z); }

// f(v, l)·(n·l) for world direction `dir` (0 below the shading or the geometric horizon).
vec3 bsdf_f_cos(Bsdf f, Surface s, vec3 dir) {
    vec3 l = bsdf_local(f, dir);
    if (l.z <= 0.0 || dot(s.geometric_normal, dir) <= 0.0) {
        return vec3(0.0);
    }
    return brdf_eval(f.m, f.v, l) * l.z;
}

// The solid-angle pdf with which brdf_sample draws world direction `dir`.
float bsdf_pdf_dir(Bsdf f, vec3 dir) { return brdf_pdf(f.m, f.v, bsdf_local(f, dir)); }

// Next-event estimate of the light that s reflects toward the viewer: Σ f·L·cos/pdf over one
// sample of each plan-enabled source, MIS-weighted (power heuristic) against BSDF sampling as
// in direct_light.
vec3 direct_reflected(Surface s, Bsdf f, inout Rng rng) {
    vec3 sum = vec3(0.0);
    vec3 origin = offset_ray_origin(s.position, s.geometric_normal);
#ifdef HAS_EMITTERS
    {
        vec3 dir, le;
        float dist, pdf;
        vec3 u = vec3(rng_next(rng), rng_next2(rng));
        if (sample_emitter(s.position, u, dir, dist, le, pdf)) {
            vec3 fc = bsdf_f_cos(f, s, dir);
            if (any(greaterThan(fc, vec3(0.0))) && unoccluded_to(origin, s.position, dir, dist)) {
                float w = power_heuristic(pdf, bsdf_pdf_dir(f, dir));
                sum += le * fc * w / pdf;
            }
        }
    }
#endif
#ifdef HAS_LIGHTS
    for (uint i = 0u; i < frame.counts.y; ++i) {
        vec3 dir;
        float dist;
        vec3 e = punctual_incident(lights[i], s.position, dir, dist);
        vec3 fc = bsdf_f_cos(f, s, dir);
        if (any(greaterThan(fc, vec3(0.0))) && any(greaterThan(e, vec3(0.0))) &&
            unoccluded_to(origin, s.position, dir, dist)) {
            sum += e * fc;
        }
    }
#endif
#ifdef HAS_ENV_MAP
    {
        vec3 dir, le;
        float pdf;
        vec3 u = vec3(rng_next(rng), rng_next2(rng));
        if (sample_environment(u, dir, le, pdf)) {
            vec3 fc = bsdf_f_cos(f, s, dir);
            if (any(greaterThan(fc, vec3(0.0))) && unoccluded(origin, dir, 1e30)) {
                float w = power_heuristic(pdf, bsdf_pdf_dir(f, dir));
                sum += le * fc * w / pdf;
            }
        }
    }
#endif
    return sum;
}
#endif

// A path in flight, advanced one vertex at a time by path_step (so a caller can start a new path
// in an invocation whose path ended while others go on: see passes/record.comp).
struct PathState {
    Ray ray;
    vec3 radiance;
    vec3 throughput;
    float bsdf_pdf;       // solid-angle pdf of ray.dir under the BSDF (0: no MIS on this segment)
    uint depth;           // vertex about to be found (0 = the first hit of the initial ray)
    uint rr_start;        // Russian roulette from this vertex on
    bool count_first;     // count sources found by the first segment
    bool done;
    float first_t;        // distance to the first hit, IC_PATH_MISS on a miss
#ifdef PATH_GRID
    // The grid cell of the first hit, which this path's continuation from there is deposited
    // into (PATH_GRID_NONE: none), and the path's radiance and throughput at that point.
    uint grid_slot;
    vec3 grid_base;
    vec3 grid_scale;
#endif
};

const float IC_PATH_MISS = 1.0e30;

PathState path_begin(Ray ray, float bsdf_pdf, bool count_first_segment, uint rr_start) {
    PathState st;
    st.ray = ray;
    st.radiance = vec3(0.0);
    st.throughput = vec3(1.0);
    st.bsdf_pdf = bsdf_pdf;
    st.depth = 0u;
    st.rr_start = rr_start;
    st.count_first = count_first_segment;
    st.done = false;
    st.first_t = IC_PATH_MISS;
#ifdef PATH_GRID
    st.grid_slot = PATH_GRID_NONE;
    st.grid_base = vec3(0.0);
    st.grid_scale = vec3(0.0);
#endif
    return st;
}

// Traces st.ray and handles the vertex it finds (or the miss); sets st.done when the path ends.
void path_step(inout PathState st, inout Rng rng) {
    bool count_sources = st.depth > 0u || st.count_first;
    rays_traced++;
    rayQueryEXT q;
    scene_trace(q, 0u, st.ray.origin, st.ray.dir, 1e30);
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
        if (count_sources) {
            vec3 le = environment_radiance(st.ray.dir);
            float w = 1.0;
#ifdef HAS_ENV_MAP
            if (st.bsdf_pdf > 0.0) {
                w = power_heuristic(st.bsdf_pdf, environment_pdf(st.ray.dir));
            }
#endif
            st.radiance += st.throughput * le * w;
        }
        st.done = true;
        return;
    }
    float t = rayQueryGetIntersectionTEXT(q, true);
    if (st.depth == 0u) {
        st.first_t = t;
    }
    Surface s = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                           uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                           rayQueryGetIntersectionBarycentricsEXT(q, true), st.ray.dir);
    vec3 le = count_sources ? material_emission(s.material, s.uv, s.front_face) : vec3(0.0);
    if (any(greaterThan(le, vec3(0.0)))) {
        float w = 1.0;
#if defined(PATH_EMITTERS_IN_CLOSED_FORM)
        if (st.bsdf_pdf > 0.0) {
            w = 0.0;  // the vertex before took all of the emitters' light (direct_light)
        }
#elif defined(HAS_EMITTERS)
        if (st.bsdf_pdf > 0.0) {
            float pdf_light = emitter_hit_pdf(s.material, s.geometric_normal, st.ray.dir, t);
            w = power_heuristic(st.bsdf_pdf, pdf_light);
        }
#endif
        st.radiance += st.throughput * le * w;
    }
#ifdef HAS_SPECULAR
    // The full BRDF: next-event estimation weighted by f·cos, then a BRDF-sampled continuation.
    Bsdf f = bsdf_at(s, material_at(s.material, s.uv), -st.ray.dir);
    st.radiance += st.throughput * direct_reflected(s, f, rng);
    BrdfSample bs = brdf_sample(f.m, f.v, vec3(rng_next2(rng), rng_next(rng)));
    vec3 next_dir = bsdf_world(f, bs.l);
    st.throughput *= bs.weight;
    if (bs.pdf <= 0.0 || dot(next_dir, s.geometric_normal) <= 0.0) {
        st.done = true;  // below the surface: no contribution
        return;
    }
#else
    vec3 albedo = material_albedo(s.material, s.uv);
    st.radiance += st.throughput * albedo * INV_PI * direct_light(s, rng);

    st.throughput *= albedo;
#endif
#ifdef PATH_GRID
    // The radiance grid (common/path_grid.glsl): a Lambertian vertex whose cell is ready ends
    // the path with the cell's mean continuation; the first hit's continuation is deposited into
    // its cell. (A glossy vertex's continuation depends on the direction it was reached from.)
#ifdef HAS_SPECULAR
    bool lambertian = f.m.metallic == 0.0 && f.m.specular_factor == 0.0;
#else
    const bool lambertian = true;
#endif
    if (g_grid_epoch != 0u && lambertian) {
        float edge;
        uint slot = path_grid_slot(s.position, s.geometric_normal, edge);
        if (slot != PATH_GRID_NONE) {
            bool ready = path_grid_ready(slot);
            if (ready && t >= PATH_GRID_MIN_SEGMENT * edge) {
                st.radiance += st.throughput * path_grid_mean(slot);
                st.done = true;
                return;
            }
            // A ready cell's sums are final (its mean is being read).
            if (st.depth == 0u && !ready) {
                st.grid_slot = slot;
                st.grid_base = st.radiance;
                st.grid_scale = st.throughput;
            }
        }
    }
#endif
    uint depth = st.depth;
    st.depth++;
    if (depth >= st.rr_start) {
        float p = min(max(st.throughput.r, max(st.throughput.g, st.throughput.b)), 0.99);
        if (rng_next(rng) >= p) {
            st.done = true;
            return;
        }
        st.throughput /= p;
    }
    if (all(equal(st.throughput, vec3(0.0))) || st.depth >= MAX_VERTICES) {
        st.done = true;
        return;
    }
#ifdef HAS_SPECULAR
    st.ray.dir = next_dir;
    st.bsdf_pdf = bs.pdf;
#else
    st.ray.dir = sample_cosine_around(s.shading_normal, rng_next2(rng));
    if (dot(st.ray.dir, s.geometric_normal) <= 0.0) {
        st.done = true;  // the shading normal sent the sample below the surface: no contribution
        return;
    }
    st.bsdf_pdf = dot(st.ray.dir, s.shading_normal) * INV_PI;
#endif
    st.ray.origin = offset_ray_origin(s.position, s.geometric_normal);
}

// The radiance a finished path gathered; a non-finite sample is dropped (guard at the source).
vec3 path_radiance(PathState st) {
    return (any(isnan(st.radiance)) || any(isinf(st.radiance))) ? vec3(0.0) : st.radiance;
}

#ifdef PATH_GRID
// Deposits a finished path's continuation from its first hit into that hit's cell: the light
// it gathered past the first hit's next-event estimation, over the throughput there (the
// albedo). A path whose throughput there has a zero channel deposits nothing.
void path_grid_finish(PathState st) {
    if (st.grid_slot != PATH_GRID_NONE && all(greaterThan(st.grid_scale, vec3(0.0)))) {
        path_grid_deposit(st.grid_slot, (st.radiance - st.grid_base) / st.grid_scale);
    }
}
#endif

// Radiance arriving along `ray`. With `count_first_segment` false, light that arrives along the
// first segment straight from a source (emission at the first hit, the environment on a miss) is
// left out: that is the indirect radiance a gather ray must return when the shading point's direct
// light is computed separately. `bsdf_pdf` is the solid-angle pdf with which `ray` was sampled by
// the BSDF (0 for camera rays: no MIS on the first segment). Russian roulette starts at vertex
// `rr_start` (0 = the first hit of `ray`).
vec3 trace_path_from(Ray ray, float bsdf_pdf, bool count_first_segment, uint rr_start,
                     inout Rng rng) {
    PathState st = path_begin(ray, bsdf_pdf, count_first_segment, rr_start);
    while (!st.done) {
        path_step(st, rng);
    }
    return path_radiance(st);
}

// Radiance arriving along a camera ray (everything counted).
vec3 trace_path(Ray ray, inout Rng rng) {
    return trace_path_from(ray, 0.0, true, RR_START, rng);
}

#endif
