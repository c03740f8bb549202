#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Pyramid level k-1 -> level k with the filter's downsample (docs/BLOOM.md "Downsample";
// cod13: Jimenez 2014, dual: Bjørge 2015, gauss9: area average before the 9-tap blur).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D src;
layout(binding = 1, DST_FORMAT) uniform writeonly image2D dst;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_down_tiled.glsl"

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  bool inside = all(lessThan(xy, dst_size));
  BloomSource s = BloomSource(ivec2(p.src_width, p.src_height), false, 0.0, 0.0);
  vec3 c = downsample_any(src, s, xy, dst_size, inside, false);
  if (inside) imageStore(dst, xy, vec4(c, 1.0));
}
