// The fold rule of the Hi-Z pyramid over a region of one workgroup, in shared memory: shared by the
// stream pass of GPUs (hiz_stream.comp, base = the depth image, for the workgroups at the right and
// bottom edges) and the tile pass (hiz_build.comp, base = the stream pass's last level, 6 on GPUs
// and 2 on CPU devices, for its edge tiles and its tail). docs/OCCLUSION.md, "Hi-Z pyramid".
//
// Fold rule: level sizes are max(1, size >> j) like Vulkan mips; child c of a parent of w texels
// covers parents 2c and 2c + 1, and the last child also covers parent w - 1 when w is odd (the
// 3-wide case; 3x3 at the corner), so no source texel is ever dropped. Equivalently, texel c of
// level j covers base texels [c * 2^j, (c + 1) * 2^j), the last one up to the edge.
//
// A region is [begin, begin + region) of the base; `edge` says, per axis, that it reaches the
// base's last texel, and so owns the folded last child of every level. A region not at an edge is
// 2^n texels wide at a multiple of 2^n, for every level j <= n it builds.
//
// The includer declares, before including:
//   float farther(float a, float b);                   // max (standard Z) or min (reversed Z)
//   void store_level(uint level, ivec2 p, float v);    // texel p of pyramid level `level`
// This file declares the shared ping-pong tiles: A holds up to 64x64 texels (the region's first
// level), B up to 32x32 (20 KiB in all, within lavapipe's 32 KiB; the host checks the device's
// limit against detail::kHiZSharedBytes in src/visibility/hiz_internal.h, which counts them).
#ifndef GLINT_HIZ_FOLD_GLSL
#define GLINT_HIZ_FOLD_GLSL

const int kStrideA = 64;
const int kStrideB = 32;
const int kOffsetB = 64 * 64;
shared float tile[64 * 64 + 32 * 32];

// Size of level j of a base of `base` texels.
ivec2 fold_level_size(ivec2 base, uint j) { return max(ivec2(1), base >> int(j)); }

// Parents covered by child c of a level of `child` texels over `parent` texels.
ivec2 parent_range(int c, int child, int parent) {
  return ivec2(2 * c, c == child - 1 ? parent - 1 : min(2 * c + 1, parent - 1));
}

// The children of level j that the region owns: [child_begin, child_end).
ivec2 child_begin(ivec2 begin, uint j) { return begin >> int(j); }
ivec2 child_end(ivec2 begin, ivec2 region, bvec2 edge, ivec2 base, uint j) {
  const ivec2 inner = (begin + region) >> int(j);
  const ivec2 size = fold_level_size(base, j);
  return ivec2(edge.x ? size.x : inner.x, edge.y ? size.y : inner.y);
}

// One reduction step in shared memory: level j - 1 of the region (in `src`, origin at
// child_begin(j - 1)) to level j (into `dst`), also stored as pyramid level base_level + j.
void reduce_shared(int src, int src_stride, int dst, int dst_stride, ivec2 begin, ivec2 region, bvec2 edge,
                   ivec2 base, uint base_level, uint j) {
  const ivec2 cb = child_begin(begin, j);
  const ivec2 cn = child_end(begin, region, edge, base, j) - cb;
  const ivec2 pb = child_begin(begin, j - 1u);
  const ivec2 child = fold_level_size(base, j);
  const ivec2 parent = fold_level_size(base, j - 1u);
  const int invocations = int(gl_WorkGroupSize.x * gl_WorkGroupSize.y);
  for (int i = int(gl_LocalInvocationIndex); i < cn.x * cn.y; i += invocations) {
    const ivec2 c = cb + ivec2(i % cn.x, i / cn.x);
    const ivec2 rx = parent_range(c.x, child.x, parent.x) - pb.x;
    const ivec2 ry = parent_range(c.y, child.y, parent.y) - pb.y;
    float v = tile[src + ry.x * src_stride + rx.x];
    for (int y = ry.x; y <= ry.y; ++y) {
      for (int x = rx.x; x <= rx.y; ++x) v = farther(v, tile[src + y * src_stride + x]);
    }
    tile[dst + (c.y - cb.y) * dst_stride + (c.x - cb.x)] = v;
    store_level(base_level + j, c, v);
  }
}

// Levels j0 + 1 .. j0 + n of the region, level j0 already in tile A (origin child_begin(j0)).
// Each step starts with a barrier (uniform control flow: n is the same for the whole workgroup).
void reduce_levels(uint j0, uint n, ivec2 begin, ivec2 region, bvec2 edge, ivec2 base, uint base_level) {
  for (uint s = 0u; s < n; ++s) {
    barrier();
    const uint j = j0 + s + 1u;
    if ((s & 1u) == 0u) {
      reduce_shared(0, kStrideA, kOffsetB, kStrideB, begin, region, edge, base, base_level, j);
    } else {
      reduce_shared(kOffsetB, kStrideB, 0, kStrideA, begin, region, edge, base, base_level, j);
    }
  }
}

#endif
