// passes/direct.comp — Rust: crates/radcache-render/src/passes/direct.rs
// Direct lighting of the cache's frame (compute, ray queries): per surface pixel, `samples`
// one-sample-MIS estimates of the light arriving straight from emissive triangles and the
// environment (see one_sample), plus the punctual lights once (they need no sampling). Written:
// albedo/π × the estimate (emission itself is in the G-buffer's emission image). With
// HAS_SPECULAR (a scene with non-Lambertian materials) the estimate weighs each sample with the
// full BRDF (one_sample_brdf), and the specular lobe's indirect light is added, path traced
// (specular_path) and pooled over the neighbourhood (specular_pooled); the written value is that
// reflected radiance. A pixel that per-pixel adaptive anti-aliasing has stopped (G-buffer
// position w = −1, docs/cache-frame.md §7.2) is no surface here: it traces nothing, and the
// composite skips it. With DIRECT_COMPOSITE and pc.composite (the later sub-frames of a frame
// splatted once, docs/cache-frame.md §6.5) the pass adds the sample to the frame's accumulators
// itself (composite_sample.glsl, as passes/composite.comp would) instead of writing the image.
//
// Sample g of a pixel (g = sub_frame · count + k; sub-frames continue the sequence) draws its random
// numbers from Kronecker sequences (Roberts 2018, the R_d sequences: point g is fract(shift + g·α),
// α the powers of 1/φ_d, φ_d the real root of x^(d+1) = x + 1; d = 1 is the golden ratio): R1 for
// the technique, R3 for the light sample, R2 for the BSDF direction, each with a random per-pixel
// shift (Cranley–Patterson rotation). Every sample is therefore uniform (the estimate is
// unbiased) while a pixel's samples stay evenly spread for any count (stratification), which
// makes direct noise fall faster than with independent samples.
#version 460
#extension GL_GOOGLE_include_directive : require

#define GBUFFER_DIRECT_ACCESS writeonly
#include "../common/path.glsl"
#include "../common/gbuffer.glsl"
#include "../shared/push.glsl"
#include "../shared/constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
#include "../common/dispatch.glsl"

layout(push_constant) uniform Push { DirectPush pc; };

layout(binding = B_DIRECT_RAY_COUNT, std430) buffer RayCount { uint ray_count; };
// With pc.adaptive_shadows, SHADOW_WORDS words a pixel (docs/cache-frame.md §8.2), from
// i = SHADOW_WORDS × the pixel's index (the words' indices SHADOW_WORD_* and counts
// SHADOW_WORDS_* come from constants.glsl, radcache_shared::consts): i + SHADOW_WORD_SEEN, what
// its neighbourhood saw of the emitters in this frame's sub-frames so far (written at sub-frame
// 0, raised to a penumbra by later ones); i + SHADOW_WORD_FROZEN, what sub-frame 0 saw, frozen
// for the later sub-frames to compare with the neighbours': the emitters' word (bits 0–1,
// SHADOW_NONE where the pixel was no surface) and the visibility of punctual lights 0 …
// REUSED_LIGHTS − 1 (bit 2 + i set where light i's shadow ray was unoccluded);
// i + SHADOW_WORD_DISTANCE, the distance from the camera of sub-frame 0's sample (its float
// bits), which tells a later sample on another surface; with HAS_ANALYTIC_EMITTERS,
// i + SHADOW_WORD_NORMAL, sub-frame 0's shading normal (octahedral, packSnorm2x16), and
// i + SHADOW_WORD_UNSHADOWED … + 2, the emitters' unshadowed irradiance there (float bits), taken
// again by later samples on that surface (`first_unshadowed`).
layout(binding = B_DIRECT_SHADOWS, std430) buffer Shadows { uint shadows[]; };
#ifdef HAS_ANALYTIC_EMITTERS
const uint SHADOW_WORDS = SHADOW_WORDS_ANALYTIC;
#else
const uint SHADOW_WORDS = SHADOW_WORDS_SAMPLED;
#endif
// What a pixel's neighbourhood saw of the emitters (the values of its SHADOW_WORD_SEEN word):
// SHADOW_HIDDEN, SHADOW_LIT, SHADOW_PENUMBRA, SHADOW_NONE (radcache_shared::consts::ShadowClass).
const uint REUSED_LIGHTS = 29u;
// The punctual lights' bits of the frozen word, and its bit 31, SHADOW_EDGE (constants.glsl):
// sub-frame 0's samples of the pixel's 3×3 neighbourhood did not all lie on the pixel's surface
// (no reuse at the pixel).
const uint PUNCTUAL_BITS = ((1u << REUSED_LIGHTS) - 1u) << 2;

