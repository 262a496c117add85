// common/path_grid.glsl — Rust: crates/radcache-render/src/passes/record/path_grid.rs
// The gather paths' radiance grid (docs/cache-frame.md §4.1), compiled into the record pass with
// the define PATH_GRID (scenes with a Lambertian material; only Lambertian vertices read and fill
// it: the continuation from one does not depend on the direction it was reached from). A cell is
// a world-space box, its edge a power of two about PATH_GRID_CELL_PX pixel footprints at its
// distance from the camera (at most PATH_GRID_MAX_CELL of the scene), and one of the six axis
// directions its vertices' geometric normals are nearest to. It holds the sum and the count
// of the continuation radiance `L_c` that paths leaving vertices in it brought back: the light a
// path finds past a vertex's next-event estimation, which a cosine-sampled continuation
// estimates as the vertex's indirect irradiance over π whatever the albedo (the albedo is in the
// path's throughput, not in `L_c`).
//
// Determinism: a cell becomes ready in the dispatch whose deposit brings its count to
// PATH_GRID_READY (that deposit stores the dispatch's epoch); only dispatches with a later epoch
// take its mean, and no later dispatch deposits into a ready cell, so every dispatch sees sums
// that are final. The sums are 64-bit fixed point (PATH_GRID_SCALE steps per unit), whose
// addition is exact and commutative: the records do not depend on the order of the invocations.
// Keys go to the first free slot of PATH_GRID_PROBES by linear probing; a key that finds none is
// served by full paths. A lookup looks through all its probes for its key before it inserts, so
// a key has one cell, found whatever order the invocations run in, also where the grid's
// ageing freed slots (docs/temporal.md §3.8). The host clears the grid at the start of a frame, or, where it is kept
// over frames with the records (docs/temporal.md §3.8), one slice of it; epochs then go on
// counting, so cells made ready in earlier frames are read.
#ifndef RADCACHE_PATH_GRID_GLSL
#define RADCACHE_PATH_GRID_GLSL

#include "hash.glsl"
#include "../shared/constants.glsl"

// x: the key's tag (0: a free slot); y: the epoch in which the cell became ready (0: not yet);
// z: the continuations deposited; w unused.
layout(binding = B_RECORD_PATH_GRID, std430) buffer PathGridKeys { uvec4 grid_keys[]; };
// Four per cell: the red, green and blue sums of L_c·PATH_GRID_SCALE; the fourth unused.
layout(binding = B_RECORD_PATH_GRID_SUMS, std430) buffer PathGridSums { int64_t grid_sums[]; };

const uint PATH_GRID_NONE = 0xffffffffu;

// This dispatch's epoch (0: the grid is off for it) and the pixel footprint per unit distance.
uint g_grid_epoch = 0u;
float g_grid_spread = 0.0;

// Starts the grid for a dispatch of epoch `epoch`. The pixel footprint at unit distance is
// 2·tan(fov/2)/height; the y row of clip_from_world is the projection's P11 = 1/tan(fov/2) times
// the camera's unit up axis.
void path_grid_begin(uint epoch) {
    g_grid_epoch = epoch;
    mat4 m = frame.clip_from_world;
    float p11 = length(vec3(m[0][1], m[1][1], m[2][1]));
    float height = float(max(frame.resolution.y, 1u));
    g_grid_spread = p11 > 0.0 ? 2.0 / (height * p11) : 0.0;
}

// The slot of the cell of a vertex at `p` with geometric normal `ng` (inserting its key when
// new), PATH_GRID_NONE when its probes are all taken by other keys; `edge` is the cell's edge,
// at most PATH_GRID_MAX_CELL of the scene's size (frame.camera_position.w, the bounding box's
// diagonal) whatever the resolution: a cell that straddles a thin wall mixes the light of both
// sides.
uint path_grid_slot(vec3 p, vec3 ng, out float edge) {
    float scale = frame.camera_position.w;
    float d = distance(p, frame.camera_position.xyz);
    float size = max(PATH_GRID_CELL_PX * g_grid_spread * d, scale * 1.0e-5);
    int largest = int(floor(log2(scale * PATH_GRID_MAX_CELL)));
    int level = clamp(int(ceil(log2(size))), -100, min(largest, 100));
    edge = exp2(float(level));
    ivec3 c = ivec3(floor(p / edge));
    vec3 a = abs(ng);
    uint axis = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
    uint side = ng[axis] < 0.0 ? 1u : 0u;
    uint h = pcg_hash(uint(c.x) ^ pcg_hash(uint(c.y) ^ pcg_hash(uint(c.z)
             ^ pcg_hash(uint(level + 128) | ((2u * axis + side) << 8u)))));
    uint tag = pcg_hash(h ^ 0x5bd1e995u) | 1u;
    // The key's cell, wherever among its probes it was inserted: where the grid is kept over
    // frames, the slot of an aged-out key before it may be free again, and a key that stopped
    // there would insert a second, empty cell for itself in one order of the invocations and
    // read its old one in another.
    for (uint i = 0u; i < PATH_GRID_PROBES; ++i) {
        uint slot = (h + i) & (PATH_GRID_CELLS - 1u);
        if (grid_keys[slot].x == tag) {
            return slot;
        }
    }
    for (uint i = 0u; i < PATH_GRID_PROBES; ++i) {
        uint slot = (h + i) & (PATH_GRID_CELLS - 1u);
        uint k = grid_keys[slot].x;
        if (k == 0u) {
            k = atomicCompSwap(grid_keys[slot].x, 0u, tag);
            if (k == 0u) {
                return slot;
            }
        }
        if (k == tag) {
            return slot;
        }
    }
    return PATH_GRID_NONE;
}

// Whether dispatches of this epoch take the cell's mean.
bool path_grid_ready(uint slot) {
    uint epoch = grid_keys[slot].y;
    return epoch != 0u && epoch < g_grid_epoch;
}

// The cell's mean L_c (a ready cell's sums are final).
vec3 path_grid_mean(uint slot) {
    float n = float(max(grid_keys[slot].z, 1u)) * PATH_GRID_SCALE;
    return vec3(float(grid_sums[4u * slot]), float(grid_sums[4u * slot + 1u]),
                float(grid_sums[4u * slot + 2u])) / n;
}

// Adds one continuation's L_c to the cell (finite values only; clamped so sums cannot overflow).
void path_grid_deposit(uint slot, vec3 lc) {
    if (any(isnan(lc)) || any(isinf(lc))) {
        return;
    }
    vec3 q = clamp(lc, -PATH_GRID_MAX_SAMPLE, PATH_GRID_MAX_SAMPLE) * PATH_GRID_SCALE;
    atomicAdd(grid_sums[4u * slot], int64_t(q.r));
    atomicAdd(grid_sums[4u * slot + 1u], int64_t(q.g));
    atomicAdd(grid_sums[4u * slot + 2u], int64_t(q.b));
    if (atomicAdd(grid_keys[slot].z, 1u) + 1u == PATH_GRID_READY) {
        atomicExchange(grid_keys[slot].y, g_grid_epoch);
    }
}

#endif
