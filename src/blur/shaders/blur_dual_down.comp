#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Dual-filter downsample (Bjørge 2015; docs/BLUR.md, "dual"): the centre tap weighs 4, the four
// diagonal taps at +-o weigh 1, over 8, each a bilinear read of the larger level at the mapped
// position.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"
#include "image_io.glsl"

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(p.dst_width, p.dst_height);
  if (any(greaterThanEqual(xy, size))) return;
  vec2 c = source_position(xy);
  float o = p.offset;
  vec4 sum = 4.0 * src_bilinear(c);
  sum += src_bilinear(c + vec2(-o, -o)) + src_bilinear(c + vec2(o, -o));
  sum += src_bilinear(c + vec2(-o, o)) + src_bilinear(c + vec2(o, o));
  imageStore(dst, xy, sum * 0.125);
}