// After sub-frame 0 (pc.adaptive_shadows): which of sub-frame 0's answers this pixel's sample
// may take without a ray. Sub-frame 0's samples of the pixel and of its 3×3 neighbours (inside
// the image) must all have lain on one surface (else SHADOW_EDGE), this sample must lie on it
// too (`same_surface_as_first`), and every neighbour must have seen the same as the pixel: the
// same visibility of every reused punctual light (`punctual`), and the emitters wholly visible
// or wholly hidden alike (`emitters`). A shadow boundary at or next to the pixel therefore
// keeps its rays, and so does a pixel that an object's edge crosses or passes next to (a rim
// or a leaf one pixel wide, whose neighbours on other surfaces say nothing of its light, or a
// grazing plane, whose neighbours lie farther apart than three footprints) and a sample that
// the jitter moved onto another object; what is reused is a pixel deep inside light or shadow
// on one surface, whose jittered samples, within half a pixel of its centre, see what nine
// samples around them saw (a shadow finer than the pixel grid can be missed).
// The linear index of `pixel` (its SHADOW_WORDS words in `shadows` start at SHADOW_WORDS × it;
// its sample sequences' seed).
uint pixel_index(ivec2 pixel) {
    return uint(pixel.y) * frame.resolution.x + uint(pixel.x);
}

// Whether the point `position` with normal `normal` lies on the surface of sample `g` (a
// neighbour's sample: normals within 25°, within one footprint of g's tangent plane and three
// footprints of g).
bool on_surface_of(GSample g, vec3 position, vec3 normal) {
    vec3 d = position - g.position;
    float reach = 3.0 * g.footprint;
    return dot(normal, g.normal) >= 0.9 && abs(dot(d, g.normal)) <= g.footprint &&
           dot(d, d) <= reach * reach;
}

// Sub-frame 0: whether the samples of the pixel's 3×3 neighbours inside the image are surfaces
// on the surface of its own sample `g` (read from the G-buffer, not the workgroup's copy).
bool neighbourhood_on_one_surface(GSample g, ivec2 pixel) {
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = pixel + ivec2(dx, dy);
            if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) ||
                any(greaterThanEqual(q, ivec2(frame.resolution.xy)))) {
                continue;
            }
            vec4 p = imageLoad(g_position, q);
            if (!(p.w > 0.5) || !on_surface_of(g, p.xyz, imageLoad(g_normal, q).xyz)) {
                return false;
            }
        }
    }
    return true;
}

// Whether sample `g` lies on the surface of the pixel's sub-frame-0 sample, `first_distance`
// from the camera: two points of one plane within a pixel differ in distance by at most about
// the pixel's footprint times the tangent of the view angle (a grazing plane's distance
// changes fast across the pixel), so the test allows 1.5 of that, cosine floored at 0.1, plus
// 0.1 % of the distance for the G-buffer's precision.
bool same_surface_as_first(GSample g, float first_distance) {
    vec3 to_camera = frame.camera_position.xyz - g.position;
    float d = length(to_camera);
    float cos_v = d > 0.0 ? abs(dot(g.normal, to_camera)) / d : 1.0;
    float sin_v = sqrt(max(1.0 - cos_v * cos_v, 0.0));
    float tol = 1.5 * g.footprint * sin_v / max(cos_v, 0.1) + 1.0e-3 * d;
    return abs(d - first_distance) <= tol;
}

struct Reuse {
    uint frozen;  // the pixel's sub-frame-0 word
    bool punctual;
    bool emitters;
    bool on_first;  // after sub-frame 0: the sample lies on the surface of sub-frame 0's
};

