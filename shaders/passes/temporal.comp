// passes/temporal.comp — Rust: crates/radcache-render/src/passes/temporal.rs
// Temporal radiance caching (docs/temporal.md §3; crates/radcache-render/src/passes/temporal.rs): records
// live on their mesh instance, carry the change of their irradiance to the next frame and a
// lifespan, and are evaluated again (at their own points, one frame ahead) when they expire.
//
// Buffers: the cache's counters (read) and records, the records' temporal state (same index), the
// list of records to evaluate this frame with its own IcCounters (record_count = records, requested =
// listed, dispatch = one workgroup per listed record, as the record pass's refresh reads it),
// the record copy evaluated at the next frame's time, the instances of the previous frame, and the
// bounding spheres of the scene's moving instances at the scene's current time (two vec4 each:
// centre and radius, then the instance index).
//
// Steps (push constant `step`, TEMPORAL_* of constants.glsl):
//   0 begin     (1 invocation)   empty list
//   1 advance   (per record)     move adopted records with their instance (point, normals; the
//                                gradients rotate with the instance's change since the previous
//                                frame); a record shows its newest known value E_k (exact at frame
//                                t_k), carried at most one frame forward at its measured rate; one
//                                whose E_k would be older than its lifespan at the next frame, or
//                                whose view of the other moving instances changed by more than a_t
//                                since t_k (below), is listed: it is evaluated again one frame
//                                ahead, for that frame; with
//                                `reclamp` (the camera moved) every record in front of the camera
//                                takes the [R⁻, R⁺] clamp of its pixel footprint in this view, as a
//                                record created now would (records kept from a distant view would
//                                otherwise stay many R⁺ wide on screen)
//   2 append    (per new record) list records [first, count) and mark them not adopted
//   3 adopt     (per listed)     new records: the point and normals in object space, E_k = the
//                                creation value, t_k = this frame (listed expired records keep theirs)
//   4 shift     (per listed)     move the copy's point and normals to the instances' current
//                                transforms (the next frame's, when this runs)
//   5 finish    (per listed)     with E(t + 1) from the record pass on the copy, over the span
//                                s = t + 1 − t_k: rate (E(t + 1) − E_k)/s, lifespan
//                                min(s·a_t·Y_k/|Y(t+1) − Y_k|, Δt_max·(1 ± 20 %)) (the stagger
//                                hashed from the record and the frame; radcache_cache::temporal),
//                                then E_k = E(t + 1), t_k = t + 1, and the moving cover at t + 1;
//                                the record also takes the gradients and the radius of that
//                                evaluation
// Motion-aware expiry: the lifespan is measured from one frame's change, so it misses what comes
// later — an object that approaches a record slowly at first. Each record keeps the cover C of
// the other moving instances at t_k (Σ over their bounding spheres of the cosine-weighted fraction
// of its hemisphere each covers, radcache_cache::moving_cover) and expires when |C(t) − C_k| > a_t:
// a change of that fraction of the incident light is what the lifespan allows.
// Every evaluation is one frame ahead: a record shows values that were exact at most `lifespan`
// frames ago (it is listed the frame before), and costs one evaluation per refresh. Carrying E_k forward more than one frame at the rate (linear extrapolation,
// docs/temporal.md §3.4) measured worse: a difference between two evaluations carries the noise of
// the paths that diverge between the two scenes (relMSE +12 % on the animated scene with one-frame
// gradients).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/scene.glsl"
#include "../common/ircache_math.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 64) in;

layout(binding = B_TEMPORAL_COUNTERS, std430) readonly buffer Counters { IcCounters counters; };
layout(binding = B_TEMPORAL_RECORDS, std430) buffer Records { GpuRecord records[]; };
layout(binding = B_TEMPORAL_TEMPORAL, std430) buffer Temporal { GpuRecordTemporal temporal[]; };
layout(binding = B_TEMPORAL_LIST, std430) buffer List { uint list[]; };
layout(binding = B_TEMPORAL_LIST_COUNTERS, std430) buffer ListCounters { IcCounters list_counters; };
layout(binding = B_TEMPORAL_LOOKAHEAD, std430) buffer Lookahead { GpuRecord lookahead[]; };
layout(binding = B_TEMPORAL_PREVIOUS, std430) readonly buffer Previous { GpuInstance previous[]; };
layout(binding = B_TEMPORAL_MOVING, std430) readonly buffer Moving { vec4 moving[]; };

