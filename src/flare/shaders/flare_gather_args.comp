#version 460
#extension GL_GOOGLE_include_directive : require
// The compute path's launch arguments (the compute path is launched with vkCmdDispatchIndirect, so
// the host never reads the count back): one invocation reads the instance count the compaction
// wrote and writes two VkDispatchIndirectCommand. The gather's (words 0..2): every screen tile when
// any instance is visible, no workgroup at all when none is (so a frame without visible lights
// costs the gather nothing). The sprite pre-pass's (words 4..6): one workgroup per
// GLINT_FLARE_SPRITES_INSTANCES instances, as rows of at most maxComputeWorkGroupCount[0] (the
// kernel takes the linear index gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x). The
// count is clamped to the bound buffers' capacity first, so a wrong count launches no more than
// the buffers can use. The count never leaves the GPU.
layout(local_size_x = 1) in;

#include "flare_params.h"

layout(std430, binding = 0) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(std430, binding = 1) writeonly buffer Args { uint args[8]; };              // 2 VkDispatchIndirectCommand
layout(push_constant) uniform Push { GlintFlareGatherArgsPush pc; };

void main() {
  uint count = min(indirect_words[pc.indirect_word], pc.capacity);  // GlintFlareIndirect::instance_count
  args[0] = count > 0u ? pc.tiles_x : 0u;
  args[1] = pc.tiles_y;
  args[2] = 1u;
  uint groups = (count + GLINT_FLARE_SPRITES_INSTANCES - 1u) / GLINT_FLARE_SPRITES_INSTANCES;
  uint x = min(groups, pc.max_groups_x);
  args[4] = x;
  args[5] = x > 0u ? (groups + x - 1u) / x : 1u;
  args[6] = 1u;
}
