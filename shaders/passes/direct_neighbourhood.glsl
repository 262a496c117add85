// passes/direct_neighbourhood.glsl — included by passes/direct.comp (Rust:
// crates/radcache-render/src/passes/direct.rs): the pass's 3×3 neighbourhoods within its 8×8
// workgroup. `neighbour_index` for every neighbourhood; with HAS_SPECULAR the pooled specular
// paths (direct_specular.glsl); with HAS_ANALYTIC_EMITTERS the ratio estimator's shared sample
// sums (docs/cache-frame.md §8.2). Needs PixelLight, on_surface_of and sample_surface.
#ifndef RADCACHE_DIRECT_NEIGHBOURHOOD_GLSL
#define RADCACHE_DIRECT_NEIGHBOURHOOD_GLSL

// The workgroup index of the neighbour at `offset` from this invocation, or 64 outside it.
uint neighbour_index(ivec2 offset) {
    ivec2 q = ivec2(gl_LocalInvocationID.xy) + offset;
    if (any(lessThan(q, ivec2(0))) || any(greaterThan(q, ivec2(7)))) {
        return 64u;
    }
    return uint(q.y * 8 + q.x);
}

#ifdef HAS_SPECULAR
#include "direct_specular.glsl"
#endif

#ifdef HAS_ANALYTIC_EMITTERS
// The workgroup's pixels' sample sums, positions and normals, for the ratio's neighbourhood.
shared vec3 s_sum_all[64];
shared vec3 s_sum_visible[64];
shared vec4 s_position[64];  // w: 1 for a surface pixel
shared vec3 s_normal[64];
shared uint s_partial[64];  // 1 where the pixel is marked a penumbra (before dilation)

// Whether workgroup pixel `j` lies on the same surface as `g` (`on_surface_of`).
bool same_surface(GSample g, uint j) {
    return s_position[j].w != 0.0 && on_surface_of(g, s_position[j].xyz, s_normal[j]);
}

// The pixel's and its same-surface 3×3 neighbours' sample sums (within its 8×8 workgroup): the
// visible fraction of the emitters' light at the pixel is Σ sum_visible / Σ sum_all over them
// (docs/cache-frame.md §8.2).
// A neighbour without samples adds nothing, so the surface test is made only where one has
// some: after sub-frame 0 most of a frame casts no emitter ray (the shadow reuse), and there the
// loop is skipped.
void neighbourhood_sums(GSample g, PixelLight light, out vec3 all_sum, out vec3 visible) {
    all_sum = light.sum_all;
    visible = light.sum_visible;
    uint with_samples = 0u;
    for (int k = 0; k < 9; ++k) {
        uint j = neighbour_index(ivec2(k % 3 - 1, k / 3 - 1));
        if (k != 4 && j != 64u && any(greaterThan(s_sum_all[j], vec3(0.0)))) {
            with_samples |= 1u << uint(k);
        }
    }
    if (with_samples == 0u) {
        return;
    }
    for (int k = 0; k < 9; ++k) {
        uint j = neighbour_index(ivec2(k % 3 - 1, k / 3 - 1));
        if ((with_samples & (1u << uint(k))) == 0u || !same_surface(g, j)) {
            continue;
        }
        all_sum += s_sum_all[j];
        visible += s_sum_visible[j];
    }
}
#endif

#endif
