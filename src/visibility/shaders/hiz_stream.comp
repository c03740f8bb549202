#version 460
#extension GL_GOOGLE_include_directive : require
// Hi-Z levels 1 to 6 straight from the depth image (docs/OCCLUSION.md, "Hi-Z pyramid"): the first
// of the pyramid's two dispatches, which moves almost all the bytes (the depth image and the
// level-1 and -2 texels, 100 % + 31 % of the depth image's size; levels 3 to 6 add 2 %) and is
// therefore shaped like a copy: four textureGather in flight per invocation, consecutive
// invocations storing consecutive texels, and little else. hiz_build.comp then reduces level 6 to
// the last level (1/4096 of the bytes), only for pyramids of more than 6 levels.
//
// Workgroup g (16x16 invocations; block_of() maps launch order to g) owns the depth texels
// [64 g, 64 g + 64) per axis, the last workgroup of a row or column up to the edge (64 to 127
// texels; 64 exactly where the size is a multiple of 64; where the remainder r = size % 64 is at
// least 2^pc.tile_levels, the host launches one more block per axis, of r texels, which then owns
// the last texel of every level built: HiZPyramid's stream_blocks()), and the texels of levels 1..6 over
// them: texel c of level k covers the depth texels [c * 2^k, (c + 1) * 2^k), the last one of a
// row or column up to the edge (the fold rule, hiz_fold.glsl). Each texel holds the farthest
// depth it covers (max for standard Z, min for reversed Z).
// - Interior workgroups, where no fold applies (all but the last of a row or column whose size is
//   not a multiple of 64; 1920 and 3840 are 30 and 60 blocks): invocation
//   (x, y) gathers the 4x4 depth texels at 4 (16 g + (x, y)), its 2x2 texels of level 1 and its
//   texel of level 2. Level 1 goes through shared memory so that the workgroup stores it row by
//   row (a 2x2 block per invocation would leave every other texel of a row to the next store);
//   16 invocations then reduce 4x4 blocks of level 2 to level 3 and 4, and one invocation level 4
//   to levels 5 and 6. Two barriers.
// - Edge workgroups apply the fold rule through hiz_fold.glsl: level 1 by gathers (the last texel
//   of an odd-sized row or column reads its third column, row or corner with one more gather each),
//   then levels 2..6 in shared memory. They start first, so that their longer loops do not finish
//   last.
// Levels above pc.tile_levels (1 to 6) are never stored: their bindings alias the last built level.
layout(local_size_x = 16, local_size_y = 16) in;

#include "light_cull_params.h"

// Nearest, clamp-to-edge sampler: a gather that reaches past the edge repeats the edge texel,
// which leaves a max or min unchanged.
layout(binding = 0) uniform sampler2D depth_tex;
layout(binding = 1, r32f) uniform writeonly image2D hiz1;
layout(binding = 2, r32f) uniform writeonly image2D hiz2;
layout(binding = 3, r32f) uniform writeonly image2D hiz3;
layout(binding = 4, r32f) uniform writeonly image2D hiz4;
layout(binding = 5, r32f) uniform writeonly image2D hiz5;
layout(binding = 6, r32f) uniform writeonly image2D hiz6;
layout(push_constant) uniform Push { GlintHiZPush pc; };

float farther(float a, float b) { return pc.reversed_z != 0u ? min(a, b) : max(a, b); }
float farther4(vec4 g) { return farther(farther(g.x, g.y), farther(g.z, g.w)); }
float farther4(float a, float b, float c, float d) { return farther(farther(a, b), farther(c, d)); }

void store_level(uint level, ivec2 p, float v) {
  const vec4 t = vec4(v, 0.0, 0.0, 0.0);
  switch (level) {
    case 1: imageStore(hiz1, p, t); break;
    case 2: imageStore(hiz2, p, t); break;
    case 3: imageStore(hiz3, p, t); break;
    case 4: imageStore(hiz4, p, t); break;
    case 5: imageStore(hiz5, p, t); break;
    case 6: imageStore(hiz6, p, t); break;
  }
}

#include "hiz_fold.glsl"

// Farthest of the depth texels p .. p + 1 per axis, clamped to the image: one textureGather at
// the texels' shared corner, where u * size - 0.5 = p + 0.5 lies half a texel from any boundary.
float gather2x2(ivec2 p, vec2 inv_size) { return farther4(textureGather(depth_tex, vec2(p + 1) * inv_size, 0)); }

