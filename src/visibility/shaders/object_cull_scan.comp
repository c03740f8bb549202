#version 460
#extension GL_GOOGLE_include_directive : require
// The object cull's scan of the test's masks (the ordered compaction, compact.glsl), in one
// dispatch: workgroup k scans tile k (compact_tile_scan_counts: each group's slot within the tile,
// the tile total) and stores the tile's four counts; the last workgroup to finish a tile (a count
// of scanned tiles after a buffer memory barrier, the "last block" pattern) scans the tile totals
// into each tile's first slot (compact_top_scan), sums the tiles' counts and writes the draw count
// (clamped to the capacity), the dispatch arguments and the statistics. Nothing accumulates across
// culls: the counts are per tile, overwritten every cull, so a cull cut short leaves nothing that
// corrupts the next one (the scatter zeroes the count of scanned tiles after every cull).
// A few hundred workgroups pay the barrier and the atomic here; folded into the test kernel, each
// of its thousands of workgroups did (docs/OCCLUSION.md, "Cost").
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#define COMPACT_GROUPS_BINDING 0
#define COMPACT_GROUPS_COHERENT  // the last workgroup reads the tile totals the others wrote
#include "compact.glsl"
#include "object_cull_params.h"

layout(std430, binding = 1) writeonly buffer Indirect { GlintObjectCullIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintObjectCullStats stats; };
// The tiles scanned so far, then each tile's counts (frustum, occluded, visible, invalid). The
// count is zero between culls: the last tile zeroes it, and the scatter (compact_scatter.comp)
// zeroes it again after every cull.
layout(std430, binding = 3) coherent buffer Tiles {
  uint tiles_done;
  uint tiles_reserved[3];
  uvec4 tile_counts[];
};
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

shared bool s_last;
shared uint s_totals[4];

void main() {
  const uint t = gl_LocalInvocationIndex;
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint group_count = (pc.count + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;
  const uint tiles = (group_count + pc.tile_groups - 1u) / pc.tile_groups;
  if (t < 4u) s_totals[t] = 0u;
  if (tiles > 0u) {  // uniform
    const uint c = compact_tile_scan_counts(pc.count);  // count t in invocation t < 4
    if (t < 4u) tile_counts[gl_WorkGroupID.x][t] = c;
    memoryBarrierBuffer();  // every invocation's slot writes and the counts before the count of tiles
    barrier();
    if (t == 0u) s_last = atomicAdd(tiles_done, 1u) == tiles - 1u;
    barrier();
    if (!s_last) return;  // uniform in the workgroup
    memoryBarrierBuffer();
  }
  // The last tile (or the one workgroup of a cull of no objects).
  const uint emitted = compact_top_scan(pc.count, pc.tile_groups);
  uvec4 c = uvec4(0u);
  for (uint k = t; k < tiles; k += threads) c += tile_counts[k];
  for (uint f = 0u; f < 4u; ++f) {
    if (c[f] != 0u) atomicAdd(s_totals[f], c[f]);
  }
  barrier();
  if (t != 0u) return;
  tiles_done = 0u;
  const uint written = min(emitted, pc.capacity);
  indirect.draw_count = written;
  indirect.group_count_x = (written + pc.objects_per_group - 1u) / pc.objects_per_group;
  indirect.group_count_y = 1u;
  indirect.group_count_z = 1u;
  stats.total = pc.count;
  stats.frustum_culled = s_totals[GLINT_OBJECT_COUNTER_FRUSTUM - 1u];
  stats.occluded = s_totals[GLINT_OBJECT_COUNTER_OCCLUDED - 1u];
  stats.visible = s_totals[GLINT_OBJECT_COUNTER_VISIBLE - 1u];
  stats.emitted = emitted;
  stats.written = written;
  stats.overflow = emitted - written;
  stats.invalid = s_totals[GLINT_OBJECT_COUNTER_INVALID - 1u];
}
