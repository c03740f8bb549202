#version 460
#extension GL_GOOGLE_include_directive : require
// Asks the device's own sampler for the LOD of each query (docs/LOD.md, "Measured on
// hardware"): textureGrad on an atlas whose level i holds the value i, trilinear, anisotropy off,
// so the returned value is the level the sampler used. The sub-texture derivatives are carried to
// atlas UV by the chain rule: d(atlas_u) = d(u) * tex_w / atlas_w.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/lod.glsl"

layout(binding = 0) uniform sampler2D level_atlas;
layout(std430, binding = 1) readonly buffer Queries { GlintLodQuery queries[]; };
layout(std430, binding = 2) writeonly buffer Levels { float levels[]; };
layout(push_constant) uniform Push {
  GlintLodAtlas atlas;
  uint count;
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  GlintLodQuery q = queries[i];
#ifdef GLINT_PROBE_EXPLICIT_LOD
  // The explicit-level variant: (dudx, dvdx) is the atlas UV and dudy the level, so the value read
  // back shows how the device blends two levels for a given fractional level (mipmapPrecisionBits).
  levels[i] = textureLod(level_atlas, vec2(q.dudx, q.dvdx), q.dudy).r;
#else
  vec2 atlas_size = vec2(atlas.atlas_w, atlas.atlas_h);
  vec2 scale = vec2(q.tex_w, q.tex_h) / atlas_size;
  vec2 centre = (vec2(q.off_x, q.off_y) + 0.5 * vec2(q.tex_w, q.tex_h)) / atlas_size;
  levels[i] = textureGrad(level_atlas, centre, vec2(q.dudx, q.dvdx) * scale, vec2(q.dudy, q.dvdy) * scale).r;
#endif
}
