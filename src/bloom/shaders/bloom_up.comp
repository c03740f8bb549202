#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Upsample and accumulate by gather: level_k += Up(accumulated level k+1), in place, each
// invocation reading and writing only its own texel: no atomics, no blending (docs/BLOOM.md).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D smaller;
layout(binding = 1, DST_FORMAT) uniform image2D level;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_up_tiled.glsl"

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  vec3 own = imageLoad(level, min(xy, dst_size - 1)).rgb;  // issued first, as in bloom_composite
  vec3 up = upsample_tiled(smaller, ivec2(p.src_width, p.src_height), dst_size, p.radius);
  if (any(greaterThanEqual(xy, dst_size))) return;  // after the barriers inside upsample_tiled
  imageStore(level, xy, vec4(own + up, 1.0));
}
