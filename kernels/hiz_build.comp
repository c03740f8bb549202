#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Hi-Z depth pyramid in one dispatch, in the manner of AMD FidelityFX SPD (issue 5, seed 004
// "Method 3"): every workgroup reduces a 64x64 tile of the base level through up to six levels in
// shared memory; the last workgroup to finish (found with an atomic counter after a memory barrier
// on the images) reduces the remaining levels from the 64x64-or-smaller level it can then see.
// Each texel holds the farthest depth it covers (max for standard Z, min for reversed Z).
// Fold rule (docs/OCCLUSION.md): level sizes are max(1, size >> k) like Vulkan mips; child c of a
// parent of width w covers parents 2c and 2c + 1, and the last child also covers parent w - 1 when
// w is odd (the 3-wide case; 3x3 at the corner), so no source texel is ever dropped. Equivalently,
// texel c of level k covers source pixels [c * 2^k, (c + 1) * 2^k), the last one up to the edge.
// Tiles: the last tile of a row or column extends to the edge (64 to 127 wide), so every fold stays
// inside one workgroup. Above 4096 texels the host runs a second dispatch from level 6.
layout(local_size_x = 256) in;

#include "occlusion.h"

layout(binding = 0) uniform texture2D depth_tex;
layout(binding = 1, r32f) uniform coherent image2D hiz1;
layout(binding = 2, r32f) uniform coherent image2D hiz2;
layout(binding = 3, r32f) uniform coherent image2D hiz3;
layout(binding = 4, r32f) uniform coherent image2D hiz4;
layout(binding = 5, r32f) uniform coherent image2D hiz5;
layout(binding = 6, r32f) uniform coherent image2D hiz6;
layout(binding = 7, r32f) uniform coherent image2D hiz7;
layout(binding = 8, r32f) uniform coherent image2D hiz8;
layout(binding = 9, r32f) uniform coherent image2D hiz9;
layout(binding = 10, r32f) uniform coherent image2D hiz10;
layout(binding = 11, r32f) uniform coherent image2D hiz11;
layout(binding = 12, r32f) uniform coherent image2D hiz12;
layout(binding = 13, r32f) uniform coherent image2D hiz13;
layout(binding = 14, r32f) uniform coherent image2D hiz14;
layout(std430, binding = 15) coherent buffer Counters { uint counters[]; };
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
    case 0: return texelFetch(depth_tex, p, 0).r;
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
    store_level(pc.base_level + j, c, v);
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

void main() {
  const ivec2 base = ivec2(pc.base_width, pc.base_height);
  const ivec2 groups = ivec2(gl_NumWorkGroups.xy);
  const ivec2 g = ivec2(gl_WorkGroupID.xy);
  const bvec2 edge = equal(g, groups - 1);
  // This group's region of the base level: a 64x64 tile, the last one extended to the edge.
  const ivec2 begin = g * GLINT_HIZ_TILE;
  const ivec2 region = ivec2(edge.x ? base.x - begin.x : GLINT_HIZ_TILE, edge.y ? base.y - begin.y : GLINT_HIZ_TILE);

  // Level 1 straight from the base level (2x2, 3x2, 2x3 or 3x3 reads per child).
  {
    const ivec2 cb = child_begin(begin, 1u);
    const ivec2 cn = child_end(begin, region, edge, 1u) - cb;
    const ivec2 child = level_size(1u);
    for (int i = int(gl_LocalInvocationIndex); i < cn.x * cn.y; i += 256) {
      const ivec2 c = cb + ivec2(i % cn.x, i / cn.x);
      const ivec2 rx = parent_range(c.x, child.x, base.x);
      const ivec2 ry = parent_range(c.y, child.y, base.y);
      float v = load_level(pc.base_level, ivec2(rx.x, ry.x));
      for (int y = ry.x; y <= ry.y; ++y) {
        for (int x = rx.x; x <= rx.y; ++x) v = farther(v, load_level(pc.base_level, ivec2(x, y)));
      }
      tile[(c.y - cb.y) * kStrideA + (c.x - cb.x)] = v;
      store_level(pc.base_level + 1u, c, v);
    }
  }
  // Levels 2 .. tile_levels in shared memory. The result of level tile_levels ends in A if
  // tile_levels is odd, in B if even.
  reduce_levels(1u, pc.tile_levels - 1u, begin, region, edge);
  if (pc.tail_levels == 0u) return;  // uniform: a push constant

  // Make this group's stores visible, then count it. Without the image barrier before the atomic,
  // the last group may read stale texels (FidelityFX SPD issue #13).
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
    tile[c.y * kStrideA + c.x] = load_level(pc.base_level + t, c);
  }
  // The tail's region is the whole base level, which reaches both edges.
  reduce_levels(t, pc.tail_levels, ivec2(0), base, bvec2(true));
}
