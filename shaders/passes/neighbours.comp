// passes/neighbours.comp — Rust: crates/radcache-render/src/passes/neighbours.rs
// Neighbour clamping (Křivánek et al. 2006; docs/cache-frame.md §5; docs/irradiance-cache.md §4.5)
// through a world-space hash grid. For every pair (i new, j any) the radii must satisfy
// R_i ≤ R_j + ‖p_i − p_j‖ and R_j ≤ R_i + ‖p_i − p_j‖ (atomic minimums on R_orig's float bits:
// IEEE order equals integer order for non-negative floats, so the order of the updates does not
// matter).
//
// Only pairs closer than max(R⁺_i, R⁺_j) can change a radius the splat uses (R_used =
// clamp(R_orig, R⁻, R⁺)), once every R_orig is capped at its R⁺: a new record's R_orig is first
// lowered to its R⁺ (mode 1). Then for d ≥ max(R⁺_i, R⁺_j), R_j + d ≥ R⁺_i ≥ R_i and vice versa,
// so the grid, which finds every pair closer than that bound, gives exactly the all-pairs result.
//
// The grid (crates/radcache-render/src/neighbours.rs): a record's level is L = ⌈log₂ R⁺⌉ clamped
// to the LEVELS levels below pc.level_max (cells of 2^L ≥ R⁺; level_max from the scene's size).
// Table A holds each record once, in the cell of its own level that contains it; table B holds
// it in the cell containing it at its own level and at every coarser one. Buckets are
// hash(table, level, cell) mod the table size, each the head of a linked list of entries
// (record × slot, slot 0 = table A, slot 1 + level − level_base = table B); colliding cells share
// a list and are told apart by the entry's level and table (the distance test does the rest).
// A query from record i reads the 27 cells around it: in table B at its own level (every record
// of level ≤ L_i within 2^L_i ≥ max(R⁺_i, R⁺_j)), and in table A at each coarser level L (records
// of level exactly L, within 2^L ≥ R⁺_j ≥ R⁺_i).
//
// Modes: 0 insert the records outside the pending batch (a rebuild after clearing the heads; one
// invocation per record); 1 cap and insert the pending batch (one workgroup per new record);
// 2 query and clamp (one workgroup per new record, its invocations share the cells).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "../shared/layouts.glsl"
#include "../shared/bindings.glsl"
#include "../common/ircache_math.glsl"
#include "../shared/push.glsl"

layout(local_size_x = 64) in;

// Read, except radii_shrunk: mode 2 counts there the records outside the batch whose used
// radius it lowered (their coverage splat is then stale: crates/radcache-render/src/frame/ic/phases.rs).
layout(binding = B_NEIGHBOURS_COUNTERS, std430) buffer Counters { IcCounters counters; };
layout(binding = B_NEIGHBOURS_RECORDS, std430) buffer Records { GpuRecord records[]; };
// The same buffer as 32-bit words, for the atomic minimum on R_orig (word 7 of 44 per record).
layout(binding = B_NEIGHBOURS_RECORD_WORDS, std430) buffer RecordWords { uint record_words[]; };
// Bucket heads: 1 + entry of the list's first entry, 0 = empty. Length a power of two.
layout(binding = B_NEIGHBOURS_HEADS, std430) buffer Heads { uint heads[]; };
// Per entry: 1 + the next entry, 0 = end of the list.
layout(binding = B_NEIGHBOURS_NEXT, std430) buffer Next { uint next_entry[]; };

layout(push_constant) uniform Push { NeighboursPush pc; };

// GPU_RECORD_WORDS, GPU_RECORD_R_ORIG_WORD, GRID_LEVELS, GRID_SLOTS (1 + GRID_LEVELS entries per
// record) and GRID_MAX_LIST (a guard against a corrupted list) come from constants.glsl.
const int LEVELS = int(GRID_LEVELS);

int level_base() { return pc.level_max - LEVELS + 1; }

int record_level(uint j) {
    float hi = sanitize_radius(records[j].bounds.y);
    int l = hi > 0.0 ? int(ceil(log2(hi))) : level_base();
    return clamp(l, level_base(), pc.level_max);
}

ivec3 cell_of(vec3 p, int level) {
    vec3 c = floor(p * exp2(float(-level)));
    return ivec3(clamp(c, vec3(-1.0e9), vec3(1.0e9)));
}