layout(push_constant) uniform Push { TemporalPush pc; };


vec3 to_world_point(GpuInstance inst, vec3 p) { return (inst.world_from_object * vec4(p, 1.0)).xyz; }

vec3 to_world_normal(GpuInstance inst, vec3 n) {
    return normalize_or_z(mat3(inst.normal_to_world) * n);
}

// Inverse of the normal transform: n_obj ∝ Aᵀ·n_world for A the linear part of world_from_object.
vec3 to_object_normal(GpuInstance inst, vec3 n) {
    return normalize_or_z(transpose(mat3(inst.world_from_object)) * n);
}

// The cover of the moving instances other than `own` over the hemisphere of (p, n) (header).
float cover_of_moving(vec3 p, vec3 n, uint own) {
    float sum = 0.0;
    for (uint j = 0u; j < pc.moving_count; ++j) {
        if (uint(moving[2u * j + 1u].x) != own) {
            sum += moving_cover(p, n, moving[2u * j]);
        }
    }
    return sum;
}

vec3 finite_or(vec3 v, vec3 fallback) {
    return (any(isnan(v)) || any(isinf(v))) ? fallback : v;
}

void append(uint index) {
    uint slot = atomicAdd(list_counters.requested, 1u);
    if (slot < pc.capacity) {
        list[slot] = index;
        atomicAdd(list_counters.dispatch.x, 1u);
    }
}

void move_record(uint i, GpuRecordTemporal tr) {
    GpuInstance inst = instances[tr.info.x];
    GpuRecord r = records[i];
    vec3 ng = to_world_normal(inst, tr.object_geometric.xyz);
    r.position_radius.xyz = to_world_point(inst, tr.object_position.xyz);
    r.normal_rorig.xyz = to_world_normal(inst, tr.object_normal.xyz);
    if (pc.has_previous != 0u) {
        // The instance's linear change since the previous frame, L = A_t·A_prev⁻¹: the
        // translational gradients are covectors (L⁻ᵀ), the rotational ones rotate with the surface
        // (L⁻ᵀ rescaled to keep their length under a uniform scale).
        mat3 a_prev = mat3(previous[tr.info.x].world_from_object);
        mat3 a_now = mat3(inst.world_from_object);
        float det_prev = determinant(a_prev);
        if (det_prev != 0.0 && a_prev != a_now) {
            mat3 l = a_now * inverse(a_prev);
            float det = determinant(l);
            if (det != 0.0 && !isnan(det) && !isinf(det)) {
                mat3 cov = transpose(inverse(l));
                float scale = pow(abs(det), 1.0 / 3.0);
                r.grad_t_red.xyz = finite_or(cov * r.grad_t_red.xyz, vec3(0.0));
                r.grad_t_green.xyz = finite_or(cov * r.grad_t_green.xyz, vec3(0.0));
                r.grad_t_blue.xyz = finite_or(cov * r.grad_t_blue.xyz, vec3(0.0));
                r.grad_r_red.xyz = finite_or(scale * (cov * r.grad_r_red.xyz), vec3(0.0));
                r.grad_r_green.xyz = finite_or(scale * (cov * r.grad_r_green.xyz), vec3(0.0));
                r.grad_r_blue.xyz = finite_or(scale * (cov * r.grad_r_blue.xyz), vec3(0.0));
            }
        }
    }
    r.grad_r_red.w = ng.x;
    r.grad_r_green.w = ng.y;
    r.grad_r_blue.w = ng.z;
    records[i] = r;
}

