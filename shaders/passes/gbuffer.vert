// passes/gbuffer.vert — Rust: crates/radcache-render/src/passes/gbuffer.rs
// G-buffer rasterization, vertex stage: vertex pulling from the scene buffers, one draw per TLAS
// instance (push constant), the instance transform, the frame's projection and a sub-pixel
// jitter (in pixels, (0, 0) = pixel centre) for anti-aliasing by jittered sub-frames.
//
// The jitter is where the pixel's sample lies: the G-buffer at pixel p describes the camera ray
// `camera_ray(p, 0.5 + jitter)` of path.glsl (the composite shades the background along that ray).
// The rasterizer samples at pixel centres, so the image is moved by −jitter: the point that was
// at centre + jitter lands on the centre.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../common/scene.glsl"
#include "gbuffer_push.glsl"

layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out TexCoords v_uv;  // both sets with HAS_TEXCOORD1
layout(location = 3) flat out uint v_triangle;
#ifdef HAS_NORMAL_MAPS
// World tangent (xyz) and handedness (the provoking, first, corner's: surface_at uses it too).
layout(location = 4) out vec3 v_tangent;
layout(location = 5) flat out float v_tangent_w;
#endif
// The triangle's unit geometric normal (world space, flipped by a mirroring instance as glTF's
// winding rule says) and its material: the same at its three corners, so a flat varying hands
// them to every fragment (read per fragment, the corners cost three gathers each).
layout(location = 6) flat out vec3 v_geometric;
layout(location = 7) flat out uint v_material;

void main() {
    GpuInstance inst = instances[pc.instance];
    uint index = indices[inst.mesh.z + uint(gl_VertexIndex)] + inst.mesh.y;
    GpuVertex v = vertices[index];
    vec4 world = inst.world_from_object * vec4(v.position_u.xyz, 1.0);
    v_position = world.xyz;
    v_normal = (inst.normal_to_world * vec4(v.normal_v.xyz, 0.0)).xyz;
    v_uv = vertex_texcoords(v, index);
    v_triangle = uint(gl_VertexIndex) / 3u;
    uint first = inst.mesh.z + 3u * v_triangle;
    vec3 p0 = vertices[indices[first] + inst.mesh.y].position_u.xyz;
    vec3 p1 = vertices[indices[first + 1u] + inst.mesh.y].position_u.xyz;
    vec3 p2 = vertices[indices[first + 2u] + inst.mesh.y].position_u.xyz;
    vec3 e1 = (inst.world_from_object * vec4(p1 - p0, 0.0)).xyz;
    vec3 e2 = (inst.world_from_object * vec4(p2 - p0, 0.0)).xyz;
    vec3 ng = cross(e1, e2);
    float len = length(ng);
    ng = len > 0.0 ? ng / len : vec3(0.0, 0.0, 1.0);
    v_geometric = inst.normal_to_world[3][3] < 0.0 ? -ng : ng;
    v_material = tri_materials[inst.mesh.w + v_triangle];
#ifdef HAS_NORMAL_MAPS
    vec4 t = world_tangent(inst, tangents[index]);
    v_tangent = t.xyz;
    v_tangent_w = t.w;
#endif
    vec4 clip = frame.clip_from_world * world;
    clip.xy -= 2.0 * pc.jitter / vec2(frame.resolution.xy) * clip.w;
    gl_Position = clip;
}
