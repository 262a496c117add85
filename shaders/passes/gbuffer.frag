// passes/gbuffer.frag — Rust: crates/radcache-render/src/passes/gbuffer.rs
// G-buffer rasterization, fragment stage: the five attachments of shaders/common/gbuffer.glsl.
// The geometric normal and the material are the triangle's, from the vertex stage (flat
// varyings: its world-space corners, flipped by mirroring instances as glTF's winding rule says);
// the normal map (HAS_NORMAL_MAPS) bends the shading normal as
// surface_at does; both normals are turned toward the camera, and the front
// face (for the emission rule) is the side the camera sees. The pixel footprint is the pinhole
// `pixel_footprint` of ircache_math.glsl (its cosine clamp keeps grazing surfaces bounded, where
// screen-space derivatives would grow without limit). The samples that rasterization's edge
// snapping may have let through the seam of a zero-thickness wall are traced again by the
// repair (gbuffer.comp with GBUFFER_REPAIR). With HAS_ALPHA a fragment where its material is
// missing (alpha_keep: MASK below the cutoff, BLEND by its stochastic coverage) is discarded,
// and the repair's ray skips such points with the same test.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/scene.glsl"
#include "../common/ircache_math.glsl"
#include "../common/gbuffer_pack.glsl"
#include "gbuffer_push.glsl"

layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in TexCoords v_uv;
layout(location = 3) flat in uint v_triangle;
#ifdef HAS_NORMAL_MAPS
layout(location = 4) in vec3 v_tangent;
layout(location = 5) flat in float v_tangent_w;
#endif
layout(location = 6) flat in vec3 v_geometric;
layout(location = 7) flat in uint v_material;

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_geometric;
layout(location = 3) out vec4 o_albedo;
layout(location = 4) out vec4 o_emission;

#ifdef HAS_ALPHA
// The seed of this pixel's BLEND tests in this sub-frame: the pixel, the sub-frame's jitter, the
// frame's seed and number. Every fragment of the pixel and the repair's ray (gbuffer.comp) draw
// the same number for the same triangle, so a blended surface the rasterizer dropped is dropped
// by the ray too.
uint gbuffer_alpha_seed() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = pcg_hash(frame.resolution.w ^ pcg_hash(frame.resolution.z));
    h = pcg_hash(h ^ floatBitsToUint(pc.jitter.x));
    h = pcg_hash(h ^ floatBitsToUint(pc.jitter.y));
    h = pcg_hash(h ^ p.x);
    return pcg_hash(h ^ p.y);
}
#endif

void main() {
    uint material = v_material;
#ifdef HAS_ALPHA
    if (!alpha_keep(material, v_uv, pc.instance, v_triangle, gbuffer_alpha_seed())) {
        discard;
    }
#endif
    vec3 ng = v_geometric;
    vec3 position = v_position;
    vec3 to_camera = frame.camera_position.xyz - position;
    bool front = dot(ng, to_camera) >= 0.0;
    if (!front) {
        ng = -ng;
    }
    vec3 ns = v_normal;
    float ns_len = length(ns);
    ns = (ns_len > 0.0 && !isnan(ns_len)) ? ns / ns_len : ng;
    TexCoords uv = v_uv;
#ifdef HAS_NORMAL_MAPS
    // On the outward normals, as surface_at does; the flip below turns the result with them.
    ns = material_shading_normal(material, uv, vec4(v_tangent, v_tangent_w), ns,
                                 front ? ng : -ng);
#endif
    if (!front) {
        ns = -ns;
    }
    if (dot(ns, ng) <= 0.0) {
        ns = ng;
    }
    float view_depth = 1.0 / gl_FragCoord.w;
    uint instance = pc.instance;
    // View depth = clip w = 1 / gl_FragCoord.w. The y row of
    // clip_from_world is the projection's ±1/tan(fov_y/2) times a row of the view rotation (a unit
    // vector).
    vec3 row_y = vec3(frame.clip_from_world[0][1], frame.clip_from_world[1][1],
                      frame.clip_from_world[2][1]);
    float dist = length(to_camera);
    float cos_view = dist > 0.0 ? dot(ng, to_camera) / dist : 1.0;
    float footprint = pixel_footprint(view_depth, 1.0 / length(row_y),
                                      float(frame.resolution.y), cos_view);
    // The stored point moves a hair toward the camera, into the free space the camera ray came
    // through: a sample exactly on an edge of a closed object seen from inside (the stiff suite's
    // `inside_object`, whose image diagonals run along the cube's edges) lies on the plane of the
    // other face too, and rays from it (offset only along its own face's normal) slipped through
    // that face at t = 0 and saw the lit room. Relative to the distance and to the position's
    // magnitude, so it survives f32 rounding at any scale; never more than half the distance.
    float step_len = min(max(1e-5 * dist, 1e-6 * max(abs(position.x), max(abs(position.y),
                                                                        abs(position.z)))),
                         0.5 * dist);
    position += dist > 0.0 ? to_camera * (step_len / dist) : vec3(0.0);
    o_position = vec4(position, 1.0);
    o_normal = vec4(ns, footprint);
    o_geometric = vec4(ng, float(material));
#ifdef HAS_SPECULAR
    Material m = material_at(material, uv);
    o_albedo = vec4(m.base_colour, float(instance));
    o_emission = vec4(material_emission(material, uv, front),
                      gbuffer_pack_metallic_roughness(m.metallic, m.roughness));
#else
    o_albedo = vec4(material_albedo(material, uv), float(instance));
    o_emission = vec4(material_emission(material, uv, front), 0.0);
#endif
}