// The [R⁻, R⁺] clamp of record i for the current view (record.comp's, from the footprint of a
// pixel at the record's point), with the gradient attenuation that goes with it.
void reclamp_record(uint i) {
    GpuRecord r = records[i];
    if (dot(r.normal_rorig.xyz, r.normal_rorig.xyz) == 0.0) {
        return;  // rejected
    }
    vec3 p = r.position_radius.xyz;
    float depth = (frame.clip_from_world * vec4(p, 1.0)).w;
    if (!(depth > 0.0)) {
        return;  // behind the camera: keeps its clamp until it is seen again
    }
    vec3 row_y = vec3(frame.clip_from_world[0][1], frame.clip_from_world[1][1],
                      frame.clip_from_world[2][1]);
    vec3 to_camera = frame.camera_position.xyz - p;
    float dist = length(to_camera);
    vec3 ng = vec3(r.grad_r_red.w, r.grad_r_green.w, r.grad_r_blue.w);
    float cos_view = dist > 0.0 ? dot(ng, to_camera) / dist : 1.0;
    float footprint = pixel_footprint(depth, 1.0 / length(row_y), float(frame.resolution.y),
                                      cos_view);
    float lo, hi;
    radius_bounds(footprint, pc.min_px, pc.max_px, pc.v_scale, lo, hi);
    float r_orig = r.normal_rorig.w;
    records[i].position_radius.w = clamp_radius(r_orig, lo, hi);
    records[i].bounds.xy = vec2(lo, hi);
    records[i].irradiance.w = gradient_attenuation(r_orig, lo);
}

