#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Upsample and accumulate by gather, level_k += Up(accumulated level k+1) in place (bloom_up.comp),
// where level k is exactly twice level k+1 on both axes and the filter is separable (cod13,
// gauss9): one invocation per 2x2 block of level k (bloom_up_2x.glsl); on GPUs the sums go through
// shared memory (one barrier) so that level k is read and written in the order of a copy
// (COPY_ORDER). Each texel is read and written by one invocation: no atomics.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D smaller;
layout(binding = 1, DST_FORMAT) uniform image2D level;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_up_2x.glsl"

void main() {
  const ivec2 k = ivec2(gl_GlobalInvocationID.xy);  // the block's texel of level k+1
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  // The texels of level k this invocation stores (up_2x_out), first: their latency overlaps the
  // reads and sums. Even sizes: a texel is inside when its block is.
  vec3 o[4];
  ivec2 at[4];
  uint ti[4];
  [[unroll]] for (uint j = 0u; j < 4u; ++j) {
    at[j] = up_2x_out(j, k, ti[j]);
    o[j] = all(lessThan(at[j], size)) ? imageLoad(level, at[j]).rgb : vec3(0.0);
  }
  vec3 a[4] = vec3[4](vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));
  if (all(lessThan(2 * k, size))) up_2x_block(smaller, ivec2(p.src_width, p.src_height), k, p.radius, a);
  up_2x_exchange(a, ti);
  [[unroll]] for (uint j = 0u; j < 4u; ++j) {
    if (all(lessThan(at[j], size))) imageStore(level, at[j], vec4(o[j] + a[j], 1.0));
  }
}
