// passes/composite_sample.glsl — included by passes/composite.comp (Rust:
// crates/radcache-render/src/passes/composite.rs) and, with DIRECT_COMPOSITE, by
// passes/direct.comp (crates/radcache-render/src/passes/direct.rs): one sample of a sub-frame
// added to the frame's accumulators (`composite_sample`; composite.comp's header says what it
// adds). The includer defines COMPOSITE_B_* as its pass's binding numbers of the resources
// below, after including path.glsl and gbuffer.glsl.
#ifndef RADCACHE_COMPOSITE_SAMPLE_GLSL
#define RADCACHE_COMPOSITE_SAMPLE_GLSL

// What a sub-frame's composite does (CompositePush's fields).
struct CompositeArgs {
    vec2 jitter;  // the sub-frame's sample within its pixel, from the pixel's centre
    uint debug;   // 1: the debug accumulator too (read where the includer binds it)
    uint glossy;  // 1: the glossy splat's target is added (HAS_RADIANCE_CACHE)
    uint centre;  // 0: the pixel's own splat; 1: the same, and stores the centre samples;
                  // 2: the splat made at the stored centres (`cached_light_from_centres`)
};

layout(binding = COMPOSITE_B_SPLAT_SUM, rgba32f) readonly uniform image2D splat_sum;
layout(binding = COMPOSITE_B_ACCUM, std430) buffer Accum { vec4 accum[]; };
layout(binding = COMPOSITE_B_NONFINITE, std430) buffer Bad { uint nonfinite; uint unmatched; };
layout(binding = COMPOSITE_B_EMISSION_ACCUM, std430) buffer EmissionAccum { vec4 emission_accum[]; };
#ifdef COMPOSITE_B_DEBUG_ACCUM
// The debug AOVs (where the includer binds them: a.debug is read only then).
// Two vec4 per pixel: indirect radiance (rgb) and Σw (a); records per pixel (x).
layout(binding = COMPOSITE_B_DEBUG_ACCUM, std430) buffer DebugAccum { vec4 debug_accum[]; };
layout(binding = COMPOSITE_B_SPLAT_COUNT, r32f) readonly uniform image2D splat_count;
#endif

// Per pixel: the centre sample's position (xyz; w = 1 on a surface) and normal (xyz; w = its
// footprint), written with centre mode 1 and read with centre mode 2 (`CompositeArgs`).
layout(binding = COMPOSITE_B_CENTRE, std430) buffer Centre { vec4 centre[]; };


#ifdef HAS_RADIANCE_CACHE
// Σw·L_glossy (rgb), Σw (a): the glossy splat (passes/splat_glossy.frag; read where `CompositeArgs` says).
layout(binding = COMPOSITE_B_GLOSSY_SUM, rgba32f) readonly uniform image2D glossy_sum;
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

CachedLight cached_light_at(ivec2 q, CompositeArgs a) {
    CachedLight c;
    vec4 s = imageLoad(splat_sum, q);
    c.irradiance = s.a > 0.0 ? s.rgb / s.a : vec3(0.0);
    c.weight = s.a;
    c.count = 0.0;
#ifdef COMPOSITE_B_DEBUG_ACCUM
    if (a.debug != 0u) {
        c.count = imageLoad(splat_count, q).r;
    }
#endif
    c.glossy = vec3(0.0);
#ifdef HAS_RADIANCE_CACHE
    if (a.glossy != 0u) {
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

// The cached light of the sample g of `pixel` at `a.jitter` (pixels from its centre) from the
// splat made at the centres: interpolated bilinearly at the sample's position between the four
// nearest centres that match it and hold light (joint bilateral upsampling); where none does,
// that of the matching centre of least cost within FAR_MATCH pixels (a leaf seen through a gap
// in the foliage has its nearest centres on other leaves, its own a few pixels away); where
// none matches there either, that of the closest centre of the 3×3 neighbourhood (`matched`
// false), or none where no centre there is a surface.
CachedLight cached_light_from_centres(GSample g, ivec2 pixel, CompositeArgs a, out bool matched) {
    vec2 pos = vec2(pixel) + a.jitter;
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
        CachedLight c = cached_light_at(base + o, a);
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
    return best.x >= 0 ? cached_light_at(best, a) : sum;
}

// Adds sample `g` of `pixel` (linear index `index`; not one that per-pixel adaptive
// anti-aliasing has stopped), whose direct light toward the camera is `direct` (0 off
// surfaces), to the frame's accumulators.
void composite_sample(ivec2 pixel, uint index, GSample g, vec3 direct, CompositeArgs a) {
    vec3 l;
    vec3 emitted = vec3(0.0);
    if (a.centre == 1u) {
        centre[2u * index] = vec4(g.position, g.surface ? 1.0 : 0.0);
        centre[2u * index + 1u] = vec4(g.normal, g.footprint);
    }
    if (g.surface) {
        // The cached light of this sample: its pixel's splat, or with centre mode 2 that made
        // at the centres around it (none matching: counted).
        CachedLight c;
        if (a.centre == 2u) {
            bool matched;
            c = cached_light_from_centres(g, pixel, a, matched);
            if (!matched) {
                atomicAdd(unmatched, 1u);
            }
        } else {
            c = cached_light_at(pixel, a);
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
        // reached (its lobe rough enough: docs/radiance-caching.md §6.2; 0 without a.glossy).
        indirect += c.glossy;
        l = direct + indirect;
        emitted = g.emission;
#ifdef COMPOSITE_B_DEBUG_ACCUM
        if (a.debug != 0u && !any(isnan(indirect)) && !any(isinf(indirect))) {
            debug_accum[2u * index] += vec4(indirect, c.weight);
            debug_accum[2u * index + 1u].x += c.count;
        }
#endif
    } else {
        Ray r = camera_ray(uvec2(pixel), vec2(0.5) + a.jitter);
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
    // The squares follow the sums (one vec4 per pixel each).
    accum[frame.resolution.x * frame.resolution.y + index] += vec4(l * l, 0.0);
#endif
    // Most samples emit nothing: the emission sums change only where one does (their count is
    // the frame accumulator's, which counts the same samples).
    if (any(notEqual(emitted, vec3(0.0)))) {
        emission_accum[index].rgb += emitted;
    }
}

#endif
