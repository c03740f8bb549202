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

layout(std430, binding = 1) readonly buffer Lights { GlintFlareLight lights[]; };
layout(std430, binding = 2) readonly buffer Records { vec4 records[]; };  // centre.xy, fraction, ndc z
layout(std430, binding = 3) writeonly buffer Instances { GlintFlareInstance instances[]; };
layout(std430, binding = 4) writeonly buffer Results { GlintFlareLightResult results[]; };
layout(push_constant) uniform Push { GlintCullCompactPush pc; };

void main() {
  const uint i = (gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
  if (i >= pc.count) return;
  uint slot;
  if (!compact_slot(i, pc.tile_groups, slot)) return;
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
