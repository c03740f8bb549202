#version 460
#extension GL_GOOGLE_include_directive : require
// The ordered compaction's scatter of fixed-size payloads (the object cull's list; compact.glsl):
// one workgroup of GLINT_COMPACT_GROUP invocations per GLINT_COMPACT_SCATTER_GROUPS consecutive
// 64-item groups. Consecutive groups' emitted items take consecutive slots (the scan is one
// exclusive prefix sum over the groups in item order), so the workgroup's items go to the one
// range first .. first + n - 1 (first: the first group's tile's first slot + its slot within the
// tile), in item order, on every run.
// 1. Invocation k < groups loads group k's mask (coalesced), invocation 0 also its tile's first
//    slot: every load of the workgroup is issued before the first barrier.
// 2. For each group in order, invocation t of an emitted item writes the item's index into the
//    shared list at (items of the earlier groups) + (its rank in the mask).
// 3. The range is copied cooperatively, invocation t taking words t, t + 64, ...: consecutive
//    invocations write consecutive words and read each item's consecutive payload words, and all
//    of the workgroup's payload loads are independent (one round trip to memory for up to 1024
//    items, where one workgroup per group paid one per 64 items and the launch of 16 times as
//    many workgroups). An index list (no payload) is the shared list itself.
// Slots at or beyond the capacity are not written (the overflow keeps the smallest indices). A
// slot receives the item's payload_words words (step[0] > 0) or its index.
// Workgroup 0 also zeroes the first step[2] words of binding 3, the user's per-run counters (the
// object cull's tile counts, object_cull.comp): this dispatch runs after every cull whatever the
// counts held, so a count left wrong (a cull cut short) is whole again for the next cull.
layout(local_size_x_id = 0, local_size_y_id = 1) in;  // GLINT_COMPACT_GROUP x 1

#define COMPACT_GROUPS_BINDING 0
#define COMPACT_GROUPS_READONLY
#define COMPACT_NO_SCAN
#include "compact.glsl"

layout(std430, binding = 1) restrict readonly buffer Payloads { uint payloads[]; };  // payload words per item
layout(std430, binding = 2) restrict writeonly buffer List { uint list[]; };         // max(1, payload words) per slot
layout(std430, binding = 3) restrict writeonly buffer Clear { uint clear_words[]; };  // step[2] words zeroed
layout(push_constant) uniform Push { GlintCompactPush pc; };  // step[0]: payload words

const uint kGroups = GLINT_COMPACT_SCATTER_GROUPS;
shared uvec2 s_mask[kGroups];
shared uint s_first;                                  // the slot of the workgroup's first emitted item
shared uint s_item[kGroups * GLINT_COMPACT_GROUP];    // the workgroup's emitted items, in order

void main() {
  const uint wg = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  const uint group_count = (pc.count + GLINT_COMPACT_GROUP - 1u) / GLINT_COMPACT_GROUP;
  const uint g0 = wg * kGroups;
  const uint t = gl_LocalInvocationIndex;
  if (wg == 0u) {
    for (uint k = t; k < pc.step[2]; k += GLINT_COMPACT_GROUP) clear_words[k] = 0u;
  }
  if (g0 >= group_count) return;  // uniform in the workgroup
  const uint ng = min(kGroups, group_count - g0);
  if (t < ng) {
    const uvec4 g = groups[g0 + t];
    s_mask[t] = g.xy;
    if (t == 0u) s_first = groups[g0 / pc.tile_groups * pc.tile_groups].w + g.z;
  }
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
  const uint pw = pc.step[0];
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
