#version 460
#extension GL_GOOGLE_include_directive : require
#ifdef GLINT_OBJECT_SUBGROUP
// The variant the host picks where the device's subgroups support arithmetic and ballots in
// compute (VkPhysicalDeviceSubgroupProperties), as for object_cull.comp.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#endif
// The object cull's scan of the test's masks (the ordered compaction, compact.glsl): workgroup k
// scans tile k (each group's slot within the tile into its z, the tile's total into its first
// group's w) and stores the tile's four counts. The tiles are independent: no workgroup waits for
// another, and nothing is left for the next cull. The scatter (object_cull_scatter.comp) adds the
// totals of the tiles before its own, and its workgroup 0 sums them all for the arguments and
// statistics, so no top-level pass runs between the two (docs/OCCLUSION.md, "Cost").
// The subgroup variant scans within each subgroup (subgroupInclusiveAdd), then one subgroup scans
// the subgroups' totals: two barriers, where the shared-memory scan of compact.glsl takes two per
// doubling (ten for a tile of 1024 groups) and its counts contend for shared atomics. The scan
// dispatch is short and one workgroup's latency is much of it (docs/OCCLUSION.md, "Cost").
// GLINT_OBJECT_SCAN_SERIAL builds the variant that takes the serial path (for subgroups that do
// not hold consecutive invocations) on every device, so that the tests reach it.
// GLINT_OBJECT_SCAN_PARTIAL builds the test variant in which subgroup 0's odd invocations sit out
// the scan of the subgroups' totals, as the inactive invocations of a partial subgroup would, and
// the subgroups of odd index report themselves out of order.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#define COMPACT_GROUPS_BINDING 0
#ifdef GLINT_OBJECT_SUBGROUP
#define COMPACT_NO_SCAN
#endif
#include "compact.glsl"
#include "object_cull_params.h"

// Each tile's counts: frustum, occluded, visible, invalid.
layout(std430, binding = 1) writeonly buffer TileCounts { uvec4 tile_counts[]; };
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

#ifdef GLINT_OBJECT_SUBGROUP
// Each invocation's group count (then, on the serial path, its exclusive prefix), and per
// subgroup (at most one per invocation, for any subgroup size) its total with kOutOfOrder, then its
// exclusive offset in the tile.
shared uint s_n[GLINT_COMPACT_SCAN_MAX_THREADS];
shared uint s_sub[GLINT_COMPACT_SCAN_MAX_THREADS];
shared uint s_counts[4];
shared uint s_tile_total, s_serial;
const uint kOutOfOrder = 0x80000000u;  // the subgroup's invocations are not consecutive in t order

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (pc.count + GLINT_COMPACT_GROUP - 1u) / GLINT_COMPACT_GROUP;
  const uint g = gl_WorkGroupID.x * threads + t;
  uint n = 0u, packed = 0u;
  if (g < group_count) {
    const uvec4 v = groups[g];
    n = uint(bitCount(v.x) + bitCount(v.y));
    packed = v.z;  // the test's four counts, a byte each (compact_pack_counts)
  }
  if (t < 4u) s_counts[t] = 0u;
  s_n[t] = n;
  // The prefix within a subgroup is in t order only where the subgroup holds consecutive
  // invocations in order; Vulkan does not promise that mapping (it holds on the devices of
  // docs/DEVICES.md), so each subgroup checks it, and a tile with a subgroup out of order is
  // scanned serially below.
  const bool in_order =
      subgroupBallotBitCount(subgroupBallot(t != gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID)) == 0u;
  const uint incl = subgroupInclusiveAdd(n);
  const uint sub_total = subgroupAdd(n);
  const uvec4 sub_counts = subgroupAdd(uvec4(packed & 0xffu, (packed >> 8u) & 0xffu, (packed >> 16u) & 0xffu, packed >> 24u));
  // The test variants report subgroups out of order that are not: every one, or those of odd index.
#if defined(GLINT_OBJECT_SCAN_SERIAL)
  const bool forced = true;
#elif defined(GLINT_OBJECT_SCAN_PARTIAL)
  const bool forced = (gl_SubgroupID & 1u) != 0u;
#else
  const bool forced = false;
#endif
  const bool out_of_order = !in_order || forced;
  if (subgroupElect()) s_sub[gl_SubgroupID] = sub_total | (out_of_order ? kOutOfOrder : 0u);
  barrier();
  if (subgroupElect()) {  // integer sums: the same in any order
    for (uint f = 0u; f < 4u; ++f) {
      if (sub_counts[f] != 0u) atomicAdd(s_counts[f], sub_counts[f]);
    }
  }
  // Subgroup 0: the subgroups' exclusive offsets (in chunks of as many subgroups as it has active
  // invocations, with a running carry) and the tile's total; where a subgroup is out of order, one
  // invocation scans the groups in t order. Chunk entry k is the invocation's rank among the active
  // ones, not gl_SubgroupInvocationID: where the workgroup's x size is not a multiple of the
  // subgroup size, Vulkan lets a subgroup (subgroup 0 too) launch with inactive invocations at any
  // index (Vulkan 1.3, built-in SubgroupLocalInvocationId), and indexing by gl_SubgroupInvocationID
  // would skip the subgroups of the inactive indices: their totals, offsets and out-of-order flags.
  // The exclusive add runs over the active invocations in gl_SubgroupInvocationID order, the
  // order of the ranks.
#ifdef GLINT_OBJECT_SCAN_PARTIAL
  const bool lead = gl_SubgroupID == 0u && (gl_SubgroupInvocationID & 1u) == 0u;  // the test variant
#else
  const bool lead = gl_SubgroupID == 0u;
#endif
  if (lead) {
    const uvec4 on = subgroupBallot(true);
    const uint lanes = subgroupBallotBitCount(on), rank = subgroupBallotExclusiveBitCount(on);
    uint carry = 0u;
    bool serial = false;
    for (uint base = 0u; base < gl_NumSubgroups; base += lanes) {
      const uint k = base + rank;
      const uint w = k < gl_NumSubgroups ? s_sub[k] : 0u;
      serial = serial || subgroupBallotBitCount(subgroupBallot((w & kOutOfOrder) != 0u)) != 0u;
      const uint x = w & ~kOutOfOrder;
      const uint before = subgroupExclusiveAdd(x);
      if (k < gl_NumSubgroups) s_sub[k] = carry + before;
      carry += subgroupAdd(x);
    }
    if (subgroupElect()) {
      if (serial) {
        uint run = 0u;
        for (uint k = 0u; k < threads; ++k) {
          const uint x = s_n[k];
          s_n[k] = run;
          run += x;
        }
      }
      s_tile_total = carry;
      s_serial = serial ? 1u : 0u;
    }
  }
  barrier();
  if (g < group_count) groups[g].z = s_serial != 0u ? s_n[t] : s_sub[gl_SubgroupID] + incl - n;
  if (t == 0u) groups[g].w = s_tile_total;  // g is the tile's first group
  if (t < 4u) tile_counts[gl_WorkGroupID.x][t] = s_counts[t];
}
#else
void main() {
  const uint c = compact_tile_scan_counts(pc.count);  // count t in invocation t < 4
  if (gl_LocalInvocationIndex < 4u) tile_counts[gl_WorkGroupID.x][gl_LocalInvocationIndex] = c;
}
#endif
