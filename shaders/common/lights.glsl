// common/lights.glsl — Rust: crates/radcache-render/src/scene/lights.rs
// Light sources: emissive triangles (power-proportional alias table, uniform area sampling),
// punctual lights (KHR_lights_punctual units), and the environment (constant, or an
// equirectangular map sampled texel-proportionally to luminance × solid angle).
//
// What is compiled in follows the scene plan through defines: HAS_EMITTERS, HAS_LIGHTS,
// HAS_ENV_CONSTANT, HAS_ENV_MAP. A scene without punctual lights has no punctual code at all.
#ifndef RADCACHE_LIGHTS_GLSL
#define RADCACHE_LIGHTS_GLSL

#include "scene.glsl"

// Equirectangular convention (+Y up): u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi, v = 0 at
// the zenith (top row). Returns the texel index of direction d in a W × H map.
uint env_texel_index(vec3 d, uint w, uint h) {
    float u = 0.5 + atan(d.x, -d.z) * (0.5 * INV_PI);
    float v = acos(clamp(d.y, -1.0, 1.0)) * INV_PI;
    uint x = min(uint(max(u, 0.0) * float(w)), w - 1u);
    uint y = min(uint(max(v, 0.0) * float(h)), h - 1u);
    return y * w + x;
}

// Solid angle of texel row y of a W × H equirectangular map.
float env_texel_solid_angle(uint y, uint w, uint h) {
    float c0 = cos(PI * float(y) / float(h));
    float c1 = cos(PI * float(y + 1u) / float(h));
    return (2.0 * PI / float(w)) * max(c0 - c1, 0.0);
}

// Radiance arriving from direction d (world, unit) out of the environment map alone (0 without
// one).
vec3 environment_map_radiance(vec3 d) {
#ifdef HAS_ENV_MAP
    uint w = frame.counts.w;
    uint h = uint(frame.totals.y);
    return env_texels[env_texel_index(d, w, h)].rgb * frame.environment.w;
#else
    return vec3(0.0);
#endif
}

// Radiance arriving from direction d (world, unit) out of the environment: its constant part
// plus its map.
vec3 environment_radiance(vec3 d) {
    vec3 l = environment_map_radiance(d);
#ifdef HAS_ENV_CONSTANT
    l += frame.environment.rgb;
#endif
    return l;
}

// Picks an entry of an alias table of n entries with one uniform number; returns its index.
uint alias_pick(float u, uint n, float prob, uint alias_index, uint i) {
    float scaled = u * float(n);
    float frac = scaled - float(i);
    return frac < prob ? i : alias_index;
}

#ifdef HAS_ENV_MAP
// Solid-angle pdf of sampling direction d with `sample_environment`.
float environment_pdf(vec3 d) {
    uint w = frame.counts.w;
    uint h = uint(frame.totals.y);
    uint i = env_texel_index(d, w, h);
    float omega = env_texel_solid_angle(i / w, w, h);
    return omega > 0.0 ? env_alias[i].pmf / omega : 0.0;
}

// Samples a direction of the environment map: a texel by the alias table, then uniformly within
// the texel's solid angle. Returns false if the map is black.
bool sample_environment(vec3 u, out vec3 dir, out vec3 radiance, out float pdf) {
    uint w = frame.counts.w;
    uint h = uint(frame.totals.y);
    uint n = w * h;
    uint i = min(uint(u.x * float(n)), n - 1u);
    GpuAlias a = env_alias[i];
    uint t = alias_pick(u.x, n, a.prob, a.alias, i);
    uint x = t % w;
    uint y = t / w;
    float phi = 2.0 * PI * ((float(x) + u.y) / float(w) - 0.5);
    float c0 = cos(PI * float(y) / float(h));
    float c1 = cos(PI * float(y + 1u) / float(h));
    float cos_theta = mix(c0, c1, u.z);
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    dir = vec3(sin_theta * sin(phi), cos_theta, -sin_theta * cos(phi));
    float omega = env_texel_solid_angle(y, w, h);
    pdf = omega > 0.0 ? env_alias[t].pmf / omega : 0.0;
    radiance = env_texels[t].rgb * frame.environment.w;
    return pdf > 0.0;
}
#endif

#ifdef HAS_EMITTERS
// Area pdf (per m²) of sampling a point on an emissive triangle with radiance factor `emission`
// and sidedness `two_sided`: the table is power-proportional, power = Y(Le)·A·π·sides, and the
// point is uniform on the triangle, so pdf_area = Y(Le)·π·sides / total power.
float emitter_area_pdf(float mean_luminance, bool two_sided) {
    float total = frame.totals.x;
    return total > 0.0 ? mean_luminance * PI * (two_sided ? 2.0 : 1.0) / total : 0.0;
}

// The solid-angle pdf with which emitter sampling picks the point `t` along `dir` of an
// emissive triangle of `material` with geometric normal `n` (the area pdf × t² / |cos|): what a
// BSDF-sampled ray that hits an emitter weighs against in MIS.
float emitter_hit_pdf(uint material, vec3 n, vec3 dir, float t) {
    GpuMaterial m = materials[material];
    float cos_l = abs(dot(n, dir));
    return emitter_area_pdf(m.params.z, m.emission.w != 0.0) * t * t / max(cos_l, 1e-8);
}

