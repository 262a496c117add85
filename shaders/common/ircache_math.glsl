// common/ircache_math.glsl — Rust: crates/radcache-cache/src/*.rs (its CPU twin)
// ircache_math.glsl: GLSL twin of the `radcache-cache` crate (crates/radcache-cache/src/*.rs).
//
// Irradiance-cache formulas of docs/irradiance-cache.md (cited in this file as a bare §N; other
// docs/ files by name): hemisphere sampling (§2.1, §2.2), record sums and gradients (§2.5, §3.1,
// §3.2), radius post-processing (§4.2-§4.7), weights and splat radius (§5.1-§5.4, §5.6, §7.2),
// extrapolation (§6.1, §6.2), Hessian error control (§10), temporal formulas (docs/temporal.md §3.3). Each function has the same
// name, arguments (in order) and guards as its Rust reference; Rust tuples/structs become `out`
// parameters, `[Vec3; 3]` RGB gradients become three vec3 (R, G, B). The Rust docs hold the
// formulas; comments here only name the section. GLSL 4.60 core, no extension; include once
// (guarded). Conventions: right-handed frames t x b = n; stratum (j, k) at index j*N + k; distances
// >= IC_FAR are misses, <= r_eps invalid; outputs never divide by inf. Test:
// crates/radcache-cache/tests/glsl.rs checks that every Rust function has a twin here and compiles
// this file with glslangValidator when it is installed.

#ifndef IRCACHE_MATH_GLSL
#define IRCACHE_MATH_GLSL

// IC_FAR, R_FLOOR, WARD_MIN_ERROR, TL_NORMAL_SCALE, KAPPA_MIN, ELEVATION_MIN_SIN2,
// EXTRAPOLATION_MAX_FACTOR, HESSIAN_ERROR, HESSIAN_SERIES_TAU, WEIGHT_WARD, WEIGHT_TL: declared once in Rust (radcache_shared::consts).
#include "../shared/constants.glsl"

const float IC_PI = 3.14159265358979;
const float IC_TAU = 6.28318530717959;

