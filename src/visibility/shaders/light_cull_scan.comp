#version 460
#extension GL_GOOGLE_include_directive : require
// The light cull's top-level scan (the second level of the ordered compaction, compact.glsl;
// compact_scan_tiles.comp is the first): one workgroup turns the tile totals into each tile's
// first instance slot. Then invocation 0 writes the indirect arguments and statistics from the
// total and the header's counters, and zeroes the counters for the next frame: a small kernel
// writes and clamps the indirect arguments, and GPU counters reset themselves in a dispatch after
// the cull's atomics.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/flare_types.h"
#define COMPACT_GROUPS_BINDING 0
#include "compact.glsl"
#include "light_cull_params.h"

layout(std430, binding = 1) writeonly buffer Indirect { GlintFlareIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintFlareStats stats; };
layout(push_constant) uniform Push { GlintCullCompactPush pc; };

void main() {
  const uint visible = compact_top_scan(pc.count, pc.tile_groups);
  if (gl_LocalInvocationIndex != 0u) return;
  const uint written = min(visible, pc.capacity);
  indirect.vertex_count = pc.vertex_count;
  indirect.instance_count = written;
  indirect.first_vertex = 0u;
  indirect.first_instance = 0u;
  // instances x groups_per_instance workgroups, as rows of at most maxComputeWorkGroupCount[0]
  // (GlintFlareIndirect says how a kernel recovers its linear workgroup index).
  const uint groups = written * pc.groups_per_instance;
  indirect.group_count_x = min(groups, pc.max_group_count_x);
  indirect.group_count_y = max(1u, (groups + pc.max_group_count_x - 1u) / pc.max_group_count_x);
  indirect.group_count_z = 1u;
  indirect.reserved = 0u;
  stats.total = pc.count;
  stats.frustum_culled = counters[GLINT_CULL_COUNTER_FRUSTUM];
  stats.occluded = counters[GLINT_CULL_COUNTER_OCCLUDED];
  stats.visible = visible;
  stats.overflow = visible - written;
  stats.disabled = counters[GLINT_CULL_COUNTER_DISABLED];
  stats.reserved0 = 0u;
  stats.reserved1 = 0u;
  compact_reset_counters();
}
