#version 460
#extension GL_GOOGLE_include_directive : require
// The second level of the object cull's two-level scan (object_cull_scan_tiles.comp is the
// first): one workgroup turns the tile totals (w of each tile's first group) into the first list
// slot of each tile, an exclusive prefix sum over the tiles in chunks of `threads` with a running
// carry (a handful of chunks: 16 M objects are 256 tiles of 1024 groups). Then invocation 0
// writes the draw count (clamped to the capacity), the dispatch arguments and the statistics,
// and zeroes the counters for the next cull (a separate dispatch after the cull's atomics, so no
// reset races them).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "object_cull_params.h"

layout(std430, binding = 0) buffer Groups {
  uint counters[GLINT_OBJECT_HEADER_WORDS];
  uvec4 groups[];  // emitted mask (x, y), slot within the tile (z), tile's first slot on its first group (w)
};
layout(std430, binding = 1) writeonly buffer Indirect { GlintObjectCullIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintObjectCullStats stats; };
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

shared uint s_sum[2][GLINT_OBJECT_SCAN_MAX_THREADS];

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (pc.count + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;
  const uint tiles = (group_count + pc.tile_groups - 1u) / pc.tile_groups;
  uint carry = 0u;  // emitted objects of the chunks before
  for (uint base = 0u; base < tiles; base += threads) {
    const uint k = base + t;
    const uint n = k < tiles ? groups[k * pc.tile_groups].w : 0u;
    s_sum[0][t] = n;
    barrier();
    uint src = 0u;
    for (uint d = 1u; d < threads; d <<= 1u) {  // inclusive scan, ping-pong
      uint v = s_sum[src][t];
      if (t >= d) v += s_sum[src][t - d];
      s_sum[src ^ 1u][t] = v;
      barrier();
      src ^= 1u;
    }
    if (k < tiles) groups[k * pc.tile_groups].w = carry + s_sum[src][t] - n;
    carry += s_sum[src][threads - 1u];
    barrier();  // s_sum is rewritten by the next chunk
  }
  if (t != 0u) return;
  const uint emitted = carry;
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
  for (uint w = 0u; w < GLINT_OBJECT_HEADER_WORDS; ++w) counters[w] = 0u;
}
