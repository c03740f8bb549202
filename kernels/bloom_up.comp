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

vec3 source_texel(ivec2 ij) { return vec3(0.0); }  // unused: upsample reads `smaller` directly

#include "bloom.glsl"
#include "bloom_up_tiled.glsl"

void main() {
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  ivec2 origin = block_origin();
  vec3 own[4];
  for (int k = 0; k < 4; ++k) {  // issued first, as in bloom_composite
    ivec2 xy = origin + ivec2(k & 1, k >> 1);  // only own texels: the others are being written
    own[k] = all(lessThan(xy, dst_size)) ? imageLoad(level, xy).rgb : vec3(0.0);
  }
  vec3 up[4];
  upsample_block(smaller, ivec2(p.src_width, p.src_height), dst_size, p.radius, up);
  for (int k = 0; k < 4; ++k) {
    ivec2 xy = origin + ivec2(k & 1, k >> 1);
    if (all(lessThan(xy, dst_size))) imageStore(level, xy, vec4(own[k] + up[k], 1.0));
  }
}
