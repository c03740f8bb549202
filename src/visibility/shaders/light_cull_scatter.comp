#version 460
#extension GL_GOOGLE_include_directive : require
// The last dispatch of the order-preserving compaction: one invocation per light. A
// visible light (its bit set in its workgroup's mask, light_cull.comp) takes the slot
// first slot of its tile (light_cull_scan.comp) + the group's slot within the tile
// (light_cull_scan_tiles.comp) + visible lights before it in the mask (a bit
// count), so visible lights fill the instance buffer in increasing light index on every run: no
// atomic decides the order. Slots at or beyond the capacity are not written; those lights become
// GLINT_FLARE_OVERFLOW, so the instances kept are the visible lights with the smallest indices.
// Writes the per-light result of visible lights (the cull wrote the others').
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/flare_types.h"
#include "light_cull_params.h"

layout(std430, binding = 0) readonly buffer Lights { GlintFlareLight lights[]; };
layout(std430, binding = 1) readonly buffer Records { vec4 records[]; };  // centre.xy, fraction, ndc z
layout(std430, binding = 2) readonly buffer Groups {
  uint counters[GLINT_CULL_HEADER_WORDS];
  uvec4 groups[];  // visibility mask (x, y), slot within the tile (z), tile's first slot on its first group (w)
};
layout(std430, binding = 3) writeonly buffer Instances { GlintFlareInstance instances[]; };
layout(std430, binding = 4) writeonly buffer Results { GlintFlareLightResult results[]; };
layout(push_constant) uniform Push { GlintCullCompactPush pc; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  const uvec4 g = groups[i / GLINT_CULL_GROUP];
  const uint b = i % GLINT_CULL_GROUP;
  const uint word = b < 32u ? g.x : g.y;
  const uint bit = b & 31u;
  if (((word >> bit) & 1u) == 0u) return;
  const uint before = uint(bitCount(word & ((1u << bit) - 1u))) + (b < 32u ? 0u : uint(bitCount(g.x)));
  // The tile's first slot (light_cull_scan.comp) + the group's within the tile + the bits before.
  const uint slot = groups[(i / GLINT_CULL_GROUP) / pc.tile_groups * pc.tile_groups].w + g.z + before;
  const vec4 record = records[i];
  uint state = GLINT_FLARE_VISIBLE;
  if (slot < pc.capacity) {
    const GlintFlareLight light = lights[i];
    GlintFlareInstance inst;
    inst.center_x_px = record.x;
    inst.center_y_px = record.y;
    inst.size_px = light.size_px;
    inst.visible_fraction = record.z;
    inst.color_r = light.color_r;
    inst.color_g = light.color_g;
    inst.color_b = light.color_b;
    inst.intensity = light.intensity;
    inst.light_index = i;
    inst.element = light.element;
    inst.ndc_depth = record.w;
    inst.reserved = 0u;
    instances[slot] = inst;
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
