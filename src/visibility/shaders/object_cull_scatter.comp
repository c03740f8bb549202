#version 460
#extension GL_GOOGLE_include_directive : require
// The object cull's scatter (the ordered compaction's last step, compact.glsl; the tiles were
// scanned by object_cull_scan.comp): one workgroup of GLINT_COMPACT_GROUP invocations per
// GLINT_COMPACT_SCATTER_GROUPS consecutive 64-object groups. Consecutive groups' emitted objects
// take consecutive slots (one exclusive prefix sum over the groups in object order), so the
// workgroup's objects go to the one range first .. first + n - 1, in object order, on every run.
// first = (the totals of the tiles before the first group's tile) + (the group's slot within its
// tile): each workgroup adds up the earlier tiles' totals itself (a few hundred at most; loads
// independent of its masks'), so no top-level scan pass runs before this one.
// 1. Invocation k < groups loads group k's mask (coalesced) and every invocation a share of the
//    earlier tiles' totals: every load of the workgroup is issued before the first barrier.
// 2. For each group in order, invocation t of an emitted object writes the object's index into the
//    shared list at (objects of the earlier groups) + (its rank in the mask).
// 3. The range is copied cooperatively, invocation t taking words t, t + 64, ...: consecutive
//    invocations write consecutive words and read each object's consecutive payload words, and all
//    of the workgroup's payload loads are independent (one round trip to memory for up to 1024
//    objects). An index list (no payload) is the shared list itself.
// Slots at or beyond the capacity are not written (the overflow keeps the smallest indices). A
// slot receives the object's payload_words words or its index.
// Workgroup 0 also sums every tile's total and counts into the draw count (clamped to the
// capacity), the dispatch arguments and the statistics (it runs for a cull of no objects too).
layout(local_size_x_id = 0, local_size_y_id = 1) in;  // GLINT_COMPACT_GROUP x 1

#define COMPACT_GROUPS_BINDING 0
#define COMPACT_GROUPS_READONLY
#define COMPACT_NO_SCAN
#include "compact.glsl"
#include "object_cull_params.h"

layout(std430, binding = 1) restrict readonly buffer Payloads { uint payloads[]; };  // payload words per object
layout(std430, binding = 2) restrict readonly buffer TileCounts { uvec4 tile_counts[]; };  // object_cull_scan.comp
layout(std430, binding = 3) restrict writeonly buffer List { uint list[]; };  // max(1, payload words) per slot
layout(std430, binding = 4) writeonly buffer Indirect { GlintObjectCullIndirect indirect; };
layout(std430, binding = 5) writeonly buffer Stats { GlintObjectCullStats stats; };
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

const uint kGroups = GLINT_COMPACT_SCATTER_GROUPS;
shared uvec2 s_mask[kGroups];
shared uint s_first;                                // the slot of the workgroup's first emitted object
shared uint s_item[kGroups * GLINT_COMPACT_GROUP];  // the workgroup's emitted objects, in order
shared uint s_totals[5];                            // workgroup 0: emitted, then the four counts

// Workgroup 0: every tile's total and counts, summed (each invocation a share, then shared
// atomics), into the arguments and statistics.
void write_arguments(uint tiles) {
  const uint t = gl_LocalInvocationIndex;
  uint emitted = 0u;
  uvec4 c = uvec4(0u);
  for (uint k = t; k < tiles; k += GLINT_COMPACT_GROUP) {
    emitted += groups[k * pc.tile_groups].w;
    c += tile_counts[k];
  }
  if (emitted != 0u) atomicAdd(s_totals[0], emitted);
  for (uint f = 0u; f < 4u; ++f) {
    if (c[f] != 0u) atomicAdd(s_totals[1u + f], c[f]);
  }
  barrier();
  if (t != 0u) return;
  const uint total = s_totals[0];
  const uint written = min(total, pc.capacity);
  indirect.draw_count = written;
  indirect.group_count_x = (written + pc.objects_per_group - 1u) / pc.objects_per_group;
  indirect.group_count_y = 1u;
  indirect.group_count_z = 1u;
  stats.total = pc.count;
  stats.frustum_culled = s_totals[GLINT_OBJECT_COUNTER_FRUSTUM];
  stats.occluded = s_totals[GLINT_OBJECT_COUNTER_OCCLUDED];
  stats.visible = s_totals[GLINT_OBJECT_COUNTER_VISIBLE];
  stats.emitted = total;
  stats.written = written;
  stats.overflow = total - written;
  stats.invalid = s_totals[GLINT_OBJECT_COUNTER_INVALID];
}

void main() {
  const uint wg = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  const uint group_count = (pc.count + GLINT_COMPACT_GROUP - 1u) / GLINT_COMPACT_GROUP;
  const uint tiles = (group_count + pc.tile_groups - 1u) / pc.tile_groups;
  const uint t = gl_LocalInvocationIndex;
  if (t < 5u) s_totals[t] = 0u;
  if (t == 0u) s_first = 0u;
  barrier();
  if (wg == 0u) write_arguments(tiles);  // uniform in the workgroup
  const uint g0 = wg * kGroups;
  if (g0 >= group_count) return;  // uniform in the workgroup
  const uint ng = min(kGroups, group_count - g0);
  const uint tile = g0 / pc.tile_groups;
  uint before = 0u;  // this invocation's share of the earlier tiles' totals
  for (uint k = t; k < tile; k += GLINT_COMPACT_GROUP) before += groups[k * pc.tile_groups].w;
  if (t < ng) {
    const uvec4 g = groups[g0 + t];
    s_mask[t] = g.xy;
    if (t == 0u) before += g.z;  // the first group's slot within its tile
  }
  if (before != 0u) atomicAdd(s_first, before);
  barrier();
  const uint bit = t & 31u;
  uint n = 0u;  // emitted items of the groups before k
  for (uint k = 0u; k < ng; ++k) {
    const uvec2 m = s_mask[k];
    const uint word = t < 32u ? m.x : m.y;
    if (((word >> bit) & 1u) != 0u) {
      const uint rank = uint(bitCount(word & ((1u << bit) - 1u))) + (t < 32u ? 0u : uint(bitCount(m.x)));
      s_item[n + rank] = (g0 + k) * GLINT_COMPACT_GROUP + t;
    }
    n += uint(bitCount(m.x) + bitCount(m.y));
  }
  barrier();
  const uint first = s_first;
  const uint kept = first >= pc.capacity ? 0u : min(n, pc.capacity - first);
  const uint pw = pc.payload_words;
  if (pw == 0u) {  // uniform: a push constant
    for (uint d = t; d < kept; d += GLINT_COMPACT_GROUP) list[first + d] = s_item[d];
    return;
  }
  // Fewer than 2^30 words (list and payload buffers fit maxStorageBufferRange): no wrap.
  const uint words = kept * pw, dst = first * pw;
  for (uint d = t; d < words; d += GLINT_COMPACT_GROUP) {
    const uint k = d / pw;
    list[dst + d] = payloads[s_item[k] * pw + (d - k * pw)];
  }
}
