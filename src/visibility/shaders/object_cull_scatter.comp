#version 460
#extension GL_GOOGLE_include_directive : require
// The last dispatch of the object cull's ordered compaction (as light_cull_scatter.comp): one
// invocation per object. An emitted object (its bit set in its workgroup's mask) takes the slot
// first slot of its tile (object_cull_scan.comp) + the group's slot within the tile
// (object_cull_scan_tiles.comp) + emitted objects before it in the mask, so
// the list holds the emitted objects in increasing index on every run; slots at or beyond the
// capacity are not written (the overflow keeps the smallest indices). The slot receives the
// object's payload words (payload_words > 0) or its index.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "object_cull_params.h"

layout(std430, binding = 0) readonly buffer Groups {
  uint counters[GLINT_OBJECT_HEADER_WORDS];
  uvec4 groups[];  // emitted mask (x, y), slot within the tile (z), tile's first slot on its first group (w)
};
layout(std430, binding = 1) readonly buffer Payloads { uint payloads[]; };  // payload_words per object
layout(std430, binding = 2) writeonly buffer List { uint list[]; };         // max(1, payload_words) per slot
layout(push_constant) uniform Push { GlintObjectCompactPush pc; };

void main() {
  const uint i = (gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (i >= pc.count) return;
  const uvec4 g = groups[i / GLINT_OBJECT_GROUP];
  const uint b = i % GLINT_OBJECT_GROUP;
  const uint word = b < 32u ? g.x : g.y;
  const uint bit = b & 31u;
  if (((word >> bit) & 1u) == 0u) return;
  // The tile's first slot (object_cull_scan.comp) + the group's within the tile + the bits before.
  const uint tile_first = groups[(i / GLINT_OBJECT_GROUP) / pc.tile_groups * pc.tile_groups].w;
  const uint slot = tile_first + g.z + uint(bitCount(word & ((1u << bit) - 1u))) + (b < 32u ? 0u : uint(bitCount(g.x)));
  if (slot >= pc.capacity) return;
  if (pc.payload_words == 0u) {
    list[slot] = i;
    return;
  }
  const uint src = i * pc.payload_words, dst = slot * pc.payload_words;
  for (uint w = 0u; w < pc.payload_words; ++w) list[dst + w] = payloads[src + w];
}