float luminance_rec709(vec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// ---- sampling (§2.1, §2.2, §2.3, §7.3) ----

uint stratum_index(uint j, uint k, uint n) { return j * n + k; }

// IcParams::falloff_strata (params.rs): the fine strata m × n of a record `steps` levels finer
// than the fine level. M' is the integer nearest m/√2^steps (at least 1), found by comparing
// (k ± ½)² with m²/2^steps, exact in f32 for m ≤ 1728; N' = round(n·M'/m) (at least 3).
void falloff_strata(uint m, uint n, uint steps, out uint m2, out uint n2) {
    m2 = m;
    n2 = n;
    if (steps == 0u || m == 0u) {
        return;
    }
    float x2 = float(m * m);
    for (uint i = 0u; i < min(steps, 30u); ++i) {
        x2 *= 0.5;
    }
    uint k = uint(round(sqrt(x2)));
    while ((float(k) + 0.5) * (float(k) + 0.5) <= x2) {
        k++;
    }
    while (k > 0u && (float(k) - 0.5) * (float(k) - 0.5) > x2) {
        k--;
    }
    m2 = max(k, 1u);
    n2 = max((2u * n * m2 + m) / (2u * m), 3u);
}

vec3 normalize_or_z(vec3 n) {
    float len2 = dot(n, n);
    if (len2 > 1.0e-30 && len2 < 1.0e30) {
        return n / sqrt(len2);
    }
    return vec3(0.0, 0.0, 1.0);
}

// Duff et al. 2017, sign(0) = +1.
void basis_from_normal(vec3 n_in, out vec3 t, out vec3 b) {
    vec3 n = normalize_or_z(n_in);
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 frame_to_world(vec3 v, vec3 t, vec3 b, vec3 n) { return t * v.x + b * v.y + n * v.z; }

vec3 world_to_frame(vec3 w, vec3 t, vec3 b, vec3 n) { return vec3(dot(w, t), dot(w, b), dot(w, n)); }

float azimuth_from_unit(float u) { return u > 0.5 ? IC_TAU * (u - 1.0) : IC_TAU * u; }

float stratum_phi_centre(uint k, uint n) { return azimuth_from_unit((float(k) + 0.5) / float(max(n, 1u))); }

float stratum_phi_start(uint k, uint n) { return azimuth_from_unit(float(k) / float(max(n, 1u))); }

vec3 horizontal_u(float phi) { return vec3(cos(phi), sin(phi), 0.0); }

vec3 horizontal_v(float phi) { return vec3(-sin(phi), cos(phi), 0.0); }

float stratum_tan_centre(uint j, uint m) {
    uint mm = max(m, 1u);
    float s2 = (float(min(j, mm - 1u)) + 0.5) / float(mm);
    return sqrt(s2 / max(1.0 - s2, 0.5 / float(mm)));
}

float stratum_tan_mean(uint j, uint m) {
    uint mm = max(m, 1u);
    uint jj = min(j, mm - 1u);
    float mf = float(mm);
    float ua = float(jj) / mf;
    float ub = float(jj + 1u) / mf;
    float sa = sqrt(ua);
    float ca = sqrt(max(1.0 - ua, 0.0));
    float sb = sqrt(min(ub, 1.0));
    float cb = sqrt(max(1.0 - ub, 0.0));
    float dtheta = atan(sb * ca - sa * cb, cb * ca + sb * sa);
    return max(mf * (dtheta - (sb * cb - sa * ca)), 0.0);
}

vec3 stratum_direction_local(uint j, uint k, uint m, uint n, float xi, float psi) {
    float x = clamp(xi, 0.0, 1.0);
    float y = clamp(psi, 0.0, 1.0);
    float s2 = clamp((float(j) + x) / float(max(m, 1u)), 0.0, 1.0);
    float sin_t = sqrt(s2);
    float cos_t = sqrt(max(1.0 - s2, 0.0));
    float phi = azimuth_from_unit((float(k) + y) / float(max(n, 1u)));
    return vec3(sin_t * cos(phi), sin_t * sin(phi), cos_t);
}

uint ircache_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float unit_float_from_bits(uint h) { return float(h >> 8u) * (1.0 / 16777216.0); }

void stratum_jitter(uint seed, uint index, out float xi, out float psi) {
    uint h1 = ircache_hash(index + ircache_hash(seed));
    uint h2 = ircache_hash(h1);
    xi = unit_float_from_bits(h1);
    psi = unit_float_from_bits(h2);
}

float stratum_projected_solid_angle(uint m, uint n) { return IC_PI / (float(max(m, 1u)) * float(max(n, 1u))); }

// ---- record sums and gradients (§2.5, §3.1, §3.2) ----

bool is_valid_sample(float r, float r_eps) { return r > max(r_eps, 0.0); }

float inverse_distance(float r, float r_eps) {
    if (is_valid_sample(r, r_eps) && r < IC_FAR) {
        return 1.0 / r;
    }
    return 0.0;
}

float harmonic_mean_distance(float sum_inv_r, float valid_count) {
    if (sum_inv_r > 0.0 && valid_count > 0.0) {
        return sum_inv_r < IC_FAR ? min(valid_count / sum_inv_r, IC_FAR) : 0.0;
    }
    return IC_FAR;
}

bool stratum_elevation_ok(uint j, uint m) { return 1.0 - (float(j) + 1.0) / float(max(m, 1u)) >= ELEVATION_MIN_SIN2; }

vec3 rotational_gradient_coeff(uint j, uint k, uint m, uint n) {
    return horizontal_v(stratum_phi_centre(k, n)) * (stratum_projected_solid_angle(m, n) * stratum_tan_mean(j, m));
}

vec3 polar_wall_coeff(uint j, uint k, uint m, uint n) {
    uint mm = max(m, 1u);
    if (j == 0u || j >= mm) {
        return vec3(0.0);
    }
    float s2 = float(j) / float(mm);
    float c = (IC_TAU / float(max(n, 1u))) * sqrt(s2) * (1.0 - s2);
    return horizontal_u(stratum_phi_centre(k, n)) * c;
}

vec3 azimuthal_wall_coeff(uint j, uint k, uint m, uint n) {
    uint mm = max(m, 1u);
    float jf = float(min(j, mm - 1u));
    float mf = float(mm);
    float s2c = (jf + 0.5) / mf;
    float cos_lo = sqrt(max(1.0 - jf / mf, 0.0));
    float cos_hi = sqrt(max(1.0 - (jf + 1.0) / mf, 0.0));
    float c = sqrt(1.0 - s2c) * (cos_lo - cos_hi) / sqrt(s2c);
    return horizontal_v(stratum_phi_start(k, n)) * c;
}

vec3 wall_term(vec3 l_cur, vec3 l_prev, float r_cur, float r_prev, float r_eps) {
    if (!is_valid_sample(r_cur, r_eps) || !is_valid_sample(r_prev, r_eps)) {
        return vec3(0.0);
    }
    float r = max(min(r_cur, r_prev), R_FLOOR);
    if (r < IC_FAR) {
        return (l_cur - l_prev) / r;
    }
    return vec3(0.0);
}

// ---- radiance records (radcache_cache::radiance, docs/radiance-caching.md §7) ----

float stratum_solid_angle(uint j, uint m, uint n) {
    uint mm = max(m, 1u);
    float jf = float(min(j, mm - 1u));
    float mf = float(mm);
    float cos_lo = sqrt(max(1.0 - jf / mf, 0.0));
    float cos_hi = sqrt(max(1.0 - (jf + 1.0) / mf, 0.0));
    return (IC_TAU / float(max(n, 1u))) * (cos_lo - cos_hi);
}

vec3 radiance_sample(vec3 l, float r) { return r < IC_FAR ? l : vec3(0.0); }

vec3 radiance_polar_wall_coeff(uint j, uint k, uint m, uint n) {
    uint mm = max(m, 1u);
    if (j == 0u || j >= mm) {
        return vec3(0.0);
    }
    float s2 = float(j) / float(mm);
    float c = (IC_TAU / float(max(n, 1u))) * sqrt(s2) * sqrt(max(1.0 - s2, 0.0));
    return horizontal_u(stratum_phi_centre(k, n)) * c;
}

vec3 radiance_azimuthal_wall_coeff(uint j, uint k, uint m, uint n) {
    uint mm = max(m, 1u);
    float jf = float(min(j, mm - 1u));
    float mf = float(mm);
    float s2c = (jf + 0.5) / mf;
    float cos_lo = sqrt(max(1.0 - jf / mf, 0.0));
    float cos_hi = sqrt(max(1.0 - (jf + 1.0) / mf, 0.0));
    return horizontal_v(stratum_phi_start(k, n)) * ((cos_lo - cos_hi) / sqrt(s2c));
}

// NaN fails every comparison, so it is rejected too (where the driver keeps NaN).
bool irradiance_is_valid(vec3 e) { return all(greaterThanEqual(e, vec3(0.0))) && all(lessThan(e, vec3(3.0e38))); }

// ---- radius (§4.2-§4.7) ----

float sanitize_radius(float r) { return min(max(r, 0.0), IC_FAR); }

float gradient_limit_radius(float r, vec3 e, vec3 gt_r, vec3 gt_g, vec3 gt_b) {
    float out_r = sanitize_radius(r);
    float g = length(gt_r);
    if (g > 0.0) { out_r = min(out_r, max(e.x, 0.0) / g); }
    g = length(gt_g);
    if (g > 0.0) { out_r = min(out_r, max(e.y, 0.0) / g); }
    g = length(gt_b);
    if (g > 0.0) { out_r = min(out_r, max(e.z, 0.0) / g); }
    return out_r;
}

// The glossy gradient limit from its sums per channel (Σ c², Σ |∂c/∂x|²): the smallest
// √(Σc²/Σg²) over the channels with a positive, finite Σg²; IC_FAR when none
// (radcache_cache::radiance::glossy_gradient_limit_from_sums).
float glossy_gradient_limit_from_sums(vec3 coeff_sq, vec3 grad_sq) {
    float out_r = IC_FAR;
    for (int c = 0; c < 3; ++c) {
        if (grad_sq[c] > 0.0 && !isinf(grad_sq[c])) {
            out_r = min(out_r, sqrt(max(coeff_sq[c], 0.0) / grad_sq[c]));
        }
    }
    return out_r;
}

float neighbour_clamp(float r_i, float r_j, float d_ij) { return min(sanitize_radius(r_i), sanitize_radius(r_j) + max(d_ij, 0.0)); }

void neighbour_clamp_pair(float r_i, vec3 p_i, float r_j, vec3 p_j, out float new_r_i, out float new_r_j) {
    float d = length(p_i - p_j);
    new_r_i = neighbour_clamp(r_i, r_j, d);
    new_r_j = neighbour_clamp(r_j, r_i, d);
}

float pixel_footprint_from_differentials(vec3 dpdx, vec3 dpdy) { return sqrt(length(cross(dpdx, dpdy))); }

float pixel_footprint(float depth, float tan_half_fov_y, float image_height, float cos_view) {
    float s = 2.0 * abs(depth) * abs(tan_half_fov_y) / max(image_height, 1.0);
    return s / sqrt(max(abs(cos_view), 0.1));
}

void radius_bounds(float footprint, float min_px, float max_px, float v_scale, out float r_lo, out float r_hi) {
    float scale = max(v_scale, 1.0e-6);
    float s = max(footprint, 0.0);
    r_lo = min(max(max(min_px, 0.0) * s / scale, R_FLOOR), IC_FAR);
    r_hi = min(max(max(max_px, 0.0) * s / scale, r_lo), IC_FAR);
}

float clamp_radius(float r, float r_lo, float r_hi) {
    float lo = min(max(r_lo, R_FLOOR), IC_FAR);
    float hi = min(max(r_hi, lo), IC_FAR);
    return min(max(sanitize_radius(r), lo), hi);
}

float gradient_attenuation(float r_unclamped, float r_lo) {
    return min(sanitize_radius(r_unclamped) / min(max(r_lo, R_FLOOR), IC_FAR), 1.0);
}

// §4.7 steps 1-5; outputs in the order of the Rust `FinalRadius` fields.
void finalize_radius(float r, vec3 e, vec3 gt_r, vec3 gt_g, vec3 gt_b, float r_neighbour, float r_lo, float r_hi,
                     out float r_orig, out float r_used, out float r_lo_out, out float r_hi_out, out float grad_t_scale) {
    float limited = gradient_limit_radius(r, e, gt_r, gt_g, gt_b);
    r_orig = min(limited, sanitize_radius(r_neighbour));
    r_lo_out = min(max(r_lo, R_FLOOR), IC_FAR);
    r_hi_out = min(max(r_hi, r_lo_out), IC_FAR);
    r_used = clamp_radius(r_orig, r_lo_out, r_hi_out);
    grad_t_scale = gradient_attenuation(r_orig, r_lo_out);
}

// ---- Hessian error control (§10; Rust: hessian.rs) ----

// Series terms of atan(sqrt(tau))/sqrt(tau) below HESSIAN_SERIES_TAU.
const uint HESSIAN_SERIES_TERMS = 13u;

vec3 hessian_angle_terms(float s2, float h) {
    float q = s2 + h * h;
    if (q <= 0.0 || (s2 <= 0.0 && h <= 0.0)) {
        return vec3(0.0);
    }
    if (h > 0.0 && s2 < HESSIAN_SERIES_TAU * h * h) {
        float tau = s2 / (h * h);
        float p0 = 0.0, p1 = 0.0, p2 = 0.0;
        for (uint i = 0u; i < HESSIAN_SERIES_TERMS; ++i) {
            uint ki = HESSIAN_SERIES_TERMS - 1u - i;
            float k = float(ki);
            float c = ((ki & 1u) == 0u ? 1.0 : -1.0) / (2.0 * k + 1.0);
            p0 = p0 * tau + c;
            if (ki >= 1u) {
                p1 = p1 * tau + c * k;
            }
            if (ki >= 2u) {
                p2 = p2 * tau + c * k * (k - 1.0);
            }
        }
        float h2 = h * h;
        return vec3(p0 / h, p1 / (h2 * h), p2 / (h2 * h2 * h));
    }
    float s = sqrt(s2);
    float gamma = atan(s, h);
    float g = gamma / s;
    float g_s = h / (2.0 * s2 * q) - gamma / (2.0 * s2 * s);
    float g_ss = -3.0 * h / (4.0 * s2 * s2 * q) - h / (2.0 * s2 * q * q) + 3.0 * gamma / (4.0 * s2 * s2 * s);
    return vec3(g, g_s, g_ss);
}

float hessian_vertex_distance(vec4 v) { return v.w > 0.0 ? min(length(v.xyz), IC_FAR) : IC_FAR; }

// Symmetric u v^T + v u^T as (xx, xy, yy).
vec3 hessian_outer(vec2 u, vec2 v) { return vec3(2.0 * u.x * v.x, u.x * v.y + u.y * v.x, 2.0 * u.y * v.y); }

vec4 hessian_edge(vec4 a, vec4 b) {
    float alpha = a.w > 0.0 ? 1.0 : 0.0;
    float beta = b.w > 0.0 ? 1.0 : 0.0;
    float la = length(a.xyz);
    float lb = length(b.xyz);
    if (la <= 0.0 || lb <= 0.0) {
        return vec4(0.0);
    }
    if (alpha * beta > 0.0 && la > 1.0e4 * lb) {
        alpha = 0.0;
    }
    if (alpha * beta > 0.0 && lb > 1.0e4 * la) {
        beta = 0.0;
    }
    float scale = max(alpha * la, beta * lb);
    float inv = scale > 0.0 ? 1.0 / scale : 1.0;
    vec3 av = a.xyz * (alpha > 0.0 ? inv : 1.0 / la);
    vec3 bv = b.xyz * (beta > 0.0 ? inv : 1.0 / lb);
    vec3 c = cross(av, bv);
    float s2 = dot(c, c);
    float h = dot(av, bv);
    float m = c.z;
    vec3 g = hessian_angle_terms(s2, h);
    float f = 0.5 * m * g.x;
    if (scale <= 0.0 || (g.x == 0.0 && g.y == 0.0)) {
        return vec4(f, 0.0, 0.0, 0.0);
    }
    float q = s2 + h * h;
    float g_h = -1.0 / q;
    float g_hh = 2.0 * h / (q * q);
    float g_sh = 1.0 / (q * q);
    vec3 w = bv * alpha - av * beta;
    vec2 gs = 2.0 * cross(c, w).xy;
    vec2 gh = -(bv * alpha + av * beta).xy;
    vec2 gm = vec2(-w.y, w.x);
    float w2 = dot(w, w);
    vec3 hs = vec3(2.0 * (w2 - w.x * w.x), -2.0 * w.x * w.y, 2.0 * (w2 - w.y * w.y));
    vec3 hh = vec3(1.0, 0.0, 1.0) * (2.0 * alpha * beta);
    vec3 hess = (hs * g.y + hh * g_h) * m + hessian_outer(gs, gs) * (0.5 * m * g.z)
              + hessian_outer(gh, gh) * (0.5 * m * g_hh) + hessian_outer(gs, gh) * (m * g_sh)
              + hessian_outer(gs, gm) * g.y + hessian_outer(gh, gm) * g_h;
    float k = 0.5 * inv * inv;
    return vec4(f, hess * k);
}

vec4 hessian_vertex(uint j, uint k, uint m, uint n, uint seed, float r, float r_eps) {
    float xi, psi;
    stratum_jitter(seed, stratum_index(j, k, n), xi, psi);
    vec3 d = stratum_direction_local(j, k, m, n, xi, psi);
    if (is_valid_sample(r, r_eps) && r < IC_FAR) {
        return vec4(d * r, 1.0);
    }
    return vec4(d, 0.0);
}

vec4 hessian_horizon_vertex(vec4 v) {
    float len = length(v.xy);
    vec2 dir = len > 0.0 ? v.xy / len : vec2(1.0, 0.0);
    float dist = v.w > 0.0 ? length(v.xyz) : 1.0;
    return vec4(dir * dist, 0.0, v.w);
}

float hessian_luminance(float y, float mean_y) { return mean_y > 0.0 ? 0.99 * max(y, 0.0) / mean_y + 0.01 : 1.0; }

float hessian_farthest(vec4 a, float y_a, vec4 b, float y_b, vec4 c, float y_c) {
    float da = hessian_vertex_distance(a);
    float db = hessian_vertex_distance(b);
    float dc = hessian_vertex_distance(c);
    if (da >= db && da >= dc) {
        return y_a;
    }
    return db >= dc ? y_b : y_c;
}

vec4 hessian_cell(vec4 a, vec4 b, vec4 c, vec4 d, vec4 bl, vec4 au, vec4 y, float y_bl, float y_au, float y_cap,
                  bool first, bool last) {
    float y_lo = hessian_farthest(a, y.x, b, y.y, d, y.w);
    float y_hi = hessian_farthest(b, y.y, c, y.z, d, y.w);
    float y_left = hessian_farthest(bl, y_bl, b, y.y, a, y.x);
    float y_above = first ? y_cap : hessian_farthest(a, y.x, d, y.w, au, y_au);
    vec4 sum = hessian_edge(b, d) * (y_lo - y_hi) + hessian_edge(a, b) * (y_lo - y_left)
             + hessian_edge(a, d) * (y_above - y_lo);
    if (last) {
        sum += hessian_edge(b, c) * y_hi;
    }
    return sum;
}

float hessian_radius(vec4 h, float footprint) {
    float mean = 0.5 * (h.y + h.w);
    float half_d = 0.5 * (h.y - h.w);
    float lambda = abs(mean) + sqrt(half_d * half_d + h.z * h.z);
    if (!(h.x > 0.0) || !(lambda > 0.0)) {
        return IC_FAR;
    }
    float rel = lambda / h.x;
    return min(sqrt(2.0 * max(footprint, 0.0) * sqrt(HESSIAN_ERROR / rel)), IC_FAR);
}

// ---- weights (§5.1-§5.4, §5.6, §7.2) ----

bool normal_test(vec3 n, vec3 n_i) { return dot(n, n_i) > 0.0; }

bool in_front_test(vec3 p, vec3 p_i, vec3 n_i, float tol) { return dot(p - p_i, n_i) >= -max(tol, 0.0); }

float normal_error(vec3 n, vec3 n_i) { return length(n - n_i) * 0.70710678; }

float position_error(vec3 p, vec3 p_i, vec3 n_i, float r_i) {
    vec3 d = p - p_i;
    return (length(d) + abs(dot(d, n_i))) / min(max(r_i, R_FLOOR), IC_FAR);
}

float ward_weight(vec3 p, vec3 n, vec3 p_i, vec3 n_i, float r_i, float a, float front_tol) {
    if (!normal_test(n, n_i) || !in_front_test(p, p_i, n_i, front_tol)) {
        return 0.0;
    }
    float eps = position_error(p, p_i, n_i, r_i) + normal_error(n, n_i);
    if (eps < a) {
        return 1.0 / max(eps, WARD_MIN_ERROR);
    }
    return 0.0;
}

float tl_weight(vec3 p, vec3 n, vec3 p_i, vec3 n_i, float r_i, float kappa, float front_tol) {
    if (!normal_test(n, n_i) || !in_front_test(p, p_i, n_i, front_tol)) {
        return 0.0;
    }
    float e_p = 2.0 * position_error(p, p_i, n_i, r_i);
    float e_n = normal_error(n, n_i) / TL_NORMAL_SCALE;
    float w = 1.0 - max(kappa, KAPPA_MIN) * max(e_p, e_n);
    return w > 0.0 ? w : 0.0;
}

// Unknown kinds behave as T&L (Rust `WeightKind::from_u32`).
float record_weight(uint kind, vec3 p, vec3 n, vec3 p_i, vec3 n_i, float r_i, float param, float front_tol) {
    if (kind == WEIGHT_WARD) {
        return ward_weight(p, n, p_i, n_i, r_i, param, front_tol);
    }
    return tl_weight(p, n, p_i, n_i, r_i, param, front_tol);
}

float validity_scale(uint kind, float param) {
    if (kind == WEIGHT_WARD) {
        return max(param, 0.0);
    }
    return 0.5 / max(param, KAPPA_MIN);
}

float splat_radius(uint kind, float r_i, float param, float w_min) {
    float r = min(max(r_i, R_FLOOR), IC_FAR);
    if (kind == WEIGHT_WARD) {
        return min(r / max(1.0 / max(param, 1.0e-6), w_min), IC_FAR);
    }
    return (1.0 - clamp(w_min, 0.0, 1.0)) * r * (0.5 / max(param, KAPPA_MIN));
}

float weight_unit(uint kind, float param) {
    if (kind == WEIGHT_WARD) {
        return 1.0 / max(param, 1.0e-6);
    }
    return 1.0;
}

float coverage_threshold(uint kind, float param, float hole_threshold) {
    return max(hole_threshold, 0.0) * weight_unit(kind, param);
}

// ---- extrapolation (§6.1, §6.2) ----

vec3 clamp_extrapolation(vec3 x, vec3 e) {
    vec3 hi = max(e, vec3(0.0)) * EXTRAPOLATION_MAX_FACTOR;
    return min(max(x, vec3(0.0)), hi);
}

vec3 extrapolate_irradiance(vec3 e_i, vec3 gr_r, vec3 gr_g, vec3 gr_b, vec3 gt_r, vec3 gt_g, vec3 gt_b,
                            vec3 p, vec3 n, vec3 p_i, vec3 n_i) {
    vec3 rot = cross(n_i, n);
    vec3 dp = p - p_i;
    vec3 raw = e_i + vec3(dot(rot, gr_r) + dot(dp, gt_r), dot(rot, gr_g) + dot(dp, gt_g), dot(rot, gr_b) + dot(dp, gt_b));
    return clamp_extrapolation(raw, e_i);
}

// ---- temporal (docs/temporal.md §3.3) ----

vec3 temporal_gradient(vec3 e_t0, vec3 e_t1) { return e_t1 - e_t0; }

float temporal_lifespan(vec3 e_t0, vec3 e_t1, float a_t, float max_age) {
    float max_a = max(max_age, 0.0);
    float y0 = max(luminance_rec709(e_t0), 0.0);
    float y1 = max(luminance_rec709(e_t1), 0.0);
    float dy = abs(y1 - y0);
    float num = max(a_t, 0.0) * y0;
    if (num >= max_a * dy) {
        return max_a;
    }
    return num / dy;
}

bool temporal_is_valid(float age, float lifespan) { return age <= lifespan; }

vec3 temporal_extrapolate(vec3 e_t0, vec3 de_dt, float age) { return max(e_t0 + de_dt * max(age, 0.0), vec3(0.0)); }

float moving_cover(vec3 p, vec3 n, vec4 sphere) {
    vec3 v = sphere.xyz - p;
    float d = length(v);
    float r = max(sphere.w, 0.0);
    if (d <= r) {
        return r > 0.0 ? 1.0 : 0.0;
    }
    float k = r / d;
    float c = dot(n, v) / d;
    float f = c >= k ? k * k * c : (c > -k ? 0.25 * k * (c + k) * (c + k) : 0.0);
    return min(f, 1.0);
}

#endif // IRCACHE_MATH_GLSL
