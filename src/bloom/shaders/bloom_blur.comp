#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// One direction of a separable 9-tap Gaussian (binomial weights, sigma about 1.5) at a
// pyramid level, taps at t * radius texels read by linear interpolation (docs/BLOOM.md, gauss9).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D src;
layout(binding = 1, DST_FORMAT) uniform writeonly image2D dst;

#include "bloom_params.h"
#include "image_io.glsl"
layout(push_constant) uniform Push { BloomPush p; };

const float kWeights[5] = float[5](0.2270270270, 0.1945945946, 0.1216216216, 0.0540540541, 0.0162162162);

vec3 linear_along(ivec2 xy, float offset, bool vertical, ivec2 size) {
  float q = float(vertical ? xy.y : xy.x) + offset;
  float f = floor(q);
  float w = q - f;
  ivec2 step_dir = vertical ? ivec2(0, 1) : ivec2(1, 0);
  ivec2 base = vertical ? ivec2(xy.x, int(f)) : ivec2(int(f), xy.y);
  vec3 a = fetch_clamped(src, base, size).rgb;
  vec3 b = fetch_clamped(src, base + step_dir, size).rgb;
  return mix(a, b, w);
}

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(p.dst_width, p.dst_height);
  if (any(greaterThanEqual(xy, size))) return;
  bool vertical = (p.flags & GLINT_BLOOM_FLAG_VERTICAL) != 0u;
  vec3 sum = kWeights[0] * fetch_clamped(src, xy, size).rgb;
  for (int t = 1; t < 5; ++t) {
    float o = float(t) * p.radius;
    sum += kWeights[t] * (linear_along(xy, o, vertical, size) + linear_along(xy, -o, vertical, size));
  }
  imageStore(dst, xy, vec4(sum, 1.0));
}
