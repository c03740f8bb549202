// The ordered compaction's GPU side, shared by every user (compact_params.h, docs/OCCLUSION.md
// "The shared compaction core"). Before including, define COMPACT_GROUPS_BINDING (the group buffer's
// binding) and, where the including kernel only reads it, COMPACT_GROUPS_READONLY; where other
// workgroups of the same dispatch read what it writes, COMPACT_GROUPS_COHERENT. The kernel
// declares local_size_x_id = 0 (the tile's groups, for the scans).
//
// The scan is the reduce-then-scan of Merrill & Garland 2016, "Single-pass Parallel Prefix Scan
// with Decoupled Look-back" (NVIDIA), section 3, without the look-back: separate dispatches need no
// forward-progress guarantee. Level 1 (compact_tile_scan, every tile in parallel): each group's
// emitted items before it in its tile, and each tile's total. Level 2 (compact_top_scan, one
// workgroup): each tile's first slot. Both scan in shared memory (Hillis & Steele 1986, ping-pong
// arrays). The scatter then derives an item's slot from its group's word and bit counts, so no
// atomic decides a slot.
#include "compact_params.h"

layout(std430, binding = COMPACT_GROUPS_BINDING)
#ifdef COMPACT_GROUPS_READONLY
    readonly
#endif
#ifdef COMPACT_GROUPS_COHERENT
    coherent  // read by other workgroups of the same dispatch (a test kernel that scans its tiles)
#endif
    buffer CompactGroups {
  uint counters[GLINT_COMPACT_HEADER_WORDS];
  uvec4 groups[];  // emitted mask (x, y), counts then slot within the tile (z), tile total / first slot (w)
};

// The test's per-group counts (each at most GLINT_COMPACT_GROUP = 64) as the bytes of a group's z;
// compact_tile_scan adds count f of every group to counters[1 + f].
uint compact_pack_counts(uvec4 c) { return c.x | (c.y << 8u) | (c.z << 16u) | (c.w << 24u); }

#ifndef COMPACT_NO_SCAN
#define GLINT_WORKGROUP_SCAN_MAX_THREADS GLINT_COMPACT_SCAN_MAX_THREADS
#include "workgroup_scan.glsl"
shared uint s_compact_counts[4][32];  // the tile's counts, spread over 32 words each

#ifndef COMPACT_GROUPS_READONLY
// Level 1: workgroup k takes the tile of `threads` consecutive groups, invocation t group
// k * threads + t (coalesced loads); writes each group's z and the tile total into its first
// group's w. Returns the tile's count f of the groups' packed counts (z, from the test) in
// invocation f < 4 (0 in the others).
uint compact_tile_scan_counts(uint count) {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (count + GLINT_COMPACT_GROUP - 1u) / GLINT_COMPACT_GROUP;
  const uint g = gl_WorkGroupID.x * threads + t;
  for (uint k = t; k < 128u; k += threads) s_compact_counts[k >> 5u][k & 31u] = 0u;
  uint n = 0u, packed = 0u;
  if (g < group_count) {
    const uvec4 v = groups[g];
    n = uint(bitCount(v.x) + bitCount(v.y));
    packed = v.z;
  }
  uint total;
  const uint sum = workgroup_scan(n, total);  // its barriers order the zeroing above
  if (g < group_count) groups[g].z = sum - n;
  if (t == 0u) groups[g].w = total;
  for (uint f = 0u; f < 4u; ++f) {
    const uint c = (packed >> (8u * f)) & 0xffu;
    if (c != 0u) atomicAdd(s_compact_counts[f][t & 31u], c);
  }
  barrier();
  uint c = 0u;
  if (t < 4u) {
    for (uint k = 0u; k < 32u; ++k) c += s_compact_counts[t][k];
  }
  return c;
}

// Level 1 with the tile's counts added to the header: one atomic per tile and counter, where one
// per group and counter made many workgroups contend for the same few words (atomics on one
// address are serialised).
void compact_tile_scan(uint count) {
  const uint c = compact_tile_scan_counts(count);
  if (c != 0u) atomicAdd(counters[1u + gl_LocalInvocationIndex], c);  // c != 0 only where t < 4
}

// Level 2, one workgroup: turns the tile totals into each tile's first slot, an exclusive prefix
// sum over the tiles in chunks of `threads` with a running carry (a handful of chunks: 16 M items
// are 256 tiles of 1024 groups). Returns the emitted items (in every invocation).
uint compact_top_scan(uint count, uint tile_groups) {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (count + GLINT_COMPACT_GROUP - 1u) / GLINT_COMPACT_GROUP;
  const uint tiles = (group_count + tile_groups - 1u) / tile_groups;
  uint carry = 0u;  // emitted items of the chunks before
  for (uint base = 0u; base < tiles; base += threads) {
    const uint k = base + t;
    const uint n = k < tiles ? groups[k * tile_groups].w : 0u;
    uint total;
    const uint sum = workgroup_scan(n, total);
    if (k < tiles) groups[k * tile_groups].w = carry + sum - n;
    carry += total;
  }
  return carry;
}

// Zeroes the header's counters for the next run (call from one invocation, after reading them).
void compact_reset_counters() {
  for (uint w = 0u; w < GLINT_COMPACT_HEADER_WORDS; ++w) counters[w] = 0u;
}
#endif
#endif

// The slot of item i (< count) after both scans, or false when it was not emitted: the tile's
// first slot + the group's slot within the tile + the emitted items before it in the mask.
bool compact_slot(uint i, uint tile_groups, out uint slot) {
  const uint gi = i / GLINT_COMPACT_GROUP;
  const uvec4 g = groups[gi];
  const uint b = i % GLINT_COMPACT_GROUP;
  const uint word = b < 32u ? g.x : g.y;
  const uint bit = b & 31u;
  slot = 0u;
  if (((word >> bit) & 1u) == 0u) return false;
  const uint before = uint(bitCount(word & ((1u << bit) - 1u))) + (b < 32u ? 0u : uint(bitCount(g.x)));
  slot = groups[gi / tile_groups * tile_groups].w + g.z + before;
  return true;
}
