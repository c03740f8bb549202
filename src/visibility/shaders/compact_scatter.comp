#version 460
#extension GL_GOOGLE_include_directive : require
// The ordered compaction's scatter of fixed-size payloads (the object cull's list; compact.glsl):
// one workgroup of GLINT_COMPACT_GROUP invocations per 64-item group. The group's emitted items
// take the consecutive slots first .. first + n - 1 (first: the tile's first slot + the group's
// slot within the tile), in item order, so the output holds the emitted items in increasing index
// on every run. Invocation t of an emitted item records its item in s_item[rank]; the group's
// destination words are then copied cooperatively, invocation t taking words t, t + 64, ...:
// consecutive invocations write consecutive words and read each item's consecutive payload words,
// so both sides coalesce whatever the payload size (an invocation per item would write
// payload_words-strided words); an index list (no payload) needs no copy loop: each emitted
// invocation writes its index to its slot. Slots at or beyond the capacity are not written (the
// overflow keeps the smallest indices). A slot receives the item's payload_words words (step[0] > 0) or its index.
layout(local_size_x_id = 0, local_size_y_id = 1) in;  // GLINT_COMPACT_GROUP x 1

#define COMPACT_GROUPS_BINDING 0
#define COMPACT_GROUPS_READONLY
#define COMPACT_NO_SCAN
#include "compact.glsl"

layout(std430, binding = 1) readonly buffer Payloads { uint payloads[]; };  // payload words per item
layout(std430, binding = 2) writeonly buffer List { uint list[]; };         // max(1, payload words) per slot
layout(push_constant) uniform Push { GlintCompactPush pc; };                // step[0]: payload words

shared uint s_item[GLINT_COMPACT_GROUP];  // the group's emitted items (bit index), in order

void main() {
  const uint group = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  const uint group_count = (pc.count + GLINT_COMPACT_GROUP - 1u) / GLINT_COMPACT_GROUP;
  if (group >= group_count) return;  // uniform in the workgroup
  const uint t = gl_LocalInvocationIndex;
  const uvec4 g = groups[group];
  const uint first = groups[group / pc.tile_groups * pc.tile_groups].w + g.z;
  const uint word = t < 32u ? g.x : g.y;
  const uint bit = t & 31u;
  const bool emitted = ((word >> bit) & 1u) != 0u;
  const uint rank = uint(bitCount(word & ((1u << bit) - 1u))) + (t < 32u ? 0u : uint(bitCount(g.x)));
  const uint pw = pc.step[0];
  const uint base = group * GLINT_COMPACT_GROUP;
  if (pw == 0u) {  // uniform: a push constant
    // Indices: the emitted invocation writes its own slot (consecutive ranks, so consecutive
    // words); no shared list and no barrier.
    if (emitted && first + rank < pc.capacity) list[first + rank] = base + t;
    return;
  }
  if (emitted) s_item[rank] = t;
  barrier();
  const uint n = uint(bitCount(g.x) + bitCount(g.y));
  const uint kept = first >= pc.capacity ? 0u : min(n, pc.capacity - first);
  // Fewer than 2^30 words (list and payload buffers fit maxStorageBufferRange): no wrap.
  const uint words = kept * pw, dst = first * pw;
  for (uint d = t; d < words; d += GLINT_COMPACT_GROUP) {
    const uint k = d / pw;
    list[dst + d] = payloads[(base + s_item[k]) * pw + (d - k * pw)];
  }
}
