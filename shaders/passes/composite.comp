// passes/composite.comp — Rust: crates/radcache-render/src/passes/composite.rs
// Composite of one sub-frame (docs/cache-frame.md §6.4 normalisation): on surfaces
// L = direct + albedo/π · Σw·Ẽ / Σw (0 where no record reaches the pixel; with HAS_SPECULAR the
// albedo is the base colour times the diffuse lobe's share), on the background the
// environment along the camera ray; added with weight 1 to the frame accumulator (a = sub-frames
// so far). The emission seen at the sub-frame's sample goes to a separate accumulator: the
// emission pass replaces it by a finely supersampled box filter where emitters have edges.
// A non-finite value is dropped and counted. With IC_AA_MOMENTS (adaptive anti-aliasing,
// docs/cache-frame.md §7.1) the squares of the sub-frame's radiance go to a second accumulator, from
// which the host estimates the sampling error of the mean (radcache_render::frame::aa).
// Splatting once per frame (pc.centre, docs/cache-frame.md §6.5): the sub-frame at the pixel
// centres stores each pixel's centre point and normal (pc.centre = 1); every later sub-frame
// (pc.centre = 2) interpolates its sample's cached light between the centres around it that
// match it (`cached_light_from_centres`), and counts the samples no centre matches.
// A pixel that per-pixel adaptive anti-aliasing has stopped (G-buffer position w = −1,
// docs/cache-frame.md §7.2) gets nothing: its sums and counts stay as they are, and its mean
// (sum / count) is over the sub-frames that shaded it.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/path.glsl"
#include "../common/gbuffer.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
#include "../common/dispatch.glsl"

layout(binding = B_COMPOSITE_SPLAT_SUM, rgba32f) readonly uniform image2D splat_sum;
layout(binding = B_COMPOSITE_ACCUM, std430) buffer Accum { vec4 accum[]; };
layout(binding = B_COMPOSITE_NONFINITE, std430) buffer Bad { uint nonfinite; uint unmatched; };
layout(binding = B_COMPOSITE_EMISSION_ACCUM, std430) buffer EmissionAccum { vec4 emission_accum[]; };
// Debug AOVs, two vec4 per pixel: indirect radiance (rgb) and Σw (a); records per pixel (x).
layout(binding = B_COMPOSITE_DEBUG_ACCUM, std430) buffer DebugAccum { vec4 debug_accum[]; };
layout(binding = B_COMPOSITE_SPLAT_COUNT, r32f) readonly uniform image2D splat_count;

// Per pixel: the centre sample's position (xyz; w = 1 on a surface) and normal (xyz; w = its
// footprint), written with pc.centre = 1 and read with pc.centre = 2.
layout(binding = B_COMPOSITE_CENTRE, std430) buffer Centre { vec4 centre[]; };

#ifdef IC_AA_MOMENTS
layout(binding = B_COMPOSITE_ACCUM_SQ, std430) buffer AccumSq { vec4 accum_sq[]; };
#endif

layout(push_constant) uniform Push { CompositePush pc; };

#ifdef HAS_RADIANCE_CACHE
// Σw·L_glossy (rgb), Σw (a): the glossy splat (passes/splat_glossy.frag; pc.glossy set).
layout(binding = B_COMPOSITE_GLOSSY_SUM, rgba32f) readonly uniform image2D glossy_sum;
#endif

// How far a pixel centre (position c, normal n) is from the sample g as a stand-in for its
// cached light, in footprints: the distance off the centre's tangent plane, the normals'
// disagreement (4 per unit of 1 − cos) and a quarter of the distance along the plane. A centre
// matches when it is within CENTRE_MATCH_PLANE footprints of the plane and its normal within
// acos(CENTRE_MATCH_COS) of the sample's (docs/cache-frame.md §6.5).
const float CENTRE_MATCH_PLANE = 1.0;
const float CENTRE_MATCH_COS = 0.9;
// How far (in pixels) a sample none of whose four nearest centres matches looks for one that
// does, and the cost added to a centre that does not match.
const int FAR_MATCH = 3;
const float NO_MATCH_COST = 1.0e3;

