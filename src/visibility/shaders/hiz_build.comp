#version 460
#extension GL_GOOGLE_include_directive : require
// Hi-Z levels above the stream pass's, in one dispatch in the manner of AMD FidelityFX SPD
// (docs/OCCLUSION.md, "Hi-Z pyramid"): the second of the pyramid's two dispatches, made only when
// there are levels above the stream pass's. The stream pass has written levels 1 to kBaseLevel
// (6 on GPUs, 2 on CPU devices) from the depth image; this kernel takes level kBaseLevel as its
// base. Every workgroup reduces a 64x64 tile of the base through up to six levels in shared
// memory; the last workgroup to finish (found with an atomic counter after a memory barrier on the
// images) reduces the remaining levels from the 64x64-or-smaller level it can then see. The base
// is at most 16384 / 4 = 4096 texels wide, so there are at most 64x64 tiles, the tail always fits
// one workgroup, and 2 + 6 + 6 levels cover the largest pyramid (14 levels). From level 6, below
// 8192 texels a side there is one tile and no tail.
// Each texel holds the farthest depth it covers (max for standard Z, min for reversed Z), by the
// fold rule of hiz_fold.glsl. Tiles: the last tile of a row or column extends to the edge (64 to
// 127 wide), so every fold stays inside one workgroup.
// Speed (docs/OCCLUSION.md, "Speed"): interior tiles, where no fold applies, take a fast path in
// which each invocation reduces a 4x4 block of the base and keeps levels 1 and 2 above it in
// registers; only edge tiles and the last workgroup run the general loops. Every store names its
// level with a constant, so no switch is left in the fast path.
layout(local_size_x = 256) in;

#include "light_cull_params.h"

// The level this kernel reads as its base, written by the stream pass before it: 6 after
// hiz_stream.comp (GPUs), 2 after hiz_stream_texels.comp (CPU devices). A specialization constant,
// so that every switch on a level folds away.
layout(constant_id = 2) const uint kBaseLevel = GLINT_HIZ_STREAM_LEVELS;

// Binding k - 1 is level k (level 1 is not accessed here: kept so that the numbering stays plain).
layout(binding = 0, r32f) uniform coherent image2D hiz1;
layout(binding = 1, r32f) uniform coherent image2D hiz2;
layout(binding = 2, r32f) uniform coherent image2D hiz3;
layout(binding = 3, r32f) uniform coherent image2D hiz4;
layout(binding = 4, r32f) uniform coherent image2D hiz5;
layout(binding = 5, r32f) uniform coherent image2D hiz6;
layout(binding = 6, r32f) uniform coherent image2D hiz7;
layout(binding = 7, r32f) uniform coherent image2D hiz8;
layout(binding = 8, r32f) uniform coherent image2D hiz9;
layout(binding = 9, r32f) uniform coherent image2D hiz10;
layout(binding = 10, r32f) uniform coherent image2D hiz11;
layout(binding = 11, r32f) uniform coherent image2D hiz12;
layout(binding = 12, r32f) uniform coherent image2D hiz13;
layout(binding = 13, r32f) uniform coherent image2D hiz14;
layout(std430, binding = 14) coherent buffer Counters { uint counters[]; };
layout(push_constant) uniform Push { GlintHiZPush pc; };

shared bool last_group;

float farther(float a, float b) { return pc.reversed_z != 0u ? min(a, b) : max(a, b); }

void store_level(uint level, ivec2 p, float v) {
  const vec4 t = vec4(v, 0.0, 0.0, 0.0);
  switch (level) {
    case 1: imageStore(hiz1, p, t); break;
    case 2: imageStore(hiz2, p, t); break;
    case 3: imageStore(hiz3, p, t); break;
    case 4: imageStore(hiz4, p, t); break;
    case 5: imageStore(hiz5, p, t); break;
    case 6: imageStore(hiz6, p, t); break;
    case 7: imageStore(hiz7, p, t); break;
    case 8: imageStore(hiz8, p, t); break;
    case 9: imageStore(hiz9, p, t); break;
    case 10: imageStore(hiz10, p, t); break;
    case 11: imageStore(hiz11, p, t); break;
    case 12: imageStore(hiz12, p, t); break;
    case 13: imageStore(hiz13, p, t); break;
    case 14: imageStore(hiz14, p, t); break;
  }
}

float load_level(uint level, ivec2 p) {
  switch (level) {
    case 1: return imageLoad(hiz1, p).r;
    case 2: return imageLoad(hiz2, p).r;
    case 3: return imageLoad(hiz3, p).r;
    case 4: return imageLoad(hiz4, p).r;
    case 5: return imageLoad(hiz5, p).r;
    case 6: return imageLoad(hiz6, p).r;
    case 7: return imageLoad(hiz7, p).r;
    case 8: return imageLoad(hiz8, p).r;
    case 9: return imageLoad(hiz9, p).r;
    case 10: return imageLoad(hiz10, p).r;
    case 11: return imageLoad(hiz11, p).r;
    case 12: return imageLoad(hiz12, p).r;
    case 13: return imageLoad(hiz13, p).r;
  }
  return imageLoad(hiz14, p).r;
}

