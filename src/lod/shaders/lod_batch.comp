#version 460
#extension GL_GOOGLE_include_directive : require
// Evaluates the atlas-aware LOD (include/glint/gpu/lod_impl.h, docs/LOD.md; Vulkan spec "LOD
// Operation") for N queries: one invocation per query.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/lod.glsl"

layout(std430, binding = 0) readonly buffer Queries { GlintLodQuery queries[]; };
layout(std430, binding = 1) writeonly buffer Levels { float levels[]; };
layout(push_constant) uniform Push {
  GlintLodAtlas atlas;
  uint count;
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  levels[i] = glint_lod(queries[i], atlas);
}