// The texture coordinates at barycentrics b (of corners 1 and 2) of emitter e: TEXCOORD_0, and
// TEXCOORD_1 with HAS_TEXCOORD1; the material's references map them as at a ray hit.
TexCoords emitter_texcoords(GpuEmitter e, vec2 b) {
    float w0 = 1.0 - b.x - b.y;
    vec2 uv0 = w0 * e.uvs.xy + b.x * e.uvs.zw + b.y * e.uv2_material.xy;
#ifdef HAS_TEXCOORD1
    return vec4(uv0, w0 * e.uvs1.xy + b.x * e.uvs1.zw + b.y * e.uv1_2.xy);
#else
    return uv0;
#endif
}

// Samples a point on an emissive triangle as seen from p. On success: unit direction to the
// point, its distance, the radiance it sends toward p, and the solid-angle pdf.
bool sample_emitter(vec3 p, vec3 u, out vec3 dir, out float dist, out vec3 radiance, out float pdf) {
    uint n = frame.counts.x;
    if (n == 0u) {
        return false;
    }
    uint i = min(uint(u.x * float(n)), n - 1u);
    GpuAlias a = emitter_alias[i];
    uint t = alias_pick(u.x, n, a.prob, a.alias, i);
    GpuEmitter e = emitters[t];
    vec2 b = sample_triangle(u.yz);
    vec3 q = (1.0 - b.x - b.y) * e.p0.xyz + b.x * e.p1.xyz + b.y * e.p2.xyz;
    vec3 ng = cross(e.p1.xyz - e.p0.xyz, e.p2.xyz - e.p0.xyz);
    float area2 = length(ng);
    vec3 to = q - p;
    float d2 = dot(to, to);
    if (area2 <= 0.0 || d2 <= 0.0) {
        return false;
    }
    ng /= area2;
    dist = sqrt(d2);
    dir = to / dist;
    float cos_l = -dot(ng, dir);
    bool two_sided = e.radiance.w != 0.0;
    if (cos_l <= 0.0 && !two_sided) {
        return false;
    }
    TexCoords uv = emitter_texcoords(e, b);
    radiance = material_emission(uint(e.uv2_material.z), uv, cos_l > 0.0);
#ifdef HAS_ALPHA
    // Where an alpha-tested emitter is missing it emits nothing: its mean coverage there (MASK 0
    // or 1, BLEND alpha, the mean of what BSDF-sampled hits find).
    radiance *= material_coverage(uint(e.uv2_material.z), uv);
#endif
    float pdf_area = emitter_alias[t].pmf / (0.5 * area2);
    pdf = pdf_area * d2 / max(abs(cos_l), 1e-8);
    return pdf > 0.0 && abs(cos_l) > 0.0;
}
#endif

#ifdef HAS_LIGHTS
// Irradiance-producing radiance of punctual light `l` at p: direction to the light, distance, and
// the incident "radiance × solid angle" (W/m² per unit cos) as the glTF extension defines it:
// point/spot: I / d² × range window × spot falloff; directional: E = intensity.
vec3 punctual_incident(GpuLight l, vec3 p, out vec3 dir, out float dist) {
    uint kind = uint(l.position.w);
    if (kind == 2u) {
        dir = -l.direction.xyz;
        dist = 1e30;
        return l.intensity.rgb;
    }
    vec3 to = l.position.xyz - p;
    float d2 = max(dot(to, to), 1e-12);
    dist = sqrt(d2);
    dir = to / dist;
    vec3 e = l.intensity.rgb / d2;
    float range = l.direction.w;
    if (range > 0.0) {
        // The extension's recommended window: clamp(1 − (d/range)⁴, 0, 1) / d² (the 1/d² above).
        float r4 = (d2 / (range * range)) * (d2 / (range * range));
        float win = clamp(1.0 - r4, 0.0, 1.0);
        e *= win;
    }
    if (kind == 1u) {
        float cd = dot(l.direction.xyz, -dir);
        float att = clamp(cd * l.spot.x + l.spot.y, 0.0, 1.0);
        e *= att * att;
    }
    return e;
}
#endif

// Ray queries this invocation has issued (shadow rays here; passes add their own), for the
// rays-per-pass statistics.
uint rays_traced = 0u;

// True when nothing blocks the segment from `origin` along `dir` up to `tmax`.
bool unoccluded(vec3 origin, vec3 dir, float tmax) {
    rays_traced++;
    rayQueryEXT q;
    scene_trace(q, gl_RayFlagsTerminateOnFirstHitEXT, origin, dir, tmax);
    return rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionNoneEXT;
}

// Whether the point at `dist` along `dir` from surface point `p` is visible from `origin`, the
// ray origin offset off that surface (offset_ray_origin). The shadow ray runs from `origin`
// toward that point and stops 1e-4 of its length short: measured from `p` instead, the offset
// (up to scene scale / 65536 near the world origin) could carry the ray past a light that is
// close in relative terms, which then shadowed itself. `dist` ≥ 1e29 (a directional light) is a
// ray to infinity along `dir`.
bool unoccluded_to(vec3 origin, vec3 p, vec3 dir, float dist) {
    if (dist >= 1e29) {
        return unoccluded(origin, dir, 1e30);
    }
    vec3 d = p + dir * dist - origin;
    float len = length(d);
    if (!(len > 0.0)) {
        return true;
    }
    return unoccluded(origin, d / len, len * (1.0 - 1e-4));
}

#endif
