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
#define GLINT_CULL_STORES_ARGUMENTS
#include "light_cull_outputs.glsl"

void main() {
  const uint visible = compact_top_scan(pc.count, pc.tile_groups);
  if (gl_LocalInvocationIndex != 0u) return;
  cull_store_arguments(pc.count, visible, counters[GLINT_CULL_COUNTER_FRUSTUM], counters[GLINT_CULL_COUNTER_OCCLUDED],
                       counters[GLINT_CULL_COUNTER_DISABLED], pc.capacity, pc.vertex_count, pc.groups_per_instance,
                       pc.max_group_count_x);
  compact_reset_counters();
}
