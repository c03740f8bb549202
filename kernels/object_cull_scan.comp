#version 460
#extension GL_GOOGLE_include_directive : require
// The middle dispatch of the object cull's ordered compaction, the same reduce-then-scan as
// light_cull_scan.comp (Merrill & Garland 2016, section 3, without the look-back): one workgroup
// turns the emitted masks object_cull.comp left per workgroup of GLINT_OBJECT_GROUP objects into
// the first list slot of each workgroup (an exclusive prefix sum of the masks' bit counts). Then
// invocation 0 writes the draw count (clamped to the capacity), the dispatch arguments and the
// statistics, and zeroes the counters for the next cull (a separate dispatch after the cull's
// atomics, so no reset races them).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "object_cull_params.h"

layout(std430, binding = 0) buffer Groups {
  uint counters[GLINT_OBJECT_HEADER_WORDS];
  uvec4 groups[];  // emitted mask (x, y), first slot (z, written here), 0
};
layout(std430, binding = 1) writeonly buffer Indirect { GlintObjectCullIndirect indirect; };
layout(std430, binding = 2) writeonly buffer Stats { GlintObjectCullStats stats; };
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

shared uint s_sum[2][GLINT_OBJECT_SCAN_MAX_THREADS];

uint emitted_in(uvec4 g) { return uint(bitCount(g.x) + bitCount(g.y)); }

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  const uint group_count = (pc.count + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;
  const uint run = (group_count + threads - 1u) / threads;
  const uint first = min(t * run, group_count), last = min(first + run, group_count);
  uint sum = 0u;
  for (uint g = first; g < last; ++g) sum += emitted_in(groups[g]);
  s_sum[0][t] = sum;
  barrier();
  uint src = 0u;
  for (uint d = 1u; d < threads; d <<= 1u) {  // inclusive Hillis-Steele scan, ping-pong
    uint v = s_sum[src][t];
    if (t >= d) v += s_sum[src][t - d];
    s_sum[src ^ 1u][t] = v;
    barrier();
    src ^= 1u;
  }
  uint slot = s_sum[src][t] - sum;
  const uint emitted = s_sum[src][threads - 1u];
  for (uint g = first; g < last; ++g) {
    const uint n = emitted_in(groups[g]);
    groups[g].z = slot;
    slot += n;
  }
  if (t != 0u) return;
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
