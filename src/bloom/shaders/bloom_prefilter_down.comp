#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Bright-pass fused into the first downsample: full-resolution scene -> pyramid level 0.
// Implements docs/BLOOM.md "Prefilter" (the soft knee) and "Downsample" with the per-box
// Karis guard (Jimenez 2014) or none; src/bloom/shaders/bloom_prefilter_smooth.comp does karis_smooth. Fusing saves writing and re-reading a full-resolution bright-pass image.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1, DST_FORMAT) uniform writeonly image2D level0;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"
#include "bloom_down_tiled.glsl"

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  bool inside = all(lessThan(xy, dst_size));
  BloomSource s = BloomSource(ivec2(p.src_width, p.src_height), true, p.threshold, p.knee);
  vec3 c = downsample_any(scene, s, xy, dst_size, inside, (p.flags & GLINT_BLOOM_FLAG_KARIS) != 0u);
  if (inside) imageStore(level0, xy, vec4(min(c, vec3(p.max_brightness)), 1.0));
}
