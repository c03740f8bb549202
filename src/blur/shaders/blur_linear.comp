#version 460
#extension GL_GOOGLE_include_directive : require
// One direction of the separable Gaussian with linear sampling (docs/BLUR.md, "separable,
// linear sampling"; Rákos 2010): taps t and t+1 are paired into one fetch through the hardware
// bilinear sampler at their weighted mean offset, so 2R+1 taps cost R+1 fetches (9 in 5). The
// sampler's clamp-to-edge addressing reproduces the clamped fetches; its sub-texel weight
// precision is this variant's error, which tests and benchmarks report.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform sampler2D src;  // linear filter, clamp to edge, normalized coordinates
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;
layout(binding = 2, std430) readonly buffer Taps { vec2 taps[]; };  // (offset, weight); taps[0] = (0, w0)

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(p.dst_width, p.dst_height);
  if (any(greaterThanEqual(xy, size))) return;
  vec2 inv = 1.0 / vec2(size);
  vec2 step_dir = (p.flags & GLINT_BLUR_FLAG_VERTICAL) != 0u ? vec2(0.0, inv.y) : vec2(inv.x, 0.0);
  vec2 uv = (vec2(xy) + 0.5) * inv;
  vec4 sum = taps[0].y * textureLod(src, uv, 0.0);
  for (uint i = 1u; i <= p.tap_count; ++i) {
    vec2 o = taps[i].x * step_dir;
    sum += taps[i].y * (textureLod(src, uv - o, 0.0) + textureLod(src, uv + o, 0.0));
  }
  imageStore(dst, xy, sum);
}
