#version 460
#extension GL_GOOGLE_include_directive : require
// The object cull's scan of the test's masks (the ordered compaction, compact.glsl): workgroup k
// scans tile k (compact_tile_scan_counts: each group's slot within the tile, the tile's total in
// its first group's w) and stores the tile's four counts. The tiles are independent: no workgroup
// waits for another, and nothing is left for the next cull. The scatter (object_cull_scatter.comp)
// adds the totals of the tiles before its own, and its workgroup 0 sums them all for the arguments
// and statistics, so no top-level pass runs between the two (docs/OCCLUSION.md, "Cost").
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#define COMPACT_GROUPS_BINDING 0
#include "compact.glsl"
#include "object_cull_params.h"

// Each tile's counts: frustum, occluded, visible, invalid.
layout(std430, binding = 1) writeonly buffer TileCounts { uvec4 tile_counts[]; };
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

void main() {
  const uint c = compact_tile_scan_counts(pc.count);  // count t in invocation t < 4
  if (gl_LocalInvocationIndex < 4u) tile_counts[gl_WorkGroupID.x][gl_LocalInvocationIndex] = c;
}
