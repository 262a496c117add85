// passes/path_trace.comp — Rust: crates/radcache-render/src/passes/path_trace.rs
// Reference path tracer: unbiased, progressive, box-filtered.
//
// Per pixel and sample: a camera ray through a uniformly jittered point of the pixel (box filter),
// continued by `trace_path` (common/path.glsl: NEE + MIS, Russian roulette).
//
// Samples [sample_start, sample_start + sample_count) are added to a per-pixel Kahan-compensated
// float sum (`precise`, so the compiler cannot reassociate it), which stays accurate over 1e5 spp.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/path.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
#include "../common/dispatch.glsl"

layout(binding = B_PATH_TRACE_ACCUM, std430) buffer Accum {
    vec4 accum[];  // per pixel: Kahan sum (rgb), sample count (a)
};
layout(binding = B_PATH_TRACE_COMPENSATION, std430) buffer Compensation {
    vec4 compensation[];  // per pixel: Kahan compensation (rgb)
};

layout(binding = B_PATH_TRACE_RAY_COUNT, std430) buffer RayCount {
    uint ray_count;  // ray queries issued by this dispatch (cleared by the host per submission)
};

layout(push_constant) uniform Push { PathTracePush pc; };

void main() {
    uvec2 pixel = interleaved_pixel();
    if (any(greaterThanEqual(pixel, frame.resolution.xy))) {
        return;
    }
    uint index = pixel.y * frame.resolution.x + pixel.x;
    precise vec3 sum = accum[index].rgb;
    precise vec3 c = compensation[index].rgb;
    for (uint k = 0u; k < pc.sample_count; ++k) {
        uint sample_index = pc.sample_start + k;
        Rng rng = rng_init(index, sample_index, frame.resolution.w);
        Ray ray = camera_ray(pixel, rng_next2(rng));
        precise vec3 y = trace_path(ray, rng) - c;
        precise vec3 t = sum + y;
        c = (t - sum) - y;
        sum = t;
    }
    accum[index] = vec4(sum, accum[index].a + float(pc.sample_count));
    compensation[index] = vec4(c, 0.0);
    atomicAdd(ray_count, rays_traced);
}