float centre_cost(GSample g, vec3 c, vec3 n, out bool matches) {
    vec3 d = g.position - c;
    float f = max(g.footprint, 1.0e-30);
    float plane = abs(dot(n, d));
    float along = length(d - n * dot(n, d));
    float cosine = dot(n, g.normal);
    matches = plane <= CENTRE_MATCH_PLANE * f && cosine >= CENTRE_MATCH_COS;
    return plane / f + 4.0 * (1.0 - cosine) + 0.25 * along / f;
}

// The cached light of one pixel's splat targets.
struct CachedLight {
    vec3 irradiance;  // Σw·Ẽ / Σw (0 where Σw = 0)
    vec3 glossy;      // the glossy splat's rgb / a, at least 0 (0 where it did not reach)
    float weight;     // Σw
    float count;      // records reaching the pixel (read for the debug AOVs only)
};

CachedLight cached_light_at(ivec2 q) {
    CachedLight c;
    vec4 s = imageLoad(splat_sum, q);
    c.irradiance = s.a > 0.0 ? s.rgb / s.a : vec3(0.0);
    c.weight = s.a;
    c.count = pc.debug != 0u ? imageLoad(splat_count, q).r : 0.0;
    c.glossy = vec3(0.0);
#ifdef HAS_RADIANCE_CACHE
    if (pc.glossy != 0u) {
        vec4 gs = imageLoad(glossy_sum, q);
        if (gs.a > 0.0) {
            // Clamped at 0 as a truncated SH product can dip below it.
            c.glossy = max(gs.rgb / gs.a, vec3(0.0));
        }
    }
#endif
    return c;
}

// Does the centre of pixel q match the sample g (and how far is it, `cost`)? False off the
// image and where the centre is not a surface.
bool centre_of(GSample g, ivec2 q, out float cost) {
    cost = 1.0e30;
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(frame.resolution.xy)))) {
        return false;
    }
    uint i = uint(q.y) * frame.resolution.x + uint(q.x);
    vec4 c = centre[2u * i];
    if (c.w < 0.5) {
        return false;
    }
    bool ok;
    cost = centre_cost(g, c.xyz, centre[2u * i + 1u].xyz, ok);
    return ok;
}

// The cached light of the sample g of `pixel` at `jitter` (pixels from its centre) from the
// splat made at the centres: interpolated bilinearly at the sample's position between the four
// nearest centres that match it and hold light (joint bilateral upsampling); where none does,
// that of the matching centre of least cost within FAR_MATCH pixels (a leaf seen through a gap
// in the foliage has its nearest centres on other leaves, its own a few pixels away); where
// none matches there either, that of the closest centre of the 3×3 neighbourhood (`matched`
// false), or none where no centre there is a surface.
CachedLight cached_light_from_centres(GSample g, ivec2 pixel, vec2 jitter, out bool matched) {
    vec2 pos = vec2(pixel) + jitter;
    ivec2 base = ivec2(floor(pos));
    vec2 f = pos - vec2(base);
    CachedLight sum = CachedLight(vec3(0.0), vec3(0.0), 0.0, 0.0);
    float total = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        float b = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        float cost;
        if (b <= 0.0 || !centre_of(g, base + o, cost)) {
            continue;
        }
        CachedLight c = cached_light_at(base + o);
        if (!(c.weight > 0.0)) {
            continue;
        }
        sum.irradiance += b * c.irradiance;
        sum.glossy += b * c.glossy;
        sum.weight += b * c.weight;
        sum.count += b * c.count;
        total += b;
    }
    matched = total > 0.0;
    if (matched) {
        float inv = 1.0 / total;
        return CachedLight(sum.irradiance * inv, sum.glossy * inv, sum.weight * inv,
                           sum.count * inv);
    }
    ivec2 best = ivec2(-1);
    float best_cost = 1.0e30;
    const int side = 2 * FAR_MATCH + 1;
    for (int k = 0; k < side * side; ++k) {
        ivec2 o = ivec2(k % side - FAR_MATCH, k / side - FAR_MATCH);
        float cost;
        // A match that holds light, of any cost, beats every other centre; those count only
        // within the 3×3 neighbourhood.
        bool ok = centre_of(g, pixel + o, cost) && imageLoad(splat_sum, pixel + o).a > 0.0;
        if (!ok && max(abs(o.x), abs(o.y)) > 1) {
            continue;
        }
        cost += ok ? 0.0 : NO_MATCH_COST;
        if (cost < best_cost) {
            best_cost = cost;
            best = pixel + o;
        }
    }
    matched = best_cost < NO_MATCH_COST;
    return best.x >= 0 ? cached_light_at(best) : sum;
}

