#version 460
#extension GL_GOOGLE_include_directive : require
// The second level of the order-preserving compaction's two-level scan (light_cull_scan_tiles.comp
// is the first; the "reduce-then-scan" of Merrill & Garland, "Single-pass Parallel Prefix Scan
// with Decoupled Look-back", NVIDIA 2016, section 3, without the look-back: separate dispatches
// need no forward-progress guarantee). One workgroup turns the tile totals (w of each tile's first
// group) into each tile's first instance slot, an exclusive prefix sum over the tiles in chunks of
// `threads` with a running carry (a handful of chunks: 4 M lights are 64 tiles of 1024 groups).
// Then invocation 0 writes the indirect arguments and statistics from the total and the header's
// counters, and zeroes the counters for the next frame: a small kernel writes and clamps the
// indirect arguments, and GPU counters reset themselves in a dispatch after the cull's atomics.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/flare_types.h"
#include "light_cull_params.h"

layout(std430, binding = 0) buffer Groups {
  uint counters[GLINT_CULL_HEADER_WORDS];
  uvec4 groups[];  // visibility mask (x, y), slot within the tile (z), tile's first slot on its first group (w)
};
layout(std430, binding = 1) writeonly buffer Indirect { GlintFlareIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintFlareStats stats; };
layout(push_constant) uniform Push { GlintCullCompactPush pc; };

shared uint s_sum[2][GLINT_CULL_SCAN_MAX_THREADS];

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (pc.count + GLINT_CULL_GROUP - 1u) / GLINT_CULL_GROUP;
  const uint tiles = (group_count + pc.tile_groups - 1u) / pc.tile_groups;
  uint carry = 0u;  // visible lights of the chunks before
  for (uint base = 0u; base < tiles; base += threads) {
    const uint k = base + t;
    const uint n = k < tiles ? groups[k * pc.tile_groups].w : 0u;
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
    if (k < tiles) groups[k * pc.tile_groups].w = carry + s_sum[src][t] - n;
    carry += s_sum[src][threads - 1u];
    barrier();  // s_sum is rewritten by the next chunk
  }
  const uint visible = carry;
  if (t != 0u) return;
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
  for (uint w = 0u; w < GLINT_CULL_HEADER_WORDS; ++w) counters[w] = 0u;
}
