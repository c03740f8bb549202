#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The pyramid method's last step (docs/BLUR.md, "pyramid"): the blurred level brought to full
// resolution at the same normalized coordinate by a uniform cubic B-spline (4x4 texels, exact
// fp32 weights). Unlike bilinear magnification it leaves no kinks at level texel centres (C2),
// and its variance is part of the method's sigma bookkeeping.
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
  vec2 q = source_position(xy);
  vec2 f = floor(q);
  vec4 wx = bspline_weights(q.x - f.x);
  vec4 wy = bspline_weights(q.y - f.y);
  ivec2 i0 = ivec2(f) - 1;
  vec4 sum = vec4(0.0);
  for (int j = 0; j < 4; ++j) {
    vec4 row = wx.x * src_texel(i0 + ivec2(0, j)) + wx.y * src_texel(i0 + ivec2(1, j)) +
               wx.z * src_texel(i0 + ivec2(2, j)) + wx.w * src_texel(i0 + ivec2(3, j));
    sum += wy[j] * row;
  }
  imageStore(dst, xy, sum);
}
