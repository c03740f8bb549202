#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Upsample and accumulate by gather, level_k += Up(accumulated level k+1) in place (bloom_up.comp),
// where level k is exactly twice level k+1 on both axes and the filter is separable (cod13,
// gauss9): one invocation per 2x2 group of 2x2 blocks of level k (bloom_up_2x.glsl, up_2x_quad()), each reading and writing
// only its own texels: no atomics, no shared memory, no barrier.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D smaller;
layout(binding = 1, DST_FORMAT) uniform image2D level;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_up_2x.glsl"

void main() {
  const ivec2 k0 = 2 * ivec2(gl_GlobalInvocationID.xy);  // the first of its 2x2 blocks' texels of level k+1
  const ivec2 size1 = ivec2(p.src_width, p.src_height);
  if (any(greaterThanEqual(k0, size1))) return;
  vec3 a[16];
  up_2x_quad(smaller, size1, k0, p.radius, a);
  // Blocks past level k+1's last row or column (odd level sizes) are skipped.
  [[unroll]] for (int by = 0; by < 2; ++by) {
    [[unroll]] for (int bx = 0; bx < 2; ++bx) {
      if (any(greaterThanEqual(k0 + ivec2(bx, by), size1))) continue;
      [[unroll]] for (int ey = 0; ey < 2; ++ey) {
        [[unroll]] for (int ex = 0; ex < 2; ++ex) {
          const ivec2 xy = 2 * (k0 + ivec2(bx, by)) + ivec2(ex, ey);
          imageStore(level, xy, vec4(imageLoad(level, xy).rgb + a[(2 * by + ey) * 4 + 2 * bx + ex], 1.0));
        }
      }
    }
  }
}
