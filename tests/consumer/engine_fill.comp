// The example engine's own compute pass (not glint's): draws the frame's HDR colour (a dim
// background and one bright disc) and depth (far everywhere but one near rectangle), and evaluates
// glint's LOD function from the installed GLSL header for a list of queries, as an engine's
// material shader would. Built with glslangValidator -I<glint prefix>/include.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "glint/gpu/lod.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba16f) uniform writeonly image2D hdr;
layout(binding = 1, r32f) uniform writeonly image2D depth;
layout(std430, binding = 2) readonly buffer Queries { GlintLodQuery queries[]; };
layout(std430, binding = 3) writeonly buffer Levels { float levels[]; };

// 80 bytes; main.cpp's FillPush has the same std430 layout.
layout(push_constant) uniform Push {
  GlintLodAtlas atlas;
  ivec2 size;
  ivec2 disc_center;  // pixel corner the disc is centred on
  ivec4 occluder;     // x0, y0, x1, y1 (exclusive) of the near rectangle
  float background;
  float disc_value;
  float disc_radius;
  uint query_count;
} pc;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  vec2 d = vec2(p) + 0.5 - vec2(pc.disc_center);
  float v = dot(d, d) <= pc.disc_radius * pc.disc_radius ? pc.disc_value : pc.background;
  imageStore(hdr, p, vec4(v, v, v, 1.0));
  bool near = all(greaterThanEqual(p, pc.occluder.xy)) && all(lessThan(p, pc.occluder.zw));
  imageStore(depth, p, vec4(near ? 0.2 : 1.0, 0.0, 0.0, 0.0));
  uint i = uint(p.y) * uint(pc.size.x) + uint(p.x);
  if (i < pc.query_count) levels[i] = glint_lod(queries[i], pc.atlas);
}
