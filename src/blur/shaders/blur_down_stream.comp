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
// SHUFFLE (the "shuffle_" variants, picked by the host where the device shuffles in compute and
// its subgroups are full and tile the 64-wide workgroups): each row is fetched in the order of a
// copy and every invocation gathers its four taps from its subgroup (row_sum_gathered). Only those
// variants declare the subgroup capabilities.
#ifdef SHUFFLE
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#endif
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

#ifdef SHUFFLE
// The same sum in the order of a copy. Invocation l of a subgroup of S owns destination column
// x = x_0 + l, whose taps are source texels c + 2 l .. c + 2 l + 3 of the subgroup's first tap c:
// row_sum() fetches 4 texels 2 apart from its neighbour's, so a quad of invocations touches four
// 16-byte spans per fetch. Here consecutive invocations fetch consecutive texels of the subgroup's
// 2 S + 2 (indices 1 + l and 1 + S + l, and one fetch for the two ends, indices 0 and 2 S + 1), and
// each invocation takes its taps by index through subgroup shuffles; the sums and their order are
// row_sum()'s. Every invocation of the subgroup must call it.
vec4 row_sum_gathered(ivec2 q) {
  const int S = int(gl_SubgroupSize), l = int(gl_SubgroupInvocationID);
  const int c = q.x - 2 * l;  // the subgroup's first tap (invocation 0's tap 0), index 0
  const vec4 a = src_texel(ivec2(c + 1 + l, q.y));                   // index 1 + l
  const vec4 b = src_texel(ivec2(c + 1 + S + l, q.y));               // index 1 + S + l
  const vec4 e = src_texel(ivec2(l == 0 ? c : c + 2 * S + 1, q.y));  // indices 0 and 2 S + 1
  const vec4 first = subgroupBroadcast(e, 0u), last = subgroupBroadcast(e, 1u);
  vec4 t[4];
  for (int k = 0; k < 4; ++k) {
    const int i = 2 * l + k;  // this invocation's tap k; S is a power of two (the Vulkan spec)
    const uint from = uint((i - 1) & (S - 1));
    const vec4 va = subgroupShuffle(a, from), vb = subgroupShuffle(b, from);
    t[k] = i == 0 ? first : i == 2 * S + 1 ? last : i <= S ? va : vb;
  }
  return binomial4(t[0], t[1], t[2], t[3]);
}
#define TAPS row_sum_gathered
// Invocation l of subgroup g owns column 64 w + S g + l (S = gl_SubgroupSize), and every
// invocation runs to the end of the band: a column past the image still fetches for its
// neighbour and stores nothing.
#define COLUMN int(gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID)
#else
#define TAPS row_sum
#define COLUMN int(gl_GlobalInvocationID.x)
#endif

void main() {
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  const int x = COLUMN;
  const int y0 = int(gl_GlobalInvocationID.y) * p.band_rows;
#ifndef SHUFFLE
  if (x >= size.x) return;
#endif
  if (y0 >= size.y) return;  // the same in every invocation of a workgroup
  const int y1 = min(y0 + p.band_rows, size.y);
  // Source texel of tap 0 of destination texel (x, y): 2 (x + dst_origin) - 1 - src_origin.
  const ivec2 q = 2 * (ivec2(x, y0) + ivec2(p.dst_origin_x, p.dst_origin_y)) - 1 - ivec2(p.src_origin_x, p.src_origin_y);
  vec4 h0 = TAPS(q), h1 = TAPS(q + ivec2(0, 1));
  for (int y = y0; y < y1; ++y) {
    const int sy = q.y + 2 * (y - y0 + 1);
    const vec4 h2 = TAPS(ivec2(q.x, sy)), h3 = TAPS(ivec2(q.x, sy + 1));
    if (x < size.x) imageStore(dst, ivec2(x, y), binomial4(h0, h1, h2, h3));
    h0 = h2;
    h1 = h3;
  }
}
