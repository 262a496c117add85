// tests/ircache_twin.comp — Rust: tests/tests/ircache_glsl.rs (harness tests/src/twin.rs)
// GPU side of tests/tests/ircache_glsl.rs: evaluates the production GLSL twin of radcache-cache
// (common/ircache_math.glsl) over a table of input rows, one invocation per row, and writes the
// results for comparison with the Rust functions. Every row is 16 vec4 in and 16 vec4 out; uint
// inputs and outputs travel as float bits, booleans as 0.0 / 1.0. The layout of each mode is
// documented at its function and mirrored by the Rust test.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/ircache_math.glsl"

layout(local_size_x = 64) in;

struct Row {
    vec4 v[16];
};

layout(binding = 0, std430) readonly buffer Inputs { Row inputs[]; };
layout(binding = 1, std430) writeonly buffer Outputs { Row outputs[]; };
// Stratum samples (L.rgb, r) of the compute_record rows.
layout(binding = 2, std430) readonly buffer Samples { vec4 samples[]; };

layout(push_constant) uniform Push {
    uint mode;
    uint count;
} pc;

// The modes are radcache_shared::consts::TwinMode (TWIN_* in constants.glsl).

float flag(bool b) { return b ? 1.0 : 0.0; }
uint bits(float x) { return floatBitsToUint(x); }
float from_bits(uint u) { return uintBitsToFloat(u); }

// in: 0 (j, k, m, n) bits; 1 (xi, psi, seed bits, index bits); 2 normal; 3 (azimuth u, hash input
// bits, unit-float input bits, hit distance r).
void sampling(Row i, inout Row o) {
    uint j = bits(i.v[0].x), k = bits(i.v[0].y), m = bits(i.v[0].z), n = bits(i.v[0].w);
    vec3 d = stratum_direction_local(j, k, m, n, i.v[1].x, i.v[1].y);
    o.v[0] = vec4(d, 0.0);
    float xi, psi;
    stratum_jitter(bits(i.v[1].z), bits(i.v[1].w), xi, psi);
    o.v[1] = vec4(xi, psi, from_bits(ircache_hash(bits(i.v[3].y))), unit_float_from_bits(bits(i.v[3].z)));
    vec3 t, b;
    basis_from_normal(i.v[2].xyz, t, b);
    vec3 nn = normalize_or_z(i.v[2].xyz);
    o.v[2] = vec4(t, 0.0);
    o.v[3] = vec4(b, 0.0);
    o.v[4] = vec4(nn, 0.0);
    o.v[5] = vec4(rotational_gradient_coeff(j, k, m, n), 0.0);
    o.v[6] = vec4(polar_wall_coeff(j, k, m, n), 0.0);
    o.v[7] = vec4(azimuthal_wall_coeff(j, k, m, n), 0.0);
    o.v[8] = vec4(stratum_tan_mean(j, m), stratum_tan_centre(j, m), flag(stratum_elevation_ok(j, m)),
                  stratum_projected_solid_angle(m, n));
    o.v[9] = vec4(stratum_phi_centre(k, n), stratum_phi_start(k, n), from_bits(stratum_index(j, k, n)),
                  azimuth_from_unit(i.v[3].x));
    vec3 w = frame_to_world(d, t, b, nn);
    o.v[10] = vec4(w, 0.0);
    o.v[11] = vec4(world_to_frame(w, t, b, nn), 0.0);
    o.v[12] = vec4(horizontal_u(i.v[1].x * 6.0 - 3.0), 0.0);
    o.v[13] = vec4(horizontal_v(i.v[1].y * 6.0 - 3.0), 0.0);
    // Radiance records: the stratum's solid angle, the sample the projection sees (l = the
    // normal input, r = in 3.w), the solid-angle wall coefficients.
    o.v[0].w = stratum_solid_angle(j, m, n);
    vec3 rs = radiance_sample(i.v[2].xyz, i.v[3].w);
    o.v[5].w = rs.x;
    o.v[6].w = rs.y;
    o.v[7].w = rs.z;
    o.v[14] = vec4(radiance_polar_wall_coeff(j, k, m, n), 0.0);
    o.v[15] = vec4(radiance_azimuthal_wall_coeff(j, k, m, n), 0.0);
    // The strata falloff of fine strata (1 + hash input % 1728) × (3 + unit-float input % 1726),
    // k % 16 levels finer.
    uint fm, fn;
    falloff_strata(1u + bits(i.v[3].y) % 1728u, 3u + bits(i.v[3].z) % 1726u, k % 16u, fm, fn);
    o.v[12].w = from_bits(fm);
    o.v[13].w = from_bits(fn);
}