Reuse shadow_reuse(GSample g, ivec2 pixel) {
    Reuse r;
    r.frozen = SHADOW_NONE;
    r.punctual = false;
    r.emitters = false;
    r.on_first = false;
    if (pc.adaptive_shadows == 0u || pc.sub_frame == 0u) {
        return r;
    }
    uint index = pixel_index(pixel);
    uint base = SHADOW_WORDS * index;
    uint own = shadows[base + SHADOW_WORD_FROZEN];
    r.frozen = own;
    float first_distance = uintBitsToFloat(shadows[base + SHADOW_WORD_DISTANCE]);
    r.on_first = (own & 3u) != SHADOW_NONE && same_surface_as_first(g, first_distance);
    if (!r.on_first || (own & SHADOW_EDGE) != 0u) {
        return r;
    }
    r.punctual = true;
    r.emitters = (own & 3u) != SHADOW_PENUMBRA;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = pixel + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(frame.resolution.xy)))) {
                continue;
            }
            uint n = shadows[SHADOW_WORDS * pixel_index(q) + SHADOW_WORD_FROZEN];
            bool surface = (n & 3u) != SHADOW_NONE;
            r.punctual = r.punctual && surface && ((n ^ own) & PUNCTUAL_BITS) == 0u;
            r.emitters = r.emitters && surface && (n & 3u) == (own & 3u);
        }
    }
    return r;
}

#ifdef HAS_RADIANCE_CACHE
// Radiance records for glossy lobes (docs/radiance-caching.md §6.2): where pc.radiance_cache is
// set and the pixel's roughness is at least GLOSSY_ROUGHNESS_MIN, the specular lobe's indirect
// light comes from the records (passes/splat_glossy.frag) instead of specular_path's paths,
// and this pass writes the pixel's glossy world weights for that splat.
#define GLOSSY_TABLE_BINDING B_DIRECT_GLOSSY_TABLE
#include "../common/glossy.glsl"
layout(binding = B_DIRECT_GLOSSY_WEIGHTS, std430) writeonly buffer GlossyWeights { vec4 glossy_w[]; };

// The world weights of pixel `index`'s lobe, packed as the records' coefficients.
void write_glossy_weights(uint index, Bsdf f, vec3 to_viewer) {
    vec3 w[SH_COEFFS];
    glossy_world_weights(f.m, f.n, to_viewer, w);
    uint base = index * RADIANCE_VEC4S;
    for (uint q = 0u; q < RADIANCE_VEC4S; ++q) {
        vec4 v;
        for (uint lane = 0u; lane < 4u; ++lane) {
            uint fi = 4u * q + lane;
            vec3 wi = w[fi / 3u];
            float x = wi[fi % 3u];
            v[lane] = (isnan(x) || isinf(x)) ? 0.0 : x;
        }
        glossy_w[base + q] = v;
    }
}
#endif

#include "direct_light.glsl"

// The light of one surface pixel: `rest` (everything but the emitters under
// HAS_ANALYTIC_EMITTERS) and, for the ratio estimator, the emitters' closed-form unshadowed
// irradiance and the pixel's sample sums.
struct PixelLight {
    vec3 rest;
    vec3 unshadowed;
    vec3 sum_all;
    vec3 sum_visible;
    uint seen;  // with adaptive shadows after sub-frame 0: what sub-frame 0 saw (SHADOW_*)
    bool reused;  // no emitter sample: sub-frame 0's answer stands (`Reuse`)
    uint punctual_seen;  // the traced punctual lights' visibility bits (`punctual_visible`)
    bool closed_form;  // the emitters' light in closed form (false: in the MIS, HAS_SPECULAR)
    bool specular_paths;  // the specular lobe's indirect light by paths (HAS_SPECULAR)
};

// A pixel's light before anything is added (also a pixel without a surface).
PixelLight no_light() {
    PixelLight light;
    light.rest = vec3(0.0);
    light.unshadowed = vec3(0.0);
    light.sum_all = vec3(0.0);
    light.sum_visible = vec3(0.0);
    light.seen = SHADOW_PENUMBRA;
    light.reused = false;
    light.punctual_seen = 0u;
    light.closed_form = true;
    light.specular_paths = false;
    return light;
}

