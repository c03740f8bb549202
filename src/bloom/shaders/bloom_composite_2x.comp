#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// The composite out = scene + intensity / N * Up(A0) (docs/BLOOM.md "Composite") where the output
// is exactly twice level 0 on both axes and the filter is separable (cod13, gauss9): one
// invocation per 2x2 block of outputs (bloom_up_2x.glsl), no shared memory and no barrier, so
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
  const ivec2 k = ivec2(gl_GlobalInvocationID.xy);  // the block's level-0 texel
  const ivec2 xy = 2 * k;                            // its first output
  if (any(greaterThanEqual(xy, ivec2(p.dst_width, p.dst_height)))) return;  // even sizes: whole blocks
  // The scene first: its latency overlaps the level-0 reads and sums.
  const vec4 s00 = texelFetch(scene, xy, 0), s10 = texelFetch(scene, xy + ivec2(1, 0), 0);
  const vec4 s01 = texelFetch(scene, xy + ivec2(0, 1), 0), s11 = texelFetch(scene, xy + ivec2(1, 1), 0);
  vec3 a[4];
  up_2x_block(level0, ivec2(p.src_width, p.src_height), k, p.radius, a);
  imageStore(result, xy, composite_texel(s00, a[0], p.composite_scale));
  imageStore(result, xy + ivec2(1, 0), composite_texel(s10, a[1], p.composite_scale));
  imageStore(result, xy + ivec2(0, 1), composite_texel(s01, a[2], p.composite_scale));
  imageStore(result, xy + ivec2(1, 1), composite_texel(s11, a[3], p.composite_scale));
}
