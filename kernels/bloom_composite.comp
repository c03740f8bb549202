#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The last upsample fused with the composite: out = scene + intensity / N * Up(A0)
// (docs/BLOOM.md "Composite"). Fusing saves a full-resolution bloom image write and read.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1) uniform texture2D level0;
layout(binding = 2, DST_FORMAT) uniform writeonly image2D result;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

vec3 source_texel(ivec2 ij) { return vec3(0.0); }  // unused

#include "bloom.glsl"
#include "bloom_up_tiled.glsl"

void main() {
  ivec2 size = ivec2(p.dst_width, p.dst_height);
  ivec2 origin = block_origin();
  vec4 s[4];
  for (int k = 0; k < 4; ++k) {  // issued first: their latency overlaps the tile work
    ivec2 xy = origin + ivec2(k & 1, k >> 1);  // only own texels: in place, others are being written
    s[k] = all(lessThan(xy, size)) ? texelFetch(scene, xy, 0) : vec4(0.0);
  }
  vec3 bloom[4];
  upsample_block(level0, ivec2(p.src_width, p.src_height), size, p.radius, bloom);
  for (int k = 0; k < 4; ++k) {
    ivec2 xy = origin + ivec2(k & 1, k >> 1);
    if (all(lessThan(xy, size))) imageStore(result, xy, vec4(s[k].rgb + p.composite_scale * bloom[k], s[k].a));
  }
}
