#version 460
#extension GL_GOOGLE_include_directive : require
// The compute path's launch arguments (the compute path is launched with
// vkCmdDispatchIndirect, so the host never reads the count back): one invocation reads the instance count the compaction wrote and
// writes the gather's VkDispatchIndirectCommand: every screen tile when any instance is visible,
// no workgroup at all when none is (so a frame without visible lights costs the gather nothing).
// The count never leaves the GPU.
layout(local_size_x = 1) in;

#include "flare_params.h"

layout(std430, binding = 0) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(std430, binding = 1) writeonly buffer Args { uint args[3]; };              // VkDispatchIndirectCommand
layout(push_constant) uniform Push { GlintFlareGatherArgsPush pc; };

void main() {
  uint count = indirect_words[pc.indirect_word];  // GlintFlareIndirect::instance_count
  args[0] = count > 0u ? pc.tiles_x : 0u;
  args[1] = pc.tiles_y;
  args[2] = 1u;
}
