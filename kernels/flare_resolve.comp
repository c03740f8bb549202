#version 460
#extension GL_GOOGLE_include_directive : require
// Adds the lens-flare light that flare_splat.comp accumulated to the HDR image (issue 5 "Compute
// path"), one workgroup per tile. Tiles no sprite touched return at once, leaving the image's
// texels untouched (bit-identical). The kernel leaves the accumulation and the tile flags at zero
// for the next frame (GPU counters reset themselves, STYLE rule 14). Alpha is kept.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "flare_params.h"

#ifndef DST_FORMAT
#define DST_FORMAT rgba16f
#endif

layout(std430, binding = 0) buffer Accum { uint accum[]; };
layout(std430, binding = 1) buffer TileFlags { uint tile_flags[]; };
layout(binding = 2, DST_FORMAT) uniform image2D color;
layout(push_constant) uniform Push { GlintFlarePush pc; };

void main() {
  uint tile = gl_WorkGroupID.y * pc.tiles_x + gl_WorkGroupID.x;
  bool touched = tile_flags[tile] != 0u;
  barrier();  // every invocation has read the flag before it is cleared
  if (!touched) return;
  if (gl_LocalInvocationIndex == 0u) tile_flags[tile] = 0u;
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= uint(pc.viewport_w) || p.y >= uint(pc.viewport_h)) return;
  uint base = (p.y * uint(pc.viewport_w) + p.x) * 3u;
  vec3 add = vec3(uintBitsToFloat(accum[base]), uintBitsToFloat(accum[base + 1u]), uintBitsToFloat(accum[base + 2u]));
  if (add == vec3(0.0)) return;
  accum[base] = 0u;
  accum[base + 1u] = 0u;
  accum[base + 2u] = 0u;
  vec4 c = imageLoad(color, ivec2(p));
  imageStore(color, ivec2(p), vec4(c.rgb + add, c.a));
}