float farther4(float a, float b, float c, float d) { return farther(farther(a, b), farther(c, d)); }

#include "hiz_fold.glsl"

// Texel p of the base level (inside it). kBaseLevel is a constant: the switch folds away.
float load_base(ivec2 p) { return load_level(kBaseLevel, p); }

// Farthest of the base texels p, p + (1, 0), p + (0, 1), p + (1, 1), each coordinate clamped to the
// base (a repeated texel changes nothing).
float load_base_2x2(ivec2 p, ivec2 base) {
  const ivec2 q = min(p + 1, base - 1);
  return farther4(load_base(p), load_base(ivec2(q.x, p.y)), load_base(ivec2(p.x, q.y)), load_base(q));
}

// Size of the level `j` levels above the base.
ivec2 level_size(uint j) { return fold_level_size(ivec2(pc.base_width, pc.base_height), j); }

// Levels j are counted from the base level below (j = 1 is pyramid level kBaseLevel + 1).
// Child c of level 1 (the general rule: 2x2, plus the folded column, row or corner at an odd edge).
// The 2x2 core comes first so that two children's core reads can be in flight together.
float fold_level1(ivec2 c, float core, ivec2 child, ivec2 base) {
  const ivec2 p = 2 * c;
  const bool fx = c.x == child.x - 1 && base.x - 1 == p.x + 2;  // odd width >= 3, last child
  const bool fy = c.y == child.y - 1 && base.y - 1 == p.y + 2;
  float v = core;
  if (fx) v = farther(v, farther(load_base(ivec2(p.x + 2, p.y)), load_base(ivec2(p.x + 2, min(p.y + 1, base.y - 1)))));
  if (fy) v = farther(v, farther(load_base(ivec2(p.x, p.y + 2)), load_base(ivec2(min(p.x + 1, base.x - 1), p.y + 2))));
  if (fx && fy) v = farther(v, load_base(p + 2));
  return v;
}

// Level 1 of an edge tile (up to 63x63 children) into tile A, two children per invocation per step.
void level1_general(ivec2 begin, ivec2 region, bvec2 edge, ivec2 base) {
  const ivec2 cb = child_begin(begin, 1u);
  const ivec2 cn = child_end(begin, region, edge, base, 1u) - cb;
  const ivec2 child = level_size(1u);
  const int n = cn.x * cn.y;
  for (int i = int(gl_LocalInvocationIndex); i < n; i += 512) {
    const int i2 = min(i + 256, n - 1);  // a repeat of the last child when past the end: not stored
    const ivec2 ca = cb + ivec2(i % cn.x, i / cn.x);
    const ivec2 cc = cb + ivec2(i2 % cn.x, i2 / cn.x);
    const float core_a = load_base_2x2(2 * ca, base);
    const float core_c = load_base_2x2(2 * cc, base);
    const float va = fold_level1(ca, core_a, child, base);
    const float vc = fold_level1(cc, core_c, child, base);
    tile[(ca.y - cb.y) * kStrideA + (ca.x - cb.x)] = va;
    store_level(kBaseLevel + 1u, ca, va);
    if (i + 256 < n) {
      tile[(cc.y - cb.y) * kStrideA + (cc.x - cb.x)] = vc;
      store_level(kBaseLevel + 1u, cc, vc);
    }
  }
}

