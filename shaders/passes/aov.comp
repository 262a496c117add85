// passes/aov.comp — Rust: crates/radcache-render/src/passes/aov.rs
// Auxiliary output variables (AOVs) of the first hit: diffuse albedo, shading normal (world) and
// depth (distance from the camera along the ray, in scene units), each box-filtered over a 4×4
// grid of sub-pixel positions. A sub-sample that sees the background contributes zeros (albedo,
// normal) and is left out of the depth mean; a pixel with no hit at all has depth 0.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/scene.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
#include "../common/dispatch.glsl"

layout(binding = B_AOV_ALBEDO, std430) writeonly buffer Albedo { vec4 albedo_out[]; };
layout(binding = B_AOV_NORMAL, std430) writeonly buffer Normal { vec4 normal_out[]; };
layout(binding = B_AOV_DEPTH, std430) writeonly buffer Depth { float depth_out[]; };

const uint GRID = 4u;

void main() {
    uvec2 pixel = interleaved_pixel();
    if (any(greaterThanEqual(pixel, frame.resolution.xy))) {
        return;
    }
    vec2 res = vec2(frame.resolution.xy);
    vec3 albedo = vec3(0.0);
    vec3 normal = vec3(0.0);
    float depth = 0.0;
    uint hits = 0u;
    for (uint k = 0u; k < GRID * GRID; ++k) {
        vec2 jitter = (vec2(k % GRID, k / GRID) + 0.5) / float(GRID);
        vec2 ndc = (vec2(pixel) + jitter) / res * 2.0 - 1.0;
        vec4 near_p = frame.world_from_clip * vec4(ndc, 1.0, 1.0);
        vec3 origin = frame.camera_position.xyz;
        vec3 dir = normalize(near_p.xyz / near_p.w - origin);
        rayQueryEXT q;
        scene_trace(q, 0u, origin, dir, 1e30);
        if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) {
            continue;
        }
        Surface s = surface_at(uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)),
                               uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)),
                               rayQueryGetIntersectionBarycentricsEXT(q, true), dir);
        albedo += material_albedo(s.material, s.uv);
        normal += s.shading_normal;
        depth += rayQueryGetIntersectionTEXT(q, true);
        hits++;
    }
    uint index = pixel.y * frame.resolution.x + pixel.x;
    float inv = 1.0 / float(GRID * GRID);
    float len = length(normal);
    albedo_out[index] = vec4(albedo * inv, 0.0);
    normal_out[index] = vec4(len > 0.0 ? normal / len : vec3(0.0), 0.0);
    depth_out[index] = hits > 0u ? depth / float(hits) : 0.0;
}
