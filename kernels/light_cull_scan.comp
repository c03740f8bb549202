#version 460
#extension GL_GOOGLE_include_directive : require
// The middle dispatch of the order-preserving compaction (issue 6): one workgroup turns the
// visibility masks light_cull.comp left per workgroup of GLINT_CULL_GROUP lights into the instance
// slot of each workgroup's first visible light, an exclusive prefix sum over the masks' bit counts
// (the "reduce-then-scan" of Merrill & Garland, "Single-pass Parallel Prefix Scan with Decoupled
// Look-back", NVIDIA 2016, section 3, without the look-back: a separate dispatch needs no forward
// progress guarantee). Invocation t sums a contiguous run of ceil(groups / threads) masks, a
// Hillis-Steele scan over the run totals in shared memory gives each run's start, and the run is
// walked again to write every workgroup's slot. Then invocation 0 writes the indirect arguments and
// statistics from the total and the header's counters, and zeroes the counters for the next frame
// (issue 5; STYLE rule 14: a small kernel writes and clamps the indirect arguments, GPU counters
// reset themselves, here in a separate dispatch after the cull's atomics: SaschaWillems/Vulkan #748).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/flare_types.h"
#include "occlusion.h"

layout(std430, binding = 0) buffer Groups {
  uint counters[GLINT_CULL_HEADER_WORDS];
  uvec4 groups[];  // visibility mask (x, y), first slot (z, written here), 0
};
layout(std430, binding = 1) writeonly buffer Indirect { GlintFlareIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintFlareStats stats; };
layout(push_constant) uniform Push { GlintCullCompactPush pc; };

shared uint s_sum[2][GLINT_CULL_SCAN_MAX_THREADS];

uint visible_in(uvec4 g) { return uint(bitCount(g.x) + bitCount(g.y)); }

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (pc.count + GLINT_CULL_GROUP - 1u) / GLINT_CULL_GROUP;
  const uint run = (group_count + threads - 1u) / threads;
  const uint first = min(t * run, group_count), last = min(first + run, group_count);
  uint sum = 0u;
  for (uint g = first; g < last; ++g) sum += visible_in(groups[g]);
  s_sum[0][t] = sum;
  barrier();
  uint src = 0u;
  for (uint d = 1u; d < threads; d <<= 1u) {  // inclusive scan, ping-pong between the two arrays
    uint v = s_sum[src][t];
    if (t >= d) v += s_sum[src][t - d];
    s_sum[src ^ 1u][t] = v;
    barrier();
    src ^= 1u;
  }
  uint slot = s_sum[src][t] - sum;
  const uint visible = s_sum[src][threads - 1u];
  for (uint g = first; g < last; ++g) {
    const uint n = visible_in(groups[g]);
    groups[g].z = slot;
    slot += n;
  }
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