// in: 0 p; 1 n; 2 p_i; 3 n_i; 4 (r_i, a, kappa, front tolerance); 5 (w_min, hole threshold, -, -).
void weight(Row i, inout Row o) {
    vec3 p = i.v[0].xyz, n = i.v[1].xyz, p_i = i.v[2].xyz, n_i = i.v[3].xyz;
    float r_i = i.v[4].x, a = i.v[4].y, kappa = i.v[4].z, tol = i.v[4].w;
    float w_min = i.v[5].x, hole = i.v[5].y;
    o.v[0] = vec4(ward_weight(p, n, p_i, n_i, r_i, a, tol), tl_weight(p, n, p_i, n_i, r_i, kappa, tol),
                  record_weight(WEIGHT_WARD, p, n, p_i, n_i, r_i, a, tol),
                  record_weight(WEIGHT_TL, p, n, p_i, n_i, r_i, kappa, tol));
    o.v[1] = vec4(flag(normal_test(n, n_i)), flag(in_front_test(p, p_i, n_i, tol)), normal_error(n, n_i),
                  position_error(p, p_i, n_i, r_i));
    o.v[2] = vec4(validity_scale(WEIGHT_WARD, a), validity_scale(WEIGHT_TL, kappa),
                  splat_radius(WEIGHT_WARD, r_i, a, w_min), splat_radius(WEIGHT_TL, r_i, kappa, w_min));
    o.v[3] = vec4(weight_unit(WEIGHT_WARD, a), weight_unit(WEIGHT_TL, kappa),
                  coverage_threshold(WEIGHT_WARD, a, hole), coverage_threshold(WEIGHT_TL, kappa, hole));
}

// in: 0 e_i; 1-3 grad_r (R, G, B); 4-6 grad_t; 7 p; 8 n; 9 p_i; 10 n_i; 11 x (clamp_extrapolation).
void extrapolate(Row i, inout Row o) {
    vec3 e = i.v[0].xyz;
    o.v[0] = vec4(extrapolate_irradiance(e, i.v[1].xyz, i.v[2].xyz, i.v[3].xyz, i.v[4].xyz, i.v[5].xyz,
                                         i.v[6].xyz, i.v[7].xyz, i.v[8].xyz, i.v[9].xyz, i.v[10].xyz),
                  0.0);
    o.v[1] = vec4(clamp_extrapolation(i.v[11].xyz, e), 0.0);
}

// in: 0 (r, r_neighbour, r_lo, r_hi); 1 e; 2-4 grad_t (R, G, B); 5 (footprint, min_px, max_px,
// v_scale); 6 (r_j, d_ij, -, -); 7 (depth, tan_half_fov_y, image_height, cos_view); 8 dpdx;
// 9 dpdy; 10 p_i; 11 p_j. out 4: glossy_gradient_limit_from_sums(e, grad_t R).
void radius(Row i, inout Row o) {
    float r = i.v[0].x, r_nb = i.v[0].y, r_lo = i.v[0].z, r_hi = i.v[0].w;
    vec3 e = i.v[1].xyz, g0 = i.v[2].xyz, g1 = i.v[3].xyz, g2 = i.v[4].xyz;
    float r_orig, r_used, lo, hi, scale;
    finalize_radius(r, e, g0, g1, g2, r_nb, r_lo, r_hi, r_orig, r_used, lo, hi, scale);
    o.v[0] = vec4(r_orig, r_used, lo, hi);
    o.v[1] = vec4(scale, clamp_radius(r, r_lo, r_hi), gradient_limit_radius(r, e, g0, g1, g2),
                  gradient_attenuation(r, r_lo));
    float b_lo, b_hi;
    radius_bounds(i.v[5].x, i.v[5].y, i.v[5].z, i.v[5].w, b_lo, b_hi);
    o.v[2] = vec4(b_lo, b_hi, sanitize_radius(r), neighbour_clamp(r, i.v[6].x, i.v[6].y));
    float ri, rj;
    neighbour_clamp_pair(r, i.v[10].xyz, i.v[6].x, i.v[11].xyz, ri, rj);
    o.v[3] = vec4(pixel_footprint(i.v[7].x, i.v[7].y, i.v[7].z, i.v[7].w),
                  pixel_footprint_from_differentials(i.v[8].xyz, i.v[9].xyz), ri, rj);
    // The glossy gradient limit on (e, grad_t R) as its two sums.
    o.v[4] = vec4(glossy_gradient_limit_from_sums(e, g0), 0.0, 0.0, 0.0);
}