// The surface of sample `g` as the light functions take it.
Surface sample_surface(GSample g) {
    Surface s;
    s.position = g.position;
    s.geometric_normal = g.geometric;
    s.shading_normal = g.normal;
    s.uv = TexCoords(0.0);
    s.material = g.material;
    s.front_face = true;
    return s;
}

#ifdef HAS_ANALYTIC_EMITTERS
// The octahedral map of unit vector n to the square [−1, 1]² (and back), for the stored normal.
vec2 octahedral(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 sign_xy = vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * sign_xy;
}

vec3 from_octahedral(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.xy += vec2(n.x >= 0.0 ? -t : t, n.y >= 0.0 ? -t : t);
    return normalize(n);
}

// Normals closer than this (cosine; about 0.6°) share sub-frame 0's unshadowed irradiance.
const float FIRST_NORMAL_COS = 0.99995;

// The emitters' unshadowed irradiance at sample `g`: after sub-frame 0, where the sample lies
// on the surface of sub-frame 0's (`reuse.on_first`) with its normal within FIRST_NORMAL_COS,
// the irradiance sub-frame 0 computed there (a later sample is within the same pixel, and the
// irradiance, smooth at the scale of the emitters' distance, changes across a pixel only by a
// linear term that the jittered sub-frames average out; docs/cache-frame.md §8.2); else the
// closed form, which sub-frame 0 stores for them.
vec3 first_unshadowed(GSample g, uint index, vec3 origin, Reuse reuse) {
    uint base = SHADOW_WORDS * index;
    if (pc.adaptive_shadows != 0u && reuse.on_first) {
        vec3 n = from_octahedral(unpackSnorm2x16(shadows[base + SHADOW_WORD_NORMAL]));
        if (dot(n, g.normal) >= FIRST_NORMAL_COS) {
            return vec3(uintBitsToFloat(shadows[base + SHADOW_WORD_UNSHADOWED]),
                        uintBitsToFloat(shadows[base + (SHADOW_WORD_UNSHADOWED + 1u)]),
                        uintBitsToFloat(shadows[base + (SHADOW_WORD_UNSHADOWED + 2u)]));
        }
    }
    vec3 e = analytic_emitter_irradiance(origin, g.normal);
    if (pc.adaptive_shadows != 0u && pc.sub_frame == 0u) {
        // Read by later sub-frames only (other dispatches).
        shadows[base + SHADOW_WORD_NORMAL] = packSnorm2x16(octahedral(g.normal));
        shadows[base + SHADOW_WORD_UNSHADOWED] = floatBitsToUint(e.r);
        shadows[base + (SHADOW_WORD_UNSHADOWED + 1u)] = floatBitsToUint(e.g);
        shadows[base + (SHADOW_WORD_UNSHADOWED + 2u)] = floatBitsToUint(e.b);
    }
    return e;
}
#endif

