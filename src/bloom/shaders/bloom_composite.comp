#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The last upsample fused with the composite: out = scene + intensity / N * Up(A0)
// (docs/BLOOM.md "Composite"). Fusing saves a full-resolution bloom image write and read.
// A NaN scene channel becomes 0 and the sum is clamped to +-OUTPUT_MAX (65504 for an RGBA16F
// output, the largest float for RGBA32F), so the output is finite even where the scene is not.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1) uniform texture2D level0;
#include "dst_image.glsl"
DST_LAYOUT(2) uniform writeonly image2D result;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_up_tiled.glsl"

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(p.dst_width, p.dst_height);
  vec4 s = texelFetch(scene, min(xy, size - 1), 0);  // issued first: its latency overlaps the tile work
  vec3 bloom = upsample_tiled(level0, ivec2(p.src_width, p.src_height), size, p.radius);
  if (any(greaterThanEqual(xy, size))) return;  // after the barriers inside upsample_tiled
  imageStore(result, xy, composite_texel(s, bloom, p.composite_scale));
}