void main() {
    uint gid = gl_GlobalInvocationID.x;
    if (pc.step == TEMPORAL_BEGIN) {
        if (gid == 0u) {
            list_counters.record_count = counters.record_count;
            list_counters.requested = 0u;
            list_counters.batch_first = 0u;
            list_counters.holes = 0u;
            list_counters.dispatch = DispatchArgs(0u, 1u, 1u, 0u);
            list_counters.record_capacity = pc.capacity;
            list_counters.request_capacity = pc.capacity;
            list_counters.dropped_requests = 0u;
            list_counters.rejected_records = 0u;
            list_counters.radii_shrunk = 0u;
        }
        return;
    }
    if (pc.step == TEMPORAL_ADVANCE) {
        if (gid >= counters.record_count) {
            return;
        }
        GpuRecordTemporal tr = temporal[gid];
        if (pc.has_lifespans != 0u && (tr.info.z & TEMPORAL_FLAG_ADOPTED) != 0u) {
            move_record(gid, tr);
            // The newest known value E_k is exact at frame t_k (info.y) and `age` frames old.
            float age = float(pc.frame) - float(tr.info.y);
            // Listed when its value at the next frame would outlive its lifespan (the look-ahead
            // evaluates it for that frame, so no frame shows a value older than the lifespan),
            // else by a change of the moving instances' cover.
            bool expired = !temporal_is_valid(age + 1.0, tr.object_position.w);
            if (!expired && age >= 1.0) {
                float cover = cover_of_moving(records[gid].position_radius.xyz,
                                              records[gid].normal_rorig.xyz, tr.info.x);
                expired = abs(cover - tr.birth_irradiance.w) > max(pc.accuracy, 0.0);
            }
            if (expired) {
                append(gid);
            }
            // The known value, carried at most one frame forward at the measured rate (see the
            // header).
            vec3 ek = tr.birth_irradiance.rgb;
            vec3 e = max(ek + clamp(age, 0.0, 1.0) * tr.gradient.rgb, vec3(0.0));
            records[gid].irradiance.rgb = finite_or(e, ek);
        }
        if (pc.reclamp != 0u) {
            reclamp_record(gid);
        }
        return;
    }
    if (pc.step == TEMPORAL_APPEND) {
        uint i = pc.first + gid;
        if (i >= counters.record_count) {
            return;
        }
        if (gid == 0u) {
            list_counters.record_count = counters.record_count;
        }
        temporal[i].info = uvec4(0u);
        append(i);
        return;
    }
    if (gid >= min(list_counters.requested, pc.capacity)) {
        return;
    }
    uint i = list[gid];
    if (pc.step == TEMPORAL_ADOPT) {
        GpuRecord r = records[i];
        GpuRecordTemporal tr = temporal[i];
        uint bits = r.info.w >> RECORD_INSTANCE_SHIFT;
        if ((tr.info.z & TEMPORAL_FLAG_ADOPTED) == 0u) {
            if (bits == 0u || dot(r.normal_rorig.xyz, r.normal_rorig.xyz) == 0.0) {
                temporal[i].info = uvec4(0u);  // rejected: never weighs, never refreshed
                return;
            }
            GpuInstance inst = instances[bits - 1u];
            vec3 ng = vec3(r.grad_r_red.w, r.grad_r_green.w, r.grad_r_blue.w);
            tr.object_position.xyz = (inverse(inst.world_from_object) * vec4(r.position_radius.xyz, 1.0)).xyz;
            tr.object_normal.xyz = to_object_normal(inst, r.normal_rorig.xyz);
            tr.object_geometric.xyz = to_object_normal(inst, ng);
            tr.info.x = bits - 1u;
            // A new record's known value is its creation value, exact now.
            tr.object_position.w = 0.0;
            tr.birth_irradiance = vec4(r.irradiance.rgb, 0.0);
            tr.gradient = vec4(0.0);
            tr.info.y = pc.frame;
            tr.info.z = TEMPORAL_FLAG_ADOPTED;
            temporal[i] = tr;
        }
        return;  // an expired record keeps its known value until the look-ahead replaces it
    }
    GpuRecordTemporal tr = temporal[i];
    if ((tr.info.z & TEMPORAL_FLAG_ADOPTED) == 0u) {
        return;
    }
    if (pc.step == TEMPORAL_SHIFT) {
        GpuInstance inst = instances[tr.info.x];
        vec3 ng = to_world_normal(inst, tr.object_geometric.xyz);
        lookahead[i].position_radius.xyz = to_world_point(inst, tr.object_position.xyz);
        lookahead[i].normal_rorig.xyz = to_world_normal(inst, tr.object_normal.xyz);
        lookahead[i].grad_r_red.w = ng.x;
        lookahead[i].grad_r_green.w = ng.y;
        lookahead[i].grad_r_blue.w = ng.z;
        return;
    }
    // TEMPORAL_FINISH: the look-ahead value E(t + 1) against the known value E_k of frame t_k.
    vec3 e0 = tr.birth_irradiance.rgb;
    vec3 e1 = finite_or(lookahead[i].irradiance.rgb, e0);
    float span = max(float(pc.frame + 1u) - float(tr.info.y), 1.0);
    float y0 = max(luminance_rec709(e0), 0.0);
    float y1 = max(luminance_rec709(e1), 0.0);
    float dy = abs(y1 - y0);
    uint h = ircache_hash(i * 0x9e3779b9u ^ ircache_hash(pc.frame));
    float max_age = max(pc.max_age, 0.0) * (0.8 + 0.4 * unit_float_from_bits(h));
    // Lifespan = span · a_t·Y₀/|Y₁ − Y₀| (the change per frame over the span), at most Δt_max.
    float num = span * max(pc.accuracy, 0.0) * y0;
    tr.object_position.w = num >= max_age * dy ? max_age : num / dy;
    tr.gradient = vec4((e1 - e0) / span, span);
    tr.birth_irradiance = vec4(e1, cover_of_moving(lookahead[i].position_radius.xyz,
                                                   lookahead[i].normal_rorig.xyz, tr.info.x));
    tr.info.y = pc.frame + 1u;
    temporal[i] = tr;
    // The gradients and the radius of the same evaluation as E_k (docs/temporal.md §3.3):
    // a new record's look-ahead is at t + 1, where E_k now is. The radius follows the
    // geometry both ways (an occluder that comes closer shrinks it, one that leaves lets it
    // grow): keeping the smaller of the old and the new, as before 2026-12-05, shrank the
    // radii with every refresh (a minimum of noisy estimates) and left kept records 1.2×
    // the error of a per-frame rebuild even when every record was re-evaluated every other
    // frame.
    GpuRecord a = lookahead[i];
    GpuRecord r = records[i];
    r.grad_r_red.xyz = a.grad_r_red.xyz;
    r.grad_r_green.xyz = a.grad_r_green.xyz;
    r.grad_r_blue.xyz = a.grad_r_blue.xyz;
    r.grad_t_red.xyz = a.grad_t_red.xyz;
    r.grad_t_green.xyz = a.grad_t_green.xyz;
    r.grad_t_blue.xyz = a.grad_t_blue.xyz;
    float r_orig = sanitize_radius(a.normal_rorig.w);
    r.normal_rorig.w = r_orig;
    r.position_radius.w = clamp_radius(r_orig, r.bounds.x, r.bounds.y);
    r.irradiance.w = gradient_attenuation(r_orig, r.bounds.x);
    records[i] = r;
}