// Interior workgroup g: no texel it builds is the last of its level. Tile A holds level 1 (32x32,
// row-major), tile B level 2 (16x16) and level 4 (4x4) after it.
void interior(ivec2 g, vec2 inv_size) {
  const ivec2 l = ivec2(gl_LocalInvocationID.xy);
  const int t = int(gl_LocalInvocationIndex);
  const ivec2 q = 16 * g + l;  // this invocation's level-2 texel
  const ivec2 p = 4 * q;
  const float a00 = gather2x2(p, inv_size);
  const float a10 = gather2x2(p + ivec2(2, 0), inv_size);
  const float a01 = gather2x2(p + ivec2(0, 2), inv_size);
  const float a11 = gather2x2(p + ivec2(2, 2), inv_size);
  tile[(2 * l.y) * 32 + 2 * l.x] = a00;
  tile[(2 * l.y) * 32 + 2 * l.x + 1] = a10;
  tile[(2 * l.y + 1) * 32 + 2 * l.x] = a01;
  tile[(2 * l.y + 1) * 32 + 2 * l.x + 1] = a11;
  const float l2 = farther4(a00, a10, a01, a11);
  const uint levels = pc.tile_levels;  // uniform: a push constant
  if (levels >= 2u) {
    imageStore(hiz2, q, vec4(l2));
    tile[kOffsetB + t] = l2;
  }
  barrier();
  // Level 1 in copy order: invocation t stores texels t, t + 256, t + 512, t + 768 of the 32x32 block.
  const ivec2 c1 = 32 * g;
  for (int k = 0; k < 4; ++k) {
    const int i = t + 256 * k;
    imageStore(hiz1, c1 + ivec2(i & 31, i >> 5), vec4(tile[i]));
  }
  if (levels < 3u) return;  // uniform; no barrier follows
  float l4 = 0.0;
  if (t < 16) {
    const ivec2 b = ivec2(t & 3, t >> 2);
    const int o = kOffsetB + 4 * b.y * 16 + 4 * b.x;
    const float b00 = farther4(tile[o], tile[o + 1], tile[o + 16], tile[o + 17]);
    const float b10 = farther4(tile[o + 2], tile[o + 3], tile[o + 18], tile[o + 19]);
    const float b01 = farther4(tile[o + 32], tile[o + 33], tile[o + 48], tile[o + 49]);
    const float b11 = farther4(tile[o + 34], tile[o + 35], tile[o + 50], tile[o + 51]);
    const ivec2 c3 = 8 * g + 2 * b;
    imageStore(hiz3, c3, vec4(b00));
    imageStore(hiz3, c3 + ivec2(1, 0), vec4(b10));
    imageStore(hiz3, c3 + ivec2(0, 1), vec4(b01));
    imageStore(hiz3, c3 + ivec2(1, 1), vec4(b11));
    l4 = farther4(b00, b10, b01, b11);
    if (levels >= 4u) imageStore(hiz4, 4 * g + b, vec4(l4));
  }
  if (levels < 5u) return;
  if (t < 16) tile[kOffsetB + 256 + t] = l4;
  barrier();
  if (t == 0) {
    const int o = kOffsetB + 256;
    const float d00 = farther4(tile[o], tile[o + 1], tile[o + 4], tile[o + 5]);
    const float d10 = farther4(tile[o + 2], tile[o + 3], tile[o + 6], tile[o + 7]);
    const float d01 = farther4(tile[o + 8], tile[o + 9], tile[o + 12], tile[o + 13]);
    const float d11 = farther4(tile[o + 10], tile[o + 11], tile[o + 14], tile[o + 15]);
    const ivec2 c5 = 2 * g;
    imageStore(hiz5, c5, vec4(d00));
    imageStore(hiz5, c5 + ivec2(1, 0), vec4(d10));
    imageStore(hiz5, c5 + ivec2(0, 1), vec4(d01));
    imageStore(hiz5, c5 + ivec2(1, 1), vec4(d11));
    if (levels >= 6u) imageStore(hiz6, g, vec4(farther4(d00, d10, d01, d11)));
  }
}

