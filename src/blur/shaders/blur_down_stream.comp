#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The pyramid method's binomial downsample D (docs/BLUR.md, "pyramid") on an exact 2:1 step of the
// padded chain, the same sums as blur_down.comp in the same order (blur.glsl, binomial4), walking
// the image instead of tiling it: an invocation owns one destination column and a band of
// p.band_rows rows of it. Destination texel (x, y) is [1 3 3 1] / 8 along x of source texels 2x - 1
// .. 2x + 2 (relative to the chain's origins), then along y of those sums for source rows 2y - 1 ..
// 2y + 2. Going down one destination row moves the four source rows by two, so the invocation keeps
// the last two rows' x sums in registers and loads two new source rows (4 texels each) a step: no
// shared memory and no barrier, every source row of the band read once per invocation, the two
// columns it shares with each neighbouring invocation from the cache. blur_down.comp instead loads
// a tile's block into shared memory and waits at two barriers per tile; this kernel runs where the
// host picks it (src/blur/blur_steps.cpp, down_step).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

// The [1 3 3 1] / 8 sum of source texels q .. q + (3, 0), as blur_down.comp's horizontal pass.
vec4 row_sum(ivec2 q) {
  return binomial4(src_texel(q), src_texel(q + ivec2(1, 0)), src_texel(q + ivec2(2, 0)), src_texel(q + ivec2(3, 0)));
}

void main() {
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  const int x = int(gl_GlobalInvocationID.x);
  const int y0 = int(gl_GlobalInvocationID.y) * p.band_rows;
  if (x >= size.x || y0 >= size.y) return;
  const int y1 = min(y0 + p.band_rows, size.y);
  // Source texel of tap 0 of destination texel (x, y): 2 (x + dst_origin) - 1 - src_origin.
  const ivec2 q = 2 * (ivec2(x, y0) + ivec2(p.dst_origin_x, p.dst_origin_y)) - 1 - ivec2(p.src_origin_x, p.src_origin_y);
  vec4 h0 = row_sum(q), h1 = row_sum(q + ivec2(0, 1));
  for (int y = y0; y < y1; ++y) {
    const int sy = q.y + 2 * (y - y0 + 1);
    const vec4 h2 = row_sum(ivec2(q.x, sy)), h3 = row_sum(ivec2(q.x, sy + 1));
    imageStore(dst, ivec2(x, y), binomial4(h0, h1, h2, h3));
    h0 = h2;
    h1 = h3;
  }
}