// compute_record over one sample set: in 0 (normal, r_eps); 1 (m, n, first sample, -) bits.
// out 0 E; 1-3 grad_r; 4-6 grad_t; 7 (r_harmonic, r_min, r_min_restricted, valid samples bits);
// 8 (irradiance_is_valid(E), luminance_rec709(E), -, -).
void record(Row i, inout Row o) {
    vec3 nn = normalize_or_z(i.v[0].xyz);
    float r_eps = i.v[0].w;
    uint m = bits(i.v[1].x), n = bits(i.v[1].y), first = bits(i.v[1].z);
    vec3 t, b;
    basis_from_normal(nn, t, b);
    vec3 sum_l = vec3(0.0);
    vec3 gr[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
    vec3 gt[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
    float sum_inv = 0.0;
    uint valid = 0u;
    float r_min = IC_FAR;
    float r_min_restricted = IC_FAR;
    for (uint j = 0u; j < m; ++j) {
        bool elevation_ok = stratum_elevation_ok(j, m);
        for (uint k = 0u; k < n; ++k) {
            vec4 s = samples[first + stratum_index(j, k, n)];
            vec3 lc = s.rgb;
            float rc = s.w;
            sum_l += lc;
            if (is_valid_sample(rc, r_eps)) {
                valid++;
                sum_inv += inverse_distance(rc, r_eps);
                r_min = min(r_min, rc);
                if (elevation_ok) {
                    r_min_restricted = min(r_min_restricted, rc);
                }
            }
            vec3 cr = frame_to_world(rotational_gradient_coeff(j, k, m, n), t, b, nn);
            vec3 trans[3] = vec3[](vec3(0.0), vec3(0.0), vec3(0.0));
            if (j > 0u) {
                vec4 sp = samples[first + stratum_index(j - 1u, k, n)];
                vec3 d = wall_term(lc, sp.rgb, rc, sp.w, r_eps);
                vec3 cw = frame_to_world(polar_wall_coeff(j, k, m, n), t, b, nn);
                trans[0] = cw * d.x;
                trans[1] = cw * d.y;
                trans[2] = cw * d.z;
            }
            vec4 sp = samples[first + stratum_index(j, k == 0u ? n - 1u : k - 1u, n)];
            vec3 d = wall_term(lc, sp.rgb, rc, sp.w, r_eps);
            vec3 ca = frame_to_world(azimuthal_wall_coeff(j, k, m, n), t, b, nn);
            for (int c = 0; c < 3; ++c) {
                gr[c] += cr * lc[c];
                gt[c] += trans[c] + ca * d[c];
            }
        }
    }
    vec3 e = sum_l * stratum_projected_solid_angle(m, n);
    o.v[0] = vec4(e, 0.0);
    for (int c = 0; c < 3; ++c) {
        o.v[1 + c] = vec4(gr[c], 0.0);
        o.v[4 + c] = vec4(gt[c], 0.0);
    }
    o.v[7] = vec4(harmonic_mean_distance(sum_inv, float(valid)), min(r_min, IC_FAR),
                  min(r_min_restricted, IC_FAR), from_bits(valid));
    o.v[8] = vec4(flag(irradiance_is_valid(e)), luminance_rec709(e), 0.0, 0.0);
}

// in: 0 E(t_i); 1 E(t_i + 1); 2 (a_t, Δt_max, age, lifespan); 3 ∂E/∂t; 4 p; 5 n; 6 sphere.
// out: 0 (temporal_lifespan, temporal_is_valid(age, lifespan), moving_cover, -);
//      1 temporal_gradient; 2 temporal_extrapolate(E(t_i), ∂E/∂t, age).
void temporal(Row i, inout Row o) {
    o.v[0] = vec4(temporal_lifespan(i.v[0].xyz, i.v[1].xyz, i.v[2].x, i.v[2].y),
                  flag(temporal_is_valid(i.v[2].z, i.v[2].w)),
                  moving_cover(i.v[4].xyz, i.v[5].xyz, i.v[6]), 0.0);
    o.v[1] = vec4(temporal_gradient(i.v[0].xyz, i.v[1].xyz), 0.0);
    o.v[2] = vec4(temporal_extrapolate(i.v[0].xyz, i.v[3].xyz, i.v[2].z), 0.0);
}

// Hessian terms. in: 0 a; 1 b (vertices); 2 (S, h, footprint, -); 3 (j, k, m, n) bits; 4 (seed bits,
// r, r_eps, mean_y); 5 c; 6 d; 7 bl; 8 au; 9 (y_a, y_b, y_c, y_d); 10 (y_bl, y_au, y_cap, flags
// bits: 1 first, 2 last); 11 h (E', H_tt, H_tb, H_bb); 12 (u, v) of hessian_outer.
// out: 0 hessian_edge(a, b); 1 (hessian_angle_terms(S, h), hessian_vertex_distance(a));
// 2 hessian_vertex; 3 hessian_horizon_vertex(a); 4 (hessian_luminance(r, mean_y),
// hessian_farthest(a, y_a, b, y_b, c, y_c), hessian_radius(h, footprint), -); 5 hessian_cell;
// 6 (hessian_outer, -).
void hessian_terms(Row i, inout Row o) {
    vec4 a = i.v[0], b = i.v[1], c = i.v[5], d = i.v[6];
    o.v[0] = hessian_edge(a, b);
    o.v[1] = vec4(hessian_angle_terms(i.v[2].x, i.v[2].y), hessian_vertex_distance(a));
    uint j = bits(i.v[3].x), k = bits(i.v[3].y), m = bits(i.v[3].z), n = bits(i.v[3].w);
    o.v[2] = hessian_vertex(j, k, m, n, bits(i.v[4].x), i.v[4].y, i.v[4].z);
    o.v[3] = hessian_horizon_vertex(a);
    vec4 y = i.v[9];
    o.v[4] = vec4(hessian_luminance(i.v[4].y, i.v[4].w), hessian_farthest(a, y.x, b, y.y, c, y.z),
                  hessian_radius(i.v[11], i.v[2].z), 0.0);
    uint flags = bits(i.v[10].w);
    o.v[5] = hessian_cell(a, b, c, d, i.v[7], i.v[8], y, i.v[10].x, i.v[10].y, i.v[10].z, (flags & 1u) != 0u,
                          (flags & 2u) != 0u);
    o.v[6] = vec4(hessian_outer(i.v[12].xy, i.v[12].zw), 0.0);
}

// A sample set's compute_hessian and radius: in 0 (footprint, r_eps, -, -); 1 (m, n, first sample,
// seed) bits. out 0 (E', H_tt, H_tb, H_bb); 1 (hessian_radius, -, -, -).
vec4 twin_vertex(uint first, uint j, uint k, uint m, uint n, uint seed, float r_eps, float mean_y, out float y) {
    uint kk = k % n;
    uint js = min(j, m - 1u);
    vec4 s = samples[first + stratum_index(js, kk, n)];
    vec4 v = hessian_vertex(js, kk, m, n, seed, s.w, r_eps);
    y = hessian_luminance(luminance_rec709(s.rgb), mean_y);
    return j >= m ? hessian_horizon_vertex(v) : v;
}

void hessian_record(Row i, inout Row o) {
    float r_eps = i.v[0].y;
    uint m = bits(i.v[1].x), n = bits(i.v[1].y), first = bits(i.v[1].z), seed = bits(i.v[1].w);
    uint count = m * n;
    float sum_y = 0.0;
    for (uint s = 0u; s < count; ++s) {
        sum_y += luminance_rec709(samples[first + s].rgb);
    }
    float mean_y = sum_y / float(count);
    float cap_d = -1.0, y_cap = 1.0;
    for (uint k = 0u; k < n; ++k) {
        float y;
        vec4 v = twin_vertex(first, 0u, k, m, n, seed, r_eps, mean_y, y);
        float d = hessian_vertex_distance(v);
        if (d > cap_d) {
            cap_d = d;
            y_cap = y;
        }
    }
    vec4 sum = vec4(0.0);
    for (uint j = 0u; j < m; ++j) {
        for (uint k = 0u; k < n; ++k) {
            float ya, yb, yc, yd, y_bl, y_au = 0.0;
            vec4 a = twin_vertex(first, j, k, m, n, seed, r_eps, mean_y, ya);
            vec4 b = twin_vertex(first, j + 1u, k, m, n, seed, r_eps, mean_y, yb);
            vec4 c = twin_vertex(first, j + 1u, k + 1u, m, n, seed, r_eps, mean_y, yc);
            vec4 d = twin_vertex(first, j, k + 1u, m, n, seed, r_eps, mean_y, yd);
            vec4 bl = twin_vertex(first, j + 1u, k + n - 1u, m, n, seed, r_eps, mean_y, y_bl);
            vec4 au = j > 0u ? twin_vertex(first, j - 1u, k + 1u, m, n, seed, r_eps, mean_y, y_au) : vec4(0.0);
            sum += hessian_cell(a, b, c, d, bl, au, vec4(ya, yb, yc, yd), y_bl, y_au, y_cap, j == 0u, j + 1u == m);
        }
    }
    o.v[0] = sum;
    o.v[1] = vec4(hessian_radius(sum, i.v[0].x), 0.0, 0.0, 0.0);
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
    if (pc.mode == TWIN_SAMPLING) {
        sampling(i, o);
    } else if (pc.mode == TWIN_WEIGHT) {
        weight(i, o);
    } else if (pc.mode == TWIN_EXTRAPOLATE) {
        extrapolate(i, o);
    } else if (pc.mode == TWIN_RADIUS) {
        radius(i, o);
    } else if (pc.mode == TWIN_RECORD) {
        record(i, o);
    } else if (pc.mode == TWIN_TEMPORAL) {
        temporal(i, o);
    } else if (pc.mode == TWIN_HESSIAN_TERMS) {
        hessian_terms(i, o);
    } else if (pc.mode == TWIN_HESSIAN_RECORD) {
        hessian_record(i, o);
    }
    outputs[id] = o;
}