PixelLight pixel_light(GSample g, ivec2 pixel) {
    Surface s = sample_surface(g);
    vec3 origin = offset_ray_origin(s.position, s.geometric_normal);
    uint index = pixel_index(pixel);
    PixelLight light = no_light();
    Reuse reuse = shadow_reuse(g, pixel);
    uint samples = max(pc.samples, 1u);
    Rng rng = rng_init(index, 0xffffffffu, pc.seed);
    float shift_pick = rng_next(rng);
    vec3 shift_light = vec3(rng_next(rng), rng_next2(rng));
    vec2 shift_bsdf = rng_next2(rng);
    // Samples of the one-sample MIS loop per sub-frame (sub-frames continue its sequences).
    uint n = samples;
#ifdef HAS_SPECULAR
    // Everything here is reflected radiance (the full BRDF), not irradiance.
    Bsdf f = bsdf_at(s, gbuffer_material(g), normalize(frame.camera_position.xyz - g.position));
#endif
#ifdef HAS_ANALYTIC_EMITTERS
#ifdef HAS_SPECULAR
    // The closed form is the diffuse lobe's, exact where that lobe is all there is (no metal, no
    // specular layer: base colour / π); a pixel with a specular lobe samples the emitters in
    // its MIS as without HAS_ANALYTIC_EMITTERS (docs/cache-frame.md §8.2).
    bool closed_form = f.m.metallic == 0.0 && f.m.specular_factor == 0.0;
    light.closed_form = closed_form;
#else
    const bool closed_form = true;
#endif
    // The emitters take their own shadow rays, a quarter of the samples (the ratio estimator
    // with its neighbourhood reaches about the noise of `samples` MIS samples with them:
    // docs/cache-frame.md §8.2); the one-sample MIS loop keeps the rest for the environment
    // (none where nothing else is sampled).
    uint n_emitters = max(1u, (samples + 3u) / 4u);
#if defined(HAS_SAMPLED_SOURCES) && (!defined(HAS_SPECULAR) || defined(MIS_ENVIRONMENT))
    n = closed_form ? max(1u, samples - n_emitters) : samples;
#elif defined(HAS_SAMPLED_SOURCES)
    n = closed_form ? 0u : samples;
#endif
    // After sub-frame 0, where no penumbra was seen one ray tells lit from hidden: the ratio is
    // exact there whatever the count, and none where the whole neighbourhood saw the same
    // (`shadow_reuse`; docs/cache-frame.md §8.2). Sub-frame k's samples start at
    // k × n_emitters of the sequence either way.
    if (pc.adaptive_shadows != 0u && pc.sub_frame > 0u) {
        light.seen = shadows[SHADOW_WORDS * index + SHADOW_WORD_SEEN];
    }
    uint n_shadow = light.seen == SHADOW_PENUMBRA ? n_emitters : (reuse.emitters ? 0u : 1u);
    light.reused = n_shadow == 0u;
    light.unshadowed = closed_form ? first_unshadowed(g, index, origin, reuse) : vec3(0.0);
#ifdef HAS_SPECULAR
    // Reflected radiance: the irradiance times the diffuse lobe, base colour / π.
    light.unshadowed *= f.m.base_colour * INV_PI;
#endif
    if (any(greaterThan(light.unshadowed, vec3(0.0)))) {
        emitter_ratio_sums(s, origin, pc.sub_frame * n_emitters, n_shadow, shift_light,
                           light.sum_all, light.sum_visible);
    }
#endif
    vec3 sum = vec3(0.0);
#if defined(HAS_SPECULAR) && defined(HAS_SAMPLED_SOURCES)
#ifdef HAS_ANALYTIC_EMITTERS
    Techniques c = techniques(!closed_form);
#else
    Techniques c = techniques(true);
#endif
#endif
#ifdef HAS_SAMPLED_SOURCES
    for (uint k = 0u; k < n; ++k) {
        uint g = pc.sub_frame * n + k;
        // The technique from the golden-ratio sequence, so each pixel's picks are stratified too.
        float u_pick = min(fract(shift_pick + float(g) * 0.6180339887), ONE_MINUS_EPS);
#ifdef HAS_SPECULAR
        vec3 e = one_sample_brdf(s, f, origin, c, u_pick, kronecker3(g, shift_light),
                                 kronecker2(g, shift_bsdf));
#else
        vec3 e = one_sample(s, origin, u_pick, kronecker3(g, shift_light), kronecker2(g, shift_bsdf));
#endif
        if (!any(isnan(e)) && !any(isinf(e))) {
            sum += e;
        }
    }
#endif
#ifdef HAS_SPECULAR
    // The specular lobe's indirect light: paths pooled over the neighbourhood (specular_pooled),
    // where the lobe has light of its own and the radiance records do not take it.
    light.specular_paths = f.m.metallic > 0.0 || f.m.specular_factor > 0.0;
#ifdef HAS_RADIANCE_CACHE
    if (pc.radiance_cache != 0u && f.m.roughness >= GLOSSY_ROUGHNESS_MIN) {
        write_glossy_weights(index, f, normalize(frame.camera_position.xyz - g.position));
        light.specular_paths = false;
    }
#endif
    light.rest = (n > 0u ? sum / float(n) : vec3(0.0)) +
                 punctual_brdf(s, f, origin, reuse, light.punctual_seen);
#else
    light.rest = (n > 0u ? sum / float(n) : vec3(0.0)) + punctual(s, origin, reuse, light.punctual_seen);
#endif
    return light;
}