uint bucket(uint table, int level, ivec3 cell) {
    uint h = ircache_hash(uint(cell.x) * 73856093u);
    h = ircache_hash(h ^ (uint(cell.y) * 19349663u));
    h = ircache_hash(h ^ (uint(cell.z) * 83492791u));
    h = ircache_hash(h ^ (uint(level + 1024) * 2u + table));
    return h & uint(heads.length() - 1);
}

void insert(uint j, uint slot, uint table, int level) {
    uint e = j * GRID_SLOTS + slot;
    uint b = bucket(table, level, cell_of(records[j].position_radius.xyz, level));
    next_entry[e] = atomicExchange(heads[b], e + 1u);
}

// Inserts record j's entry `slot` (0: table A; 1 + k: table B at level base + k) if it has one.
void insert_slot(uint j, uint slot) {
    int own = record_level(j);
    if (slot == 0u) {
        insert(j, 0u, 0u, own);
        return;
    }
    int level = level_base() + int(slot) - 1;
    if (level >= own && level <= pc.level_max) {
        insert(j, slot, 1u, level);
    }
}

shared float group_min[64];

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint count = counters.record_count;
    uint base = counters.batch_first;
    uint batch_end = min(base + counters.dispatch.x, count);
    if (pc.step == NEIGHBOURS_INSERT_OLD) {
        uint j = gl_GlobalInvocationID.x;
        if (j < count && (j < base || j >= batch_end)) {
            for (uint s = 0u; s < GRID_SLOTS; ++s) {
                insert_slot(j, s);
            }
        }
        return;
    }
    uint i = base + gl_WorkGroupID.x;
    if (i >= batch_end) {
        return;
    }
    if (pc.step == NEIGHBOURS_INSERT_BATCH) {
        if (lid == 0u) {
            float hi = sanitize_radius(records[i].bounds.y);
            atomicMin(record_words[i * GPU_RECORD_WORDS + GPU_RECORD_R_ORIG_WORD], floatBitsToUint(hi));
        }
        if (lid < GRID_SLOTS) {
            insert_slot(i, lid);
        }
        return;
    }

    vec3 p_i = records[i].position_radius.xyz;
    float r_i = sanitize_radius(uintBitsToFloat(record_words[i * GPU_RECORD_WORDS + GPU_RECORD_R_ORIG_WORD]));
    int own = record_level(i);
    uint items = uint(pc.level_max - own + 1) * 27u;
    float local_min = IC_FAR;
    for (uint t = lid; t < items; t += 64u) {
        int level = own + int(t / 27u);
        uint c = t % 27u;
        ivec3 cell = cell_of(p_i, level) + ivec3(int(c % 3u) - 1, int((c / 3u) % 3u) - 1, int(c / 9u) - 1);
        uint table = level == own ? 1u : 0u;
        uint want_slot = table == 1u ? uint(1 + level - level_base()) : 0u;
        uint e1 = heads[bucket(table, level, cell)];
        for (uint steps = 0u; e1 != 0u && steps < GRID_MAX_LIST; ++steps) {
            uint e = e1 - 1u;
            e1 = next_entry[e];
            uint j = e / GRID_SLOTS;
            if (e % GRID_SLOTS != want_slot || j == i || j >= count) {
                continue;
            }
            if (table == 0u && record_level(j) != level) {
                continue;
            }
            float d = distance(p_i, records[j].position_radius.xyz);
            float r_j =
                sanitize_radius(uintBitsToFloat(record_words[j * GPU_RECORD_WORDS + GPU_RECORD_R_ORIG_WORD]));
            local_min = min(local_min, neighbour_clamp(IC_FAR, r_j, d));
            float shrunk = neighbour_clamp(r_j, r_i, d);
            if (shrunk < r_j) {
                uint before = atomicMin(record_words[j * GPU_RECORD_WORDS + GPU_RECORD_R_ORIG_WORD],
                                        floatBitsToUint(shrunk));
                vec2 b = records[j].bounds.xy;
                if (j < base &&
                    clamp_radius(shrunk, b.x, b.y) < clamp_radius(uintBitsToFloat(before), b.x, b.y)) {
                    atomicAdd(counters.radii_shrunk, 1u);
                }
            }
        }
    }
    group_min[lid] = local_min;
    barrier();
    for (uint s = 32u; s > 0u; s >>= 1u) {
        if (lid < s) {
            group_min[lid] = min(group_min[lid], group_min[lid + s]);
        }
        barrier();
    }
    if (lid == 0u && group_min[0] < r_i) {
        atomicMin(record_words[i * GPU_RECORD_WORDS + GPU_RECORD_R_ORIG_WORD], floatBitsToUint(group_min[0]));
    }
}
