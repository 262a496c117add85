// passes/direct_specular.glsl — included by passes/direct.comp (Rust:
// crates/radcache-render/src/passes/direct.rs), with HAS_SPECULAR: the specular lobe's indirect
// light, its paths (direct_light.glsl's specular_path) pooled over the pixel's neighbourhood.
// Needs the pass's push constants (pc), neighbour_index (direct_neighbourhood.glsl), on_surface_of
// and sample_surface.
#ifndef RADCACHE_DIRECT_SPECULAR_GLSL
#define RADCACHE_DIRECT_SPECULAR_GLSL

// The specular lobe's paths pooled over the pixel's neighbourhood (docs/materials.md §10). Pixel
// q's paths, drawn from its own lobe (density pdf_q), estimate pixel p's integral too:
// f_p(l)·cos_p / pdf_q(l) · L(l) is unbiased for ∫ f_p cos L wherever pdf_q > 0, which the GGX
// visible normals are over the whole hemisphere. So p averages the estimates of the members of
// its 3×3 neighbourhood (within the 8×8 workgroup) with pc.specular_pool: its own and those of
// the pixels on its surface (`on_surface_of`), of its material, whose lobe is at least
// SPEC_POOL_WIDTH of its own wide and points within 2α of its own (the angle between the ideal
// reflections; a lobe of width α about the half vector is about 2α wide about the reflection):
// there the weights stay within a small factor of 1, while a mirror's neighbours, whose lobes
// miss each other, never pool. The radiance a neighbour's path brings back is that seen from
// its point, a pixel away (the bias: parallax and occlusion over one pixel), and a neighbour's
// direction below its own surface is not traced (its estimate counts it as 0, as p's does).
// The paths go SPEC_BATCH at a time through shared memory.
const uint SPEC_BATCH = 4u;
const float SPEC_POOL_WIDTH = 0.8;
shared vec4 s_spec_dir[SPEC_BATCH * 64u];  // a path's world direction (xyz), its density (w; 0: none)
shared vec3 s_spec_radiance[SPEC_BATCH * 64u];  // the radiance it brought back
shared vec4 s_spec_lobe[64];  // the ideal reflection (xyz), α (w; 0: the pixel takes no part)
shared vec4 s_spec_point[64];  // the sample's point (xyz), its material (w)
shared vec3 s_spec_normal[64];  // its shading normal

// The specular lobe's indirect light of this invocation's pixel (`tracing`: it traces paths,
// light.specular_paths); every invocation of the workgroup calls it (barriers).
vec3 specular_pooled(GSample g, uint index, bool tracing) {
    uint lid = gl_LocalInvocationIndex;
    Surface s = sample_surface(g);
    vec3 to_viewer = normalize(frame.camera_position.xyz - g.position);
    Bsdf f;
    float alpha = 0.0;
    vec3 mirror = vec3(0.0);
    if (tracing) {
        f = bsdf_at(s, gbuffer_material(g), to_viewer);
        alpha = alpha_from_roughness(f.m.roughness);
        mirror = reflect(-to_viewer, f.n);
    }
    s_spec_lobe[lid] = vec4(mirror, alpha);
    s_spec_point[lid] = vec4(g.position, float(g.material));
    s_spec_normal[lid] = g.normal;
    barrier();
    // A workgroup where no pixel traces (most of a frame) skips the batches and their barriers
    // (the same answer in every invocation: uniform control flow).
    bool any_tracing = false;
    for (uint j = 0u; j < 64u; ++j) {
        any_tracing = any_tracing || s_spec_lobe[j].w > 0.0;
    }
    if (!any_tracing) {
        return vec3(0.0);
    }
    // The members (bit k for offset k of the 3×3 block, own included) and their count.
    uint members = 0u;
    uint count = 0u;
    float cos_width = cos(min(2.0 * alpha, 1.5));
    for (int k = 0; k < 9 && tracing; ++k) {
        uint j = neighbour_index(ivec2(k % 3 - 1, k / 3 - 1));
        if (j == 64u) {
            continue;
        }
        vec4 lobe = s_spec_lobe[j];
        bool member = j == lid ||
                      (pc.specular_pool != 0u && lobe.w >= SPEC_POOL_WIDTH * alpha && s_spec_point[j].w == float(g.material) &&
                       dot(lobe.xyz, mirror) >= cos_width &&
                       on_surface_of(g, s_spec_point[j].xyz, s_spec_normal[j]));
        if (member) {
            members |= 1u << uint(k);
            count++;
        }
    }
    vec3 origin = offset_ray_origin(s.position, s.geometric_normal);
    uint paths = max(pc.specular_paths, 1u);
    vec3 sum = vec3(0.0);
    for (uint first = 0u; first < paths; first += SPEC_BATCH) {
        for (uint b = 0u; b < SPEC_BATCH; ++b) {
            uint k = first + b;
            vec4 dir = vec4(0.0);
            vec3 radiance = vec3(0.0);
            if (tracing && k < paths) {
                Rng rng = rng_init(index, pc.sub_frame * paths + k, pc.seed ^ 0x5bd1e995u);
                specular_path(s, f, origin, rng, dir, radiance);
                if (any(isnan(radiance)) || any(isinf(radiance))) {
                    dir = vec4(0.0);
                }
            }
            s_spec_dir[SPEC_BATCH * lid + b] = dir;
            s_spec_radiance[SPEC_BATCH * lid + b] = radiance;
        }
        barrier();
        for (int k = 0; k < 9 && tracing; ++k) {
            if ((members & (1u << uint(k))) == 0u) {
                continue;
            }
            uint j = neighbour_index(ivec2(k % 3 - 1, k / 3 - 1));
            for (uint b = 0u; b < SPEC_BATCH; ++b) {
                vec4 dir = s_spec_dir[SPEC_BATCH * j + b];
                if (!(dir.w > 0.0) || dot(dir.xyz, s.geometric_normal) <= 0.0) {
                    continue;
                }
                vec3 l = bsdf_local(f, dir.xyz);
                if (l.z < COS_MIN) {
                    continue;
                }
                vec3 c = brdf_eval_lobes(f.m, f.v, l).specular * (l.z / dir.w) *
                         s_spec_radiance[SPEC_BATCH * j + b];
                if (!any(isnan(c)) && !any(isinf(c))) {
                    sum += c;
                }
            }
        }
        barrier();
    }
    return tracing ? sum / float(paths * max(count, 1u)) : vec3(0.0);
}

#endif
