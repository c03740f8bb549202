#version 460
#extension GL_GOOGLE_include_directive : require
// Hi-Z levels 3 and up, in one dispatch in the manner of AMD FidelityFX SPD (docs/OCCLUSION.md,
// "Hi-Z pyramid"): the second of the pyramid's two dispatches. hiz_stream.comp has written levels
// 1 and 2 from the depth image; this kernel takes level 2 as its base. Every workgroup reduces a
// 64x64 tile of level 2 through up to six levels in shared memory; the last workgroup to finish
// (found with an atomic counter after a memory barrier on the images) reduces the remaining levels
// from the 64x64-or-smaller level it can then see. Level 2 is at most 4096 texels wide (the depth
// image at most 16384), so the tail always fits one workgroup and 2 + 6 + 6 levels cover the
// largest pyramid (14 levels).
// Each texel holds the farthest depth it covers (max for standard Z, min for reversed Z).
// Fold rule (docs/OCCLUSION.md): level sizes are max(1, size >> k) like Vulkan mips; child c of a
// parent of width w covers parents 2c and 2c + 1, and the last child also covers parent w - 1 when
// w is odd (the 3-wide case; 3x3 at the corner), so no source texel is ever dropped. Equivalently,
// texel c of level k covers source pixels [c * 2^k, (c + 1) * 2^k), the last one up to the edge.
// Tiles: the last tile of a row or column extends to the edge (64 to 127 wide), so every fold stays
// inside one workgroup.
// Speed (docs/OCCLUSION.md, "Speed"): interior tiles, where no fold applies, take a fast path in
// which each invocation reduces a 4x4 block of the base and keeps levels 1 and 2 above it in
// registers; only edge tiles and the last workgroup run the general loops. Every store names its
// level with a constant, so no switch is left in the fast path.
layout(local_size_x = 256) in;

#include "light_cull_params.h"

// The level this kernel reads as its base (written by hiz_stream.comp before it).
const uint kBaseLevel = 2u;

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

// Ping-pong tiles: A holds up to 64x64 texels (level 1 of an edge tile, or the tail's start level),
// B up to 32x32.
const int kStrideA = 64;
const int kStrideB = 32;
const int kOffsetB = 64 * 64;
shared float tile[64 * 64 + 32 * 32];
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

// Texel p of the base level (inside it). kBaseLevel is a constant: the switch folds away.
float load_base(ivec2 p) { return load_level(kBaseLevel, p); }

// Farthest of the base texels p, p + (1, 0), p + (0, 1), p + (1, 1), each coordinate clamped to the
// base (a repeated texel changes nothing).
float load_base_2x2(ivec2 p, ivec2 base) {
  const ivec2 q = min(p + 1, base - 1);
  return farther4(load_base(p), load_base(ivec2(q.x, p.y)), load_base(ivec2(p.x, q.y)), load_base(q));
}

// Size of the level `j` levels above the base.
ivec2 level_size(uint j) { return max(ivec2(1), ivec2(pc.base_width, pc.base_height) >> int(j)); }

// Parents covered by child c of a level of `child` texels over `parent` texels (fold rule).
ivec2 parent_range(int c, int child, int parent) {
  return ivec2(2 * c, c == child - 1 ? parent - 1 : min(2 * c + 1, parent - 1));
}

// Children of level `j` (1..) that the region [begin, end) of the base level owns. `edge`: the
// region reaches the base level's last texel, so it also owns the folded last child.
ivec2 child_begin(ivec2 begin, uint j) { return begin >> int(j); }
ivec2 child_end(ivec2 begin, ivec2 region, bvec2 edge, uint j) {
  const ivec2 inner = (begin + region) >> int(j);
  return ivec2(edge.x ? level_size(j).x : inner.x, edge.y ? level_size(j).y : inner.y);
}

// One reduction step in shared memory: level j - 1 (in `src`, origin at child_begin(j - 1)) to
// level j (into `dst`), also stored to the pyramid.
void reduce_shared(int src, int src_stride, int dst, int dst_stride, ivec2 begin, ivec2 region, bvec2 edge, uint j) {
  const ivec2 cb = child_begin(begin, j);
  const ivec2 cn = child_end(begin, region, edge, j) - cb;
  const ivec2 pb = child_begin(begin, j - 1u);
  const ivec2 child = level_size(j);
  const ivec2 parent = level_size(j - 1u);
  for (int i = int(gl_LocalInvocationIndex); i < cn.x * cn.y; i += 256) {
    const ivec2 c = cb + ivec2(i % cn.x, i / cn.x);
    const ivec2 rx = parent_range(c.x, child.x, parent.x) - pb.x;
    const ivec2 ry = parent_range(c.y, child.y, parent.y) - pb.y;
    float v = tile[src + ry.x * src_stride + rx.x];
    for (int y = ry.x; y <= ry.y; ++y) {
      for (int x = rx.x; x <= rx.y; ++x) v = farther(v, tile[src + y * src_stride + x]);
    }
    tile[dst + (c.y - cb.y) * dst_stride + (c.x - cb.x)] = v;
    store_level(kBaseLevel + j, c, v);
  }
}

// Levels j0 + 1 .. j0 + n of the region, level j0 already in tile A (origin child_begin(j0)).
void reduce_levels(uint j0, uint n, ivec2 begin, ivec2 region, bvec2 edge) {
  for (uint s = 0u; s < n; ++s) {
    barrier();
    const uint j = j0 + s + 1u;
    if ((s & 1u) == 0u) {
      reduce_shared(0, kStrideA, kOffsetB, kStrideB, begin, region, edge, j);
    } else {
      reduce_shared(kOffsetB, kStrideB, 0, kStrideA, begin, region, edge, j);
    }
  }
}

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
  const ivec2 cn = child_end(begin, region, edge, 1u) - cb;
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
    reduce_levels(1u, pc.tile_levels - 1u, begin, region, edge);
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
  reduce_levels(t, pc.tail_levels, ivec2(0), base, bvec2(true));
}
