#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// The composite out = scene + intensity / N * Up(A0) (docs/BLOOM.md "Composite") where the output
// is exactly twice level 0 on both axes and the filter is separable (cod13, gauss9): one
// invocation per 2x2 block of outputs (bloom_up_2x.glsl); on GPUs the outputs go through shared
// memory (one barrier) so that the scene is read and the result written in the order of a copy
// (COPY_ORDER). Each output follows composite_texel() (bloom.glsl).
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
  const ivec2 k = ivec2(gl_GlobalInvocationID.xy);  // the block's level-0 texel
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  // The scene at the four outputs this invocation stores (up_2x_out), first: their latency
  // overlaps the level-0 reads and sums. Even sizes: an output is inside when its block is.
  vec4 s[4];
  ivec2 at[4];
  uint ti[4];
  [[unroll]] for (uint j = 0u; j < 4u; ++j) {
    at[j] = up_2x_out(j, k, ti[j]);
    s[j] = all(lessThan(at[j], size)) ? texelFetch(scene, at[j], 0) : vec4(0.0);
  }
  vec3 a[4] = vec3[4](vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));
  if (all(lessThan(2 * k, size))) up_2x_block(level0, ivec2(p.src_width, p.src_height), k, p.radius, a);
  up_2x_exchange(a, ti);
  [[unroll]] for (uint j = 0u; j < 4u; ++j) {
    if (all(lessThan(at[j], size))) imageStore(result, at[j], composite_texel(s[j], a[j], p.composite_scale));
  }
}
