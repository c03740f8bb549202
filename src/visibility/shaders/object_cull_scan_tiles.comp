#version 460
#extension GL_GOOGLE_include_directive : require
// The first level of the object cull's two-level scan (Merrill & Garland 2016, "Single-pass
// Parallel Prefix Scan with Decoupled Look-back", section 3's reduce-then-scan, without the
// look-back): workgroup k takes the tile of `threads` consecutive 64-object groups, invocation t
// group k * threads + t (coalesced loads), and writes into each group's z the emitted objects of
// the tile before it (an exclusive prefix sum of the masks' bit counts, Hillis & Steele 1986 in
// shared memory) and into the tile's first group's w the tile's total. object_cull_scan.comp then
// scans the tile totals. Every tile runs in parallel, so no one workgroup walks every group.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "object_cull_params.h"

layout(std430, binding = 0) buffer Groups {
  uint counters[GLINT_OBJECT_HEADER_WORDS];
  uvec4 groups[];  // emitted mask (x, y), slot within the tile (z), tile total on a tile's first (w)
};
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

shared uint s_sum[2][GLINT_OBJECT_SCAN_MAX_THREADS];

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (pc.count + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;
  const uint g = gl_WorkGroupID.x * threads + t;
  uint n = 0u;
  if (g < group_count) {
    const uvec4 v = groups[g];
    n = uint(bitCount(v.x) + bitCount(v.y));
  }
  s_sum[0][t] = n;
  barrier();
  uint src = 0u;
  for (uint d = 1u; d < threads; d <<= 1u) {  // inclusive scan, ping-pong between the two arrays
    uint v = s_sum[src][t];
    if (t >= d) v += s_sum[src][t - d];
    s_sum[src ^ 1u][t] = v;
    barrier();
    src ^= 1u;
  }
  if (g < group_count) groups[g].z = s_sum[src][t] - n;
  if (t == 0u) groups[g].w = s_sum[src][threads - 1u];
}
