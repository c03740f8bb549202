#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Copies (and converts between RGBA16F and RGBA32F) one image into another: what bloom records
// when intensity is 0, so the output equals the input bit for bit when the formats match.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(xy, ivec2(p.dst_width, p.dst_height)))) return;
  imageStore(dst, xy, texelFetch(src, xy, 0));
}