void main() {
    ivec2 pixel = ivec2(interleaved_pixel());
    if (any(greaterThanEqual(pixel, ivec2(frame.resolution.xy)))) {
        return;
    }
    uint index = uint(pixel.y) * frame.resolution.x + uint(pixel.x);
    GSample g = gbuffer_load(pixel);
    if (g.stopped) {
        return;  // per-pixel adaptive anti-aliasing has stopped the pixel: no sample
    }
    vec3 l;
    vec3 emitted = vec3(0.0);
    if (pc.centre == 1u) {
        centre[2u * index] = vec4(g.position, g.surface ? 1.0 : 0.0);
        centre[2u * index + 1u] = vec4(g.normal, g.footprint);
    }
    if (g.surface) {
        // The cached light of this sample: its pixel's splat, or with pc.centre = 2 that made
        // at the centres around it (none matching: counted).
        CachedLight c;
        if (pc.centre == 2u) {
            bool matched;
            c = cached_light_from_centres(g, pixel, pc.jitter, matched);
            if (!matched) {
                atomicAdd(unmatched, 1u);
            }
        } else {
            c = cached_light_at(pixel);
        }
        vec3 e = c.irradiance;
#ifdef HAS_SPECULAR
        // The cached irradiance lights the diffuse lobe alone, weighted by its share for this
        // view direction (docs/materials.md §6); the direct pass adds the specular lobe's light.
        vec3 to_camera = normalize(frame.camera_position.xyz - g.position);
        float share = diffuse_share(gbuffer_material(g), dot(g.normal, to_camera));
        vec3 indirect = g.albedo * (share * INV_PI) * e;
#else
        vec3 indirect = g.albedo * INV_PI * e;
#endif
        // The specular lobe's indirect light from the radiance records, where the glossy splat
        // reached (its lobe rough enough: docs/radiance-caching.md §6.2; 0 without pc.glossy).
        indirect += c.glossy;
        l = imageLoad(g_direct, pixel).rgb + indirect;
        emitted = g.emission;
        if (pc.debug != 0u && !any(isnan(indirect)) && !any(isinf(indirect))) {
            debug_accum[2u * index] += vec4(indirect, c.weight);
            debug_accum[2u * index + 1u].x += c.count;
        }
    } else {
        Ray r = camera_ray(uvec2(pixel), vec2(0.5) + pc.jitter);
        l = environment_radiance(r.dir);
    }
    if (any(isnan(l)) || any(isinf(l))) {
        l = vec3(0.0);
        atomicAdd(nonfinite, 1u);
    }
    if (any(isnan(emitted)) || any(isinf(emitted))) {
        emitted = vec3(0.0);
        atomicAdd(nonfinite, 1u);
    }
    accum[index] += vec4(l, 1.0);
#ifdef IC_AA_MOMENTS
    accum_sq[index] += vec4(l * l, 0.0);
#endif
    emission_accum[index] += vec4(emitted, 1.0);
}
