#version 460
#extension GL_GOOGLE_include_directive : require
#ifdef GLINT_OBJECT_SUBGROUP
// The variant the host picks where the device's subgroups support arithmetic in compute
// (VkPhysicalDeviceSubgroupProperties), as for object_cull.comp.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
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
// Per subgroup (at most one per invocation, for any subgroup size): its emitted objects, then its
// exclusive offset in the tile; its counts as 16-bit halves (frustum | occluded << 16, visible |
// invalid << 16: at most 128 invocations x 64 objects each, below 2^16).
shared uint s_sub[GLINT_COMPACT_SCAN_MAX_THREADS];
shared uvec2 s_sub_counts[GLINT_COMPACT_SCAN_MAX_THREADS];
shared uint s_tile_total;

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
  const uint incl = subgroupInclusiveAdd(n);
  const uint sub_total = subgroupAdd(n);
  const uvec2 sub_counts = subgroupAdd(uvec2((packed & 0xffu) | (((packed >> 8u) & 0xffu) << 16u),
                                             ((packed >> 16u) & 0xffu) | ((packed >> 24u) << 16u)));
  if (subgroupElect()) {
    s_sub[gl_SubgroupID] = sub_total;
    s_sub_counts[gl_SubgroupID] = sub_counts;
  }
  barrier();
  // Subgroup 0: the subgroups' exclusive offsets (in chunks of its size, with a running carry),
  // the tile's total and its counts.
  if (gl_SubgroupID == 0u) {
    uint carry = 0u;
    uvec4 c = uvec4(0u);
    for (uint base = 0u; base < gl_NumSubgroups; base += gl_SubgroupSize) {
      const uint k = base + gl_SubgroupInvocationID;
      const uint x = k < gl_NumSubgroups ? s_sub[k] : 0u;
      const uint before = subgroupExclusiveAdd(x);
      if (k < gl_NumSubgroups) {
        const uvec2 h = s_sub_counts[k];
        c += uvec4(h.x & 0xffffu, h.x >> 16u, h.y & 0xffffu, h.y >> 16u);
        s_sub[k] = carry + before;
      }
      carry += subgroupAdd(x);
    }
    c = subgroupAdd(c);
    if (subgroupElect()) {
      s_tile_total = carry;
      tile_counts[gl_WorkGroupID.x] = c;
    }
  }
  barrier();
  if (g < group_count) groups[g].z = s_sub[gl_SubgroupID] + incl - n;
  if (t == 0u) groups[g].w = s_tile_total;  // g is the tile's first group
}
#else
void main() {
  const uint c = compact_tile_scan_counts(pc.count);  // count t in invocation t < 4
  if (gl_LocalInvocationIndex < 4u) tile_counts[gl_WorkGroupID.x][gl_LocalInvocationIndex] = c;
}
#endif
