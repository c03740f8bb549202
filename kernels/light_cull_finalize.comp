#version 460
#extension GL_GOOGLE_include_directive : require
// Turns the counters of light_cull.comp into the indirect arguments and statistics of the frame,
// then zeroes them for the next frame (issue 5; STYLE rule 14: a small kernel writes and clamps
// the indirect arguments and GPU counters reset themselves). A separate dispatch after a barrier,
// so the reset cannot race with the cull's atomics (SaschaWillems/Vulkan #748).
layout(local_size_x = 1) in;

#include "flare_types.h"
#include "occlusion.h"

layout(std430, binding = 0) buffer Counters { uint counters[]; };
layout(std430, binding = 1) writeonly buffer Indirect { GlintFlareIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintFlareStats stats; };
layout(push_constant) uniform Push { GlintCullFinalizePush pc; };

void main() {
  const uint visible = counters[GLINT_CULL_COUNTER_VISIBLE];
  const uint written = min(visible, pc.capacity);
  indirect.vertex_count = pc.vertex_count;
  indirect.instance_count = written;
  indirect.first_vertex = 0u;
  indirect.first_instance = 0u;
  indirect.group_count_x = written * pc.groups_per_instance;
  indirect.group_count_y = 1u;
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
  for (uint w = 0u; w < GLINT_CULL_COUNTER_WORDS; ++w) counters[w] = 0u;
}