#include "direct_neighbourhood.glsl"

#ifdef DIRECT_COMPOSITE
// With pc.composite (docs/cache-frame.md §6.5): the sub-frame's composite against the frame's
// centre samples, here rather than in a pass of its own, which would load the G-buffer and the
// direct image again (passes/composite.comp; the composite's resources at the pass's bindings).
#define COMPOSITE_B_SPLAT_SUM B_DIRECT_COMPOSITE_SPLAT_SUM
#define COMPOSITE_B_ACCUM B_DIRECT_COMPOSITE_ACCUM
#define COMPOSITE_B_NONFINITE B_DIRECT_COMPOSITE_NONFINITE
#define COMPOSITE_B_EMISSION_ACCUM B_DIRECT_COMPOSITE_EMISSION_ACCUM
#define COMPOSITE_B_CENTRE B_DIRECT_COMPOSITE_CENTRE
#define COMPOSITE_B_GLOSSY_SUM B_DIRECT_COMPOSITE_GLOSSY_SUM
#include "composite_sample.glsl"
#endif

void main() {
    ivec2 pixel = ivec2(interleaved_pixel());
    bool inside = all(lessThan(pixel, ivec2(frame.resolution.xy)));
    GSample g;
    g.surface = false;
    if (inside) {
        g = gbuffer_load(pixel);
    }
    PixelLight light = no_light();
    if (g.surface) {
        light = pixel_light(g, pixel);
    }
#ifdef HAS_SPECULAR
    // Every invocation of the workgroup reaches the barriers inside (no early return above).
    light.rest += specular_pooled(g, inside ? pixel_index(pixel) : 0u, light.specular_paths);
#endif
    // Sub-frame 0's emitter word for the frozen copy (HIDDEN for all without analytic emitters).
    uint frozen_class = SHADOW_HIDDEN;
    vec3 e = light.rest;
#ifdef HAS_ANALYTIC_EMITTERS
    // Every invocation of the workgroup reaches this barrier (no early return above).
    uint lid = gl_LocalInvocationIndex;
    s_sum_all[lid] = light.sum_all;
    s_sum_visible[lid] = light.sum_visible;
    s_position[lid] = vec4(g.position, g.surface ? 1.0 : 0.0);
    s_normal[lid] = g.normal;
    barrier();
    // What this sub-frame's pooled samples say: lit, hidden, or a penumbra (also where no
    // sample reached emitters whose unshadowed light is not zero).
    uint own = SHADOW_HIDDEN;
    if (g.surface) {
        vec3 all_sum, visible_sum;
        neighbourhood_sums(g, light, all_sum, visible_sum);
        // Per channel; a channel no sample reached takes what sub-frame 0 saw when that was
        // light or shadow (one ray may miss an emitter that four reach), else counts as hidden.
        float fallback = light.seen == SHADOW_LIT ? 1.0 : 0.0;
        vec3 visible = vec3(all_sum.r > 0.0 ? visible_sum.r / all_sum.r : fallback,
                            all_sum.g > 0.0 ? visible_sum.g / all_sum.g : fallback,
                            all_sum.b > 0.0 ? visible_sum.b / all_sum.b : fallback);
        e += light.unshadowed * visible;
        bool reached = false, any_lit = false, any_dark = false, partly_hidden = false;
        for (int c = 0; c < 3; ++c) {
            if (all_sum[c] > 0.0) {
                bool lit = visible[c] >= 1.0 - 1e-4, dark = visible[c] <= 1e-4;
                reached = true;
                any_lit = any_lit || lit;
                any_dark = any_dark || dark;
                partly_hidden = partly_hidden || (!lit && !dark);
            }
        }
        if (!reached && light.reused) {
            own = light.seen;  // no sample by design: sub-frame 0's answer stands
        } else if (!reached) {
            // Unknown where some light arrives unshadowed: every sample is kept.
            own = any(greaterThan(light.unshadowed, vec3(0.0))) ? SHADOW_PENUMBRA : SHADOW_HIDDEN;
        } else if (partly_hidden || (any_lit && any_dark)) {
            own = SHADOW_PENUMBRA;
        } else {
            own = any_lit ? SHADOW_LIT : SHADOW_HIDDEN;
        }
    }
    if (pc.adaptive_shadows != 0u) {
        // Uniform control flow: the condition is a push constant. A later sub-frame that sees
        // other than sub-frame 0 saw (light where there was shadow, or the reverse) has found a
        // shadow boundary too. A pixel whose own neighbourhood saw only light or only shadow
        // still lends its samples to a neighbour's penumbra: it is marked too, so that the
        // penumbra keeps all of its samples (dilation by the same 3×3 neighbourhood).
        bool mark = own == SHADOW_PENUMBRA || (pc.sub_frame > 0u && g.surface && own != light.seen);
        s_partial[lid] = mark ? 1u : 0u;
        barrier();
        // The surface test only toward marked neighbours (few: penumbrae and what changed).
        uint marked = 0u;
        for (int k = 0; k < 9; ++k) {
            uint j = neighbour_index(ivec2(k % 3 - 1, k / 3 - 1));
            if (j != 64u && s_partial[j] != 0u) {
                marked |= 1u << uint(k);
            }
        }
        for (int k = 0; k < 9 && marked != 0u && g.surface && !mark; ++k) {
            uint j = neighbour_index(ivec2(k % 3 - 1, k / 3 - 1));
            if ((marked & (1u << uint(k))) != 0u && same_surface(g, j)) {
                mark = true;
            }
        }
        frozen_class = mark ? SHADOW_PENUMBRA : own;
        if (inside) {
            uint index = pixel_index(pixel);
            if (pc.sub_frame == 0u) {
                shadows[SHADOW_WORDS * index + SHADOW_WORD_SEEN] = frozen_class;
            } else if (mark) {
                shadows[SHADOW_WORDS * index + SHADOW_WORD_SEEN] = SHADOW_PENUMBRA;
            }
        }
    }
#endif
    if (pc.adaptive_shadows != 0u && pc.sub_frame == 0u && inside) {
        // Read by later sub-frames only (other dispatches): no race with the neighbours' reads.
        // A pixel whose emitters are in its MIS (HAS_SPECULAR) has no class: none for reuse.
        bool classed = g.surface && light.closed_form;
        uint index = pixel_index(pixel);
        uint edge = classed && !neighbourhood_on_one_surface(g, pixel) ? SHADOW_EDGE : 0u;
        uint base = SHADOW_WORDS * index;
        shadows[base + SHADOW_WORD_FROZEN] = classed ? frozen_class | light.punctual_seen | edge : SHADOW_NONE;
        shadows[base + SHADOW_WORD_DISTANCE] = floatBitsToUint(length(frame.camera_position.xyz - g.position));
    }
    if (!inside) {
        return;
    }
    vec3 value = vec3(0.0);
    if (g.surface && !any(isnan(e)) && !any(isinf(e))) {
#ifdef HAS_SPECULAR
        value = e;
#else
        value = g.albedo * INV_PI * e;
#endif
    }
#ifdef DIRECT_COMPOSITE
    if (pc.composite != 0u) {
        if (!g.stopped) {
            composite_sample(pixel, pixel_index(pixel), g, value,
                             CompositeArgs(pc.jitter, 0u, pc.radiance_cache, 2u));
        }
    } else {
        imageStore(g_direct, pixel, vec4(value, 0.0));
    }
#else
    imageStore(g_direct, pixel, vec4(value, 0.0));
#endif
    // Most pixels of a later sub-frame trace no ray (adaptive shadows): they leave the shared
    // counter alone.
    if (rays_traced != 0u) {
        atomicAdd(ray_count, rays_traced);
    }
}
