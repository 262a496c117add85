// passes/composite.comp — Rust: crates/radcache-render/src/passes/composite.rs
// Composite of one sub-frame (docs/cache-frame.md §6.4 normalisation): on surfaces
// L = direct + albedo/π · Σw·Ẽ / Σw (0 where no record reaches the pixel; with HAS_SPECULAR the
// albedo is the base colour times the diffuse lobe's share), on the background the
// environment along the camera ray; added with weight 1 to the frame accumulator (a = sub-frames
// so far). The emission seen at the sub-frame's sample goes to a separate accumulator (rgb
// sums; the frame accumulator's a counts its samples too): the emission pass replaces it by a
// finely supersampled box filter where emitters have edges.
// A non-finite value is dropped and counted. With IC_AA_MOMENTS (adaptive anti-aliasing,
// docs/cache-frame.md §7.1) the squares of the sub-frame's radiance go to a second accumulator, from
// which the host estimates the sampling error of the mean (radcache_render::frame::aa).
// Splatting once per frame (pc.centre, docs/cache-frame.md §6.5): the sub-frame at the pixel
// centres stores each pixel's centre point and normal (pc.centre = 1); every later sub-frame
// (pc.centre = 2) interpolates its sample's cached light between the centres around it that
// match it (`cached_light_from_centres`), and counts the samples no centre matches (outside a
// frame with the debug AOVs the direct pass does that itself, passes/direct.comp).
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

#define COMPOSITE_B_SPLAT_SUM B_COMPOSITE_SPLAT_SUM
#define COMPOSITE_B_ACCUM B_COMPOSITE_ACCUM
#define COMPOSITE_B_NONFINITE B_COMPOSITE_NONFINITE
#define COMPOSITE_B_EMISSION_ACCUM B_COMPOSITE_EMISSION_ACCUM
#define COMPOSITE_B_DEBUG_ACCUM B_COMPOSITE_DEBUG_ACCUM
#define COMPOSITE_B_SPLAT_COUNT B_COMPOSITE_SPLAT_COUNT
#define COMPOSITE_B_CENTRE B_COMPOSITE_CENTRE
#define COMPOSITE_B_GLOSSY_SUM B_COMPOSITE_GLOSSY_SUM
#include "composite_sample.glsl"

layout(push_constant) uniform Push { CompositePush pc; };

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
    vec3 direct = g.surface ? imageLoad(g_direct, pixel).rgb : vec3(0.0);
    composite_sample(pixel, index, g, direct,
                     CompositeArgs(pc.jitter, pc.debug, pc.glossy, pc.centre));
}
