#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Dual-filter upsample (Bjørge 2015; docs/BLUR.md, "dual"): four edge taps at +-o (weight 1) and
// four diagonal taps at +-o/2 (weight 2), over 12, gathered from the smaller level at the mapped
// position: each output texel reads, nothing scatters, no atomics, no blending.
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
  float h = 0.5 * o;
  vec4 edges = src_bilinear(c + vec2(-o, 0.0)) + src_bilinear(c + vec2(o, 0.0)) +
               src_bilinear(c + vec2(0.0, -o)) + src_bilinear(c + vec2(0.0, o));
  vec4 diagonals = src_bilinear(c + vec2(-h, -h)) + src_bilinear(c + vec2(h, -h)) +
                   src_bilinear(c + vec2(-h, h)) + src_bilinear(c + vec2(h, h));
  imageStore(dst, xy, (edges + 2.0 * diagonals) / 12.0);
}