// Children of level 1 per invocation in an edge workgroup: up to 63x63 over 256 invocations,
// gathered kEdgeBatch at a time. The batch sets the kernel's register count (the interior path
// alone needs 40 on the H100): all 16 gathers in flight took 118 registers there, 8 took 77 and
// 4 take 54, which lets 4 workgroups share a multiprocessor instead of 3: on the H200 0.1 us
// slower for the full pyramid at 3840x2160 (the same at 1920x1080), 1 us faster for the flare
// pass's shallow one at 1920x1080, where a remainder block of 64 columns (at most 32x31 texels
// of level 1) needs one batch (docs/OCCLUSION.md, "Speed").
const int kEdgeLevel1PerInvocation = 16;
const int kEdgeBatch = 4;

// Edge workgroup: level 1 of the region [begin, begin + region) of the depth image into tile A
// (origin begin / 2) by gathers, then levels 2..pc.tile_levels in shared memory.
void edge_block(ivec2 begin, ivec2 region, bvec2 edge, ivec2 base, vec2 inv_size) {
  const ivec2 cb = child_begin(begin, 1u);
  const ivec2 cn = child_end(begin, region, edge, base, 1u) - cb;
  const ivec2 n1 = fold_level_size(base, 1u);
  const int n = cn.x * cn.y;
  const int t = int(gl_LocalInvocationIndex);
  for (int k0 = 0; k0 < kEdgeLevel1PerInvocation; k0 += kEdgeBatch) {
    if (256 * k0 >= n) break;  // uniform
    // The batch's core gathers first, so that they are in flight together.
    float v[kEdgeBatch];
    for (int k = 0; k < kEdgeBatch; ++k) {
      const int i = min(t + 256 * (k0 + k), n - 1);
      v[k] = gather2x2(2 * (cb + ivec2(i % cn.x, i / cn.x)), inv_size);
    }
    for (int k = 0; k < kEdgeBatch; ++k) {
      const int i = t + 256 * (k0 + k);
      if (i < n) {
        const ivec2 c = cb + ivec2(i % cn.x, i / cn.x);
        const ivec2 p = 2 * c;
        // The last texel of an odd size >= 3 also covers the depth texel 2c + 2.
        const bool fx = c.x == n1.x - 1 && p.x + 2 < base.x;
        const bool fy = c.y == n1.y - 1 && p.y + 2 < base.y;
        float w = v[k];
        if (fx) w = farther(w, gather2x2(p + ivec2(2, 0), inv_size));
        if (fy) w = farther(w, gather2x2(p + ivec2(0, 2), inv_size));
        if (fx && fy) w = farther(w, gather2x2(p + 2, inv_size));
        tile[(c.y - cb.y) * kStrideA + (c.x - cb.x)] = w;
        imageStore(hiz1, c, vec4(w));
      }
    }
  }
  reduce_levels(1u, pc.tile_levels - 1u, begin, region, edge, base, 0u);
}

// The block of the workgroup with linear index i (in launch order): the last row, then the last
// column (the edge blocks, where the size is not a multiple of 64), so that their longer path does
// not finish last, then the other blocks row by row.
ivec2 block_of(int i, ivec2 groups) {
  if (i < groups.x) return ivec2(i, groups.y - 1);
  i -= groups.x;
  if (i < groups.y - 1) return ivec2(groups.x - 1, i);
  i -= groups.y - 1;
  return ivec2(i % (groups.x - 1), i / (groups.x - 1));
}

void main() {
  const ivec2 base = ivec2(pc.base_width, pc.base_height);
  const vec2 inv_size = 1.0 / vec2(base);
  const ivec2 groups = ivec2(gl_NumWorkGroups.xy);
  const ivec2 g = block_of(int(gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x), groups);
  // A block of the last row or column folds only where the size is not a multiple of 64: a last
  // block of exactly 64 texels is built like any interior block.
  const bvec2 last = equal(g, groups - 1), ragged = notEqual(base & 63, ivec2(0));
  const bvec2 edge = bvec2(last.x && ragged.x, last.y && ragged.y);
  if (!any(edge)) {  // uniform per workgroup
    interior(g, inv_size);
    return;
  }
  const ivec2 begin = 64 * g;
  const ivec2 region = ivec2(edge.x ? base.x - begin.x : 64, edge.y ? base.y - begin.y : 64);
  edge_block(begin, region, edge, base, inv_size);
}
