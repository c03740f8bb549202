#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// One direction of the separable Gaussian for radii above the fused kernel's (docs/BLUR.md,
// "separable"): a workgroup loads a segment of one line plus an apron of R texels into shared
// memory once and convolves it with the taps from the tap buffer. Same-size source and output.
layout(local_size_x_id = 0, local_size_y_id = 1) in;  // run as (SEGMENT, 1)
layout(constant_id = 2) const int MAX_RADIUS = 192;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;
layout(binding = 2, std430) readonly buffer Taps { float taps[]; };  // w[0..R]

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

const int SEGMENT = int(gl_WorkGroupSize.x);
shared vec4 s_line[SEGMENT + 2 * MAX_RADIUS];

void main() {
  bool vertical = (p.flags & GLINT_BLUR_FLAG_VERTICAL) != 0u;
  int radius = int(p.tap_count);
  int length = vertical ? p.dst_height : p.dst_width;
  // Workgroup (gx, gy): segment gx along the axis, line gy across it.
  int start = int(gl_WorkGroupID.x) * SEGMENT;
  int line = int(gl_WorkGroupID.y);
  int local = int(gl_LocalInvocationID.x);
  for (int i = local; i < SEGMENT + 2 * radius; i += SEGMENT) {
    int a = clamp(start - radius + i, 0, length - 1);
    s_line[i] = src_texel(vertical ? ivec2(line, a) : ivec2(a, line));
  }
  barrier();
  int at = start + local;
  if (at >= length) return;
  int c = local + radius;
  vec4 sum = taps[0] * s_line[c];
  for (int t = 1; t <= radius; ++t) sum += taps[t] * (s_line[c - t] + s_line[c + t]);
  imageStore(dst, vertical ? ivec2(line, at) : ivec2(at, line), sum);
}