// An interior 64x64 tile (no fold, no clamp: its children are never the last of their level).
// Invocation t owns the 4x4 base block b = (t % 16, t / 16): four 2x2 reads (16 loads, all issued
// before the first use) give its 2x2 texels of level 1 and its texel of level 2 (counted from the
// base) in registers. Level 2 (16x16) goes through shared memory once;
// 16 invocations then reduce 4x4 blocks of it to 2x2 texels of level 3 and one of level 4, and one
// invocation reduces the 4x4 of level 4 to levels 5 and 6. Two barriers in all.
void interior_tile(ivec2 begin, ivec2 base) {
  const int t = int(gl_LocalInvocationIndex);
  const ivec2 b = ivec2(t & 15, t >> 4);
  const ivec2 p = begin + 4 * b;
  const float a00 = load_base_2x2(p, base);
  const float a10 = load_base_2x2(p + ivec2(2, 0), base);
  const float a01 = load_base_2x2(p + ivec2(0, 2), base);
  const float a11 = load_base_2x2(p + ivec2(2, 2), base);
  const ivec2 c1 = (begin >> 1) + 2 * b;
  store_level(kBaseLevel + 1u, c1, a00);
  store_level(kBaseLevel + 1u, c1 + ivec2(1, 0), a10);
  store_level(kBaseLevel + 1u, c1 + ivec2(0, 1), a01);
  store_level(kBaseLevel + 1u, c1 + ivec2(1, 1), a11);
  if (pc.tile_levels < 2u) return;  // uniform (a push constant); no barrier follows
  const float l2 = farther4(a00, a10, a01, a11);
  store_level(kBaseLevel + 2u, (begin >> 2) + b, l2);
  tile[t] = l2;  // 16x16, row-major
  barrier();
  if (t < 16 && pc.tile_levels >= 3u) {
    const ivec2 q = ivec2(t & 3, t >> 2);
    const int o = 4 * q.y * 16 + 4 * q.x;
    const float b00 = farther4(tile[o], tile[o + 1], tile[o + 16], tile[o + 17]);
    const float b10 = farther4(tile[o + 2], tile[o + 3], tile[o + 18], tile[o + 19]);
    const float b01 = farther4(tile[o + 32], tile[o + 33], tile[o + 48], tile[o + 49]);
    const float b11 = farther4(tile[o + 34], tile[o + 35], tile[o + 50], tile[o + 51]);
    const ivec2 c3 = (begin >> 3) + 2 * q;
    store_level(kBaseLevel + 3u, c3, b00);
    store_level(kBaseLevel + 3u, c3 + ivec2(1, 0), b10);
    store_level(kBaseLevel + 3u, c3 + ivec2(0, 1), b01);
    store_level(kBaseLevel + 3u, c3 + ivec2(1, 1), b11);
    if (pc.tile_levels >= 4u) {
      const float l4 = farther4(b00, b10, b01, b11);
      store_level(kBaseLevel + 4u, (begin >> 4) + q, l4);
      tile[256 + t] = l4;  // 4x4, row-major
    }
  }
  barrier();
  if (t == 0 && pc.tile_levels >= 5u) {
    const int o = 256;
    const float d00 = farther4(tile[o], tile[o + 1], tile[o + 4], tile[o + 5]);
    const float d10 = farther4(tile[o + 2], tile[o + 3], tile[o + 6], tile[o + 7]);
    const float d01 = farther4(tile[o + 8], tile[o + 9], tile[o + 12], tile[o + 13]);
    const float d11 = farther4(tile[o + 10], tile[o + 11], tile[o + 14], tile[o + 15]);
    const ivec2 c5 = begin >> 5;
    store_level(kBaseLevel + 5u, c5, d00);
    store_level(kBaseLevel + 5u, c5 + ivec2(1, 0), d10);
    store_level(kBaseLevel + 5u, c5 + ivec2(0, 1), d01);
    store_level(kBaseLevel + 5u, c5 + ivec2(1, 1), d11);
    if (pc.tile_levels >= 6u) store_level(kBaseLevel + 6u, begin >> 6, farther4(d00, d10, d01, d11));
  }
}

void main() {
  const ivec2 base = ivec2(pc.base_width, pc.base_height);
  const ivec2 groups = ivec2(gl_NumWorkGroups.xy);
  // Tiles are numbered from the bottom-right corner: the last row and column of tiles, up to twice
  // as tall or wide and on the general loops, start first so that they do not finish last.
  const ivec2 g = groups - 1 - ivec2(gl_WorkGroupID.xy);
  const bvec2 edge = equal(g, groups - 1);
  // This group's region of the base level: a 64x64 tile, the last one extended to the edge.
  const ivec2 begin = g * GLINT_HIZ_TILE;
  const ivec2 region = ivec2(edge.x ? base.x - begin.x : GLINT_HIZ_TILE, edge.y ? base.y - begin.y : GLINT_HIZ_TILE);

  if (!any(edge)) {  // uniform per workgroup
    interior_tile(begin, base);
  } else {
    level1_general(begin, region, edge, base);
    // Levels 2 .. tile_levels in shared memory. The result of level tile_levels ends in A if
    // tile_levels is odd, in B if even.
    reduce_levels(1u, pc.tile_levels - 1u, begin, region, edge, base, kBaseLevel);
  }
  if (pc.tail_levels == 0u) return;  // uniform: a push constant

  // Make this group's stores visible, then count it. Without the image barrier before the atomic,
  // the last group may read stale texels (reported against FidelityFX SPD:
  // https://github.com/GPUOpen-Effects/FidelityFX-SPD/issues/13).
  memoryBarrierImage();
  memoryBarrierBuffer();
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    const uint total = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
    last_group = atomicAdd(counters[pc.counter_index], 1u) == total - 1u;
  }
  barrier();
  if (!last_group) return;  // uniform: a shared value read after a barrier
  memoryBarrierImage();
  if (gl_LocalInvocationIndex == 0u) counters[pc.counter_index] = 0u;  // reset for the next frame

  // Tail: the whole level tile_levels (at most 64x64) into A, then its next levels.
  const uint t = pc.tile_levels;
  const ivec2 tsize = level_size(t);
  for (int i = int(gl_LocalInvocationIndex); i < tsize.x * tsize.y; i += 256) {
    const ivec2 c = ivec2(i % tsize.x, i / tsize.x);
    tile[c.y * kStrideA + c.x] = load_level(kBaseLevel + t, c);
  }
  // The tail's region is the whole base level, which reaches both edges.
  reduce_levels(t, pc.tail_levels, ivec2(0), base, bvec2(true), base, kBaseLevel);
}
