#version 460
#extension GL_GOOGLE_include_directive : require
// The last dispatch of the light cull's ordered compaction (compact.glsl): one invocation per
// light. A visible light (its bit set in its workgroup's mask, light_cull.comp) takes the slot
// compact_slot gives (the tile's first slot + the group's slot within the tile + visible lights
// before it in the mask), so visible lights fill the instance buffer in increasing light index on
// every run: no atomic decides the order. Slots at or beyond the capacity are not written; those
// lights become GLINT_FLARE_OVERFLOW, so the instances kept are the visible lights with the
// smallest indices. Writes the per-light result of visible lights (the cull wrote the others').
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/flare_types.h"
#define COMPACT_GROUPS_BINDING 0
#define COMPACT_GROUPS_READONLY
#define COMPACT_NO_SCAN
#include "compact.glsl"
#include "light_cull_params.h"

// GlintFlareLight[] and GlintFlareInstance[] as vec4 words (48 bytes each, three words): 16-byte
// loads and stores instead of 4-byte ones (the structs' members are 4-byte aligned).
layout(std430, binding = 1) readonly buffer Lights { vec4 light_words[]; };
layout(std430, binding = 2) readonly buffer Records { vec4 records[]; };  // centre.xy, fraction, ndc z
layout(std430, binding = 3) writeonly buffer Instances { uvec4 instance_words[]; };  // integer words: bits stored as they are
layout(std430, binding = 4) writeonly buffer Results { GlintFlareLightResult results[]; };
layout(push_constant) uniform Push { GlintCullCompactPush pc; };
#define GLINT_CULL_STORES_INSTANCES
#include "light_cull_outputs.glsl"

void main() {
  const uint i = (gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (i >= pc.count) return;
  uint slot;
  if (!compact_slot(i, pc.tile_groups, slot)) return;
  const vec4 record = records[i];
  uint state = GLINT_FLARE_VISIBLE;
  if (slot < pc.capacity) {
    // Light words: (position, intensity), (colour, size_px), (element, enabled, reserved x2).
    cull_store_instance(slot, i, record, light_words[3u * i], light_words[3u * i + 1u],
                        floatBitsToUint(light_words[3u * i + 2u].x));
  } else {
    state = GLINT_FLARE_OVERFLOW;
  }
  if ((pc.flags & GLINT_CULL_WRITE_RESULTS) != 0u) {
    GlintFlareLightResult r;
    r.visible_fraction = state == GLINT_FLARE_VISIBLE ? record.z : 0.0;
    r.culled = state;
    results[i] = r;
  }
}
