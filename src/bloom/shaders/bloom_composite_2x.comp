#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// The composite out = scene + intensity / N * Up(A0) (docs/BLOOM.md "Composite") where the output
// is exactly twice level 0 on both axes and the filter is separable (cod13, gauss9): one
// invocation per 2x2 group of 2x2 blocks of outputs (bloom_up_2x.glsl, up_2x_quad()), no shared memory and no barrier, so
// that the kernel streams the scene like a copy. Each output follows composite_texel() (bloom.glsl).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1) uniform texture2D level0;
#include "dst_image.glsl"
DST_LAYOUT(2) uniform writeonly image2D result;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_up_2x.glsl"

void main() {
  const ivec2 k0 = 2 * ivec2(gl_GlobalInvocationID.xy);  // the first of its 2x2 blocks' level-0 texels
  const ivec2 size0 = ivec2(p.src_width, p.src_height);
  if (any(greaterThanEqual(k0, size0))) return;
  vec3 a[16];
  up_2x_quad(level0, size0, k0, p.radius, a);
  // Blocks past level 0's last row or column (odd level sizes) are skipped.
  [[unroll]] for (int by = 0; by < 2; ++by) {
    [[unroll]] for (int bx = 0; bx < 2; ++bx) {
      if (any(greaterThanEqual(k0 + ivec2(bx, by), size0))) continue;
      [[unroll]] for (int ey = 0; ey < 2; ++ey) {
        [[unroll]] for (int ex = 0; ex < 2; ++ex) {
          const ivec2 xy = 2 * (k0 + ivec2(bx, by)) + ivec2(ex, ey);
          imageStore(result, xy, composite_texel(texelFetch(scene, xy, 0), a[(2 * by + ey) * 4 + 2 * bx + ex],
                                                 p.composite_scale));
        }
      }
    }
  }
}
