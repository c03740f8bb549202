#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Upsample and accumulate by gather, level_k += Up(accumulated level k+1) in place (bloom_up.comp),
// where level k is exactly twice level k+1 on both axes and the filter is separable (cod13,
// gauss9): one invocation per 2x2 block of level k (bloom_up_2x.glsl), each reading and writing
// only its own texels: no atomics, no shared memory, no barrier.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D smaller;
layout(binding = 1, DST_FORMAT) uniform image2D level;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_up_2x.glsl"

void main() {
  const ivec2 k = ivec2(gl_GlobalInvocationID.xy);  // the block's texel of level k+1
  const ivec2 xy = 2 * k;                            // its first texel of level k
  if (any(greaterThanEqual(xy, ivec2(p.dst_width, p.dst_height)))) return;  // even sizes: whole blocks
  // Own texels first: their latency overlaps the reads and sums.
  const vec3 o00 = imageLoad(level, xy).rgb, o10 = imageLoad(level, xy + ivec2(1, 0)).rgb;
  const vec3 o01 = imageLoad(level, xy + ivec2(0, 1)).rgb, o11 = imageLoad(level, xy + ivec2(1, 1)).rgb;
  vec3 a[4];
  up_2x_block(smaller, ivec2(p.src_width, p.src_height), k, p.radius, a);
  imageStore(level, xy, vec4(o00 + a[0], 1.0));
  imageStore(level, xy + ivec2(1, 0), vec4(o10 + a[1], 1.0));
  imageStore(level, xy + ivec2(0, 1), vec4(o01 + a[2], 1.0));
  imageStore(level, xy + ivec2(1, 1), vec4(o11 + a[3], 1.0));
}
