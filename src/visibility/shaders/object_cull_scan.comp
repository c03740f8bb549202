#version 460
#extension GL_GOOGLE_include_directive : require
// The object cull's top-level scan after the previous test kernel (object_cull_v1.comp; the
// second level of the ordered compaction, compact.glsl, after compact_scan_tiles.comp): one
// workgroup turns the tile totals into each tile's first list slot. Then invocation 0 writes the
// draw count (clamped to the capacity), the dispatch arguments and the statistics, and zeroes the
// counters for the next cull (a separate dispatch after the cull's atomics, so no reset races
// them). object_cull.comp runs the same top level
// itself (finish_cull).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#define COMPACT_GROUPS_BINDING 0
#include "compact.glsl"
#include "object_cull_params.h"

layout(std430, binding = 1) writeonly buffer Indirect { GlintObjectCullIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintObjectCullStats stats; };
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

void main() {
  const uint emitted = compact_top_scan(pc.count, pc.tile_groups);
  if (gl_LocalInvocationIndex != 0u) return;
  const uint written = min(emitted, pc.capacity);
  indirect.draw_count = written;
  indirect.group_count_x = (written + pc.objects_per_group - 1u) / pc.objects_per_group;
  indirect.group_count_y = 1u;
  indirect.group_count_z = 1u;
  stats.total = pc.count;
  stats.frustum_culled = counters[GLINT_OBJECT_COUNTER_FRUSTUM];
  stats.occluded = counters[GLINT_OBJECT_COUNTER_OCCLUDED];
  stats.visible = counters[GLINT_OBJECT_COUNTER_VISIBLE];
  stats.emitted = emitted;
  stats.written = written;
  stats.overflow = emitted - written;
  stats.invalid = counters[GLINT_OBJECT_COUNTER_INVALID];
  compact_reset_counters();
}
