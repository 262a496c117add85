// passes/emission.comp — Rust: crates/radcache-render/src/passes/emission.rs
// Box-filtered emission of the cache's frame. Emission is the brightest thing in most images, so
// a handful of jittered sub-frames leaves its edges visibly stepped (all pixels of a sub-frame
// share one jitter, so the errors along an edge are correlated and survive block averaging).
// Where a pixel or one of its 8 neighbours saw emission in any sub-frame, the pixel's emission is
// recomputed from COUNT camera rays over the pixel (the reference's box filter);
// elsewhere the sub-frames' mean is kept (it is 0 or exact). The result, times the sub-frame
// count, is added to the frame accumulator, whose mean is the image.
//
// The rays form a Hammersley (0,6,2)-net, digitally shifted per pixel: every 8×8 stratum and
// every 1/64-wide row and column of the pixel holds one ray, so an axis-aligned edge's coverage
// is exact to 1/64 (a plain 8×8 grid quantises it to 1/8: the Cornell box's light edge was 32 %
// too bright, 28 % of the default preset's own error), and the shift decorrelates neighbouring
// pixels along an edge.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/hash.glsl"
#include "../common/path.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
#include "../common/dispatch.glsl"

layout(binding = B_EMISSION_ACCUM, std430) buffer Accum { vec4 accum[]; };
layout(binding = B_EMISSION_EMISSION_ACCUM, std430) readonly buffer EmissionAccum { vec4 emission_accum[]; };
layout(binding = B_EMISSION_RAY_COUNT, std430) buffer RayCount { uint ray_count; };

const uint BITS = 6u;            // 64 rays per pixel
const uint COUNT = 1u << BITS;

void main() {
    ivec2 pixel = ivec2(interleaved_pixel());
    ivec2 size = ivec2(frame.resolution.xy);
    if (any(greaterThanEqual(pixel, size))) {
        return;
    }
    uint index = uint(pixel.y * size.x + pixel.x);
    vec4 own = emission_accum[index];
    // The sub-frames that shaded the pixel: the frame accumulator's count (the emission sums
    // hold rgb alone, passes/composite.comp).
    float subframes = max(accum[index].a, 1.0);
    bool near_emitter = false;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1);
            near_emitter = near_emitter || any(greaterThan(emission_accum[q.y * size.x + q.x].rgb, vec3(0.0)));
        }
    }
    vec3 e = own.rgb / subframes;
    if (near_emitter) {
        vec3 sum = vec3(0.0);
        uint shift = pcg_hash(index ^ pcg_hash(frame.resolution.w));
        uint shift_x = shift & (COUNT - 1u);
        uint shift_y = (shift >> 16) & (COUNT - 1u);
        for (uint k = 0u; k < COUNT; ++k) {
            uint row = bitfieldReverse(k) >> (32u - BITS);
            vec2 jitter = (vec2(k ^ shift_x, row ^ shift_y) + 0.5) / float(COUNT);
            Ray r = camera_ray(uvec2(pixel), jitter);
            rays_traced++;
            rayQueryEXT q;
            scene_trace(q, 0u, r.origin, r.dir, 1e30);
            if (rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
                Surface s = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                                       uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                                       rayQueryGetIntersectionBarycentricsEXT(q, true), r.dir);
                sum += material_emission(s.material, s.uv, s.front_face);
            }
        }
        e = sum / float(COUNT);
        atomicAdd(ray_count, rays_traced);
    }
    if (any(isnan(e)) || any(isinf(e))) {
        e = vec3(0.0);
    }
    accum[index].rgb += e * subframes;
}
