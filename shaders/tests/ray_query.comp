// tests/ray_query.comp — Rust: tests/tests/ray_query.rs and xtask/src/bench/rays.rs
// Traces one ray per invocation against the TLAS (closest hit) and records what was hit.
// Used by the foundation test (against a CPU ray-triangle reference) and by `cargo xtask bench
// rays` (MODE_BENCH: only the distance is kept, summed per ray to stop dead-code elimination).
#version 460
#extension GL_EXT_ray_query : require
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

struct Ray {
    vec4 origin_tmin;
    vec4 dir_tmax;
};

struct Hit {
    float t;
    int primitive;
    int instance;
    int custom_index;
    vec2 barycentrics;
    uint hit;
    uint pad;
};

layout(binding = 0) uniform accelerationStructureEXT tlas;
layout(binding = 1, std430) readonly buffer Rays { Ray rays[]; };
layout(binding = 2, std430) writeonly buffer Hits { Hit hits[]; };

layout(push_constant) uniform Push {
    uint count;
    uint flags;
    uint row_width;
    uint pad;
} pc;

void main() {
    uint i = gl_GlobalInvocationID.y * pc.row_width + gl_GlobalInvocationID.x;
    if (i >= pc.count) {
        return;
    }
    Ray r = rays[i];
    rayQueryEXT q;
    rayQueryInitializeEXT(q, tlas, gl_RayFlagsOpaqueEXT | pc.flags, 0xFF, r.origin_tmin.xyz,
                          r.origin_tmin.w, r.dir_tmax.xyz, r.dir_tmax.w);
    while (rayQueryProceedEXT(q)) {
    }
    Hit h = Hit(-1.0, -1, -1, -1, vec2(0.0), 0u, 0u);
    if (rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        h.t = rayQueryGetIntersectionTEXT(q, true);
        h.primitive = rayQueryGetIntersectionPrimitiveIndexEXT(q, true);
        h.instance = rayQueryGetIntersectionInstanceIdEXT(q, true);
        h.custom_index = rayQueryGetIntersectionInstanceCustomIndexEXT(q, true);
        h.barycentrics = rayQueryGetIntersectionBarycentricsEXT(q, true);
        h.hit = 1u;
    }
    hits[i] = h;
}
