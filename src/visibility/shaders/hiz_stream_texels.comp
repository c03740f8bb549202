#version 460
#extension GL_GOOGLE_include_directive : require
// Hi-Z levels 1 and 2 straight from the depth image, one invocation per level-2 texel, with no
// shared memory and no barrier (docs/OCCLUSION.md, "Hi-Z pyramid"): the stream pass that CPU
// devices run (detail::HiZStream::texels). GPUs run hiz_stream.comp, which writes levels 1 to 6 by
// 64x64 blocks; on lavapipe that one took 4.5x as long (30 against 6.8 ms at 1920x1080), and as
// long with its work removed (returning at once), so the cost lies in how lavapipe runs a kernel
// with shared memory and barriers, not in the work. hiz_build.comp then reduces level 2 to the
// last level.
//
// Fold rule (docs/OCCLUSION.md): texel c of level k covers the source pixels [c * 2^k, (c + 1) * 2^k),
// the last texel of a level up to the edge; level sizes are max(1, size >> k). Invocation q owns
// level-2 texel q and the level-1 texels under it: 2q and 2q + 1 per axis, and for the last q also
// the last level-1 texel when level 1 has an odd size (so 1 to 3 per axis). Each texel holds the
// farthest depth it covers (max for standard Z, min for reversed Z).
layout(local_size_x = 32, local_size_y = 4) in;

#include "light_cull_params.h"

// Nearest, clamp-to-edge sampler: a gather that reaches past the edge repeats the edge texel,
// which leaves a max or min unchanged.
layout(binding = 0) uniform sampler2D depth_tex;
layout(binding = 1, r32f) uniform writeonly image2D hiz1;
layout(binding = 2, r32f) uniform writeonly image2D hiz2;  // level 1 again when only one level is built
layout(push_constant) uniform Push { GlintHiZPush pc; };

float farther(float a, float b) { return pc.reversed_z != 0u ? min(a, b) : max(a, b); }
float farther4(vec4 g) { return farther(farther(g.x, g.y), farther(g.z, g.w)); }

// Farthest of the depth texels p .. p + 1 per axis, clamped to the image: one textureGather at
// the texels' shared corner, where u * size - 0.5 = p + 0.5 lies half a texel from any boundary.
float gather2x2(ivec2 p, vec2 inv_size) { return farther4(textureGather(depth_tex, vec2(p + 1) * inv_size, 0)); }

void main() {
  const ivec2 base = ivec2(pc.base_width, pc.base_height);
  const ivec2 n1 = max(ivec2(1), base >> 1);
  const ivec2 n2 = max(ivec2(1), n1 >> 1);
  const ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(q, n2))) return;
  const vec2 inv_size = 1.0 / vec2(base);
  const bool two_levels = pc.tile_levels >= 2u;  // uniform: a push constant

  if (all(lessThan(q, n2 - 1))) {
    // Not the last texel of level 2 along either axis: its level-1 texels 2q .. 2q + 1 are not the
    // last of level 1 (2q + 1 <= 2 n2 - 3 < n1 - 1) and cover exactly the 4x4 depth texels at 4q,
    // all inside the image. The four gathers are issued before any use.
    const ivec2 p = 4 * q;
    const float a00 = gather2x2(p, inv_size);
    const float a10 = gather2x2(p + ivec2(2, 0), inv_size);
    const float a01 = gather2x2(p + ivec2(0, 2), inv_size);
    const float a11 = gather2x2(p + ivec2(2, 2), inv_size);
    const ivec2 c = 2 * q;
    imageStore(hiz1, c, vec4(a00));
    imageStore(hiz1, c + ivec2(1, 0), vec4(a10));
    imageStore(hiz1, c + ivec2(0, 1), vec4(a01));
    imageStore(hiz1, c + ivec2(1, 1), vec4(a11));
    if (two_levels) imageStore(hiz2, q, vec4(farther(farther(a00, a10), farther(a01, a11))));
    return;
  }

  // The last row or column of level 2 (n2.x + n2.y - 1 invocations): the general rule. Level-1
  // texels c = 2q .. end - 1 per axis, the last q owning up to n1 - 1; texel c covers depth texels
  // 2c .. 2c + 1, and the last one of level 1 also 2c + 2 when the image size is odd (one more
  // gather, clamped to the edge, for that column, row and corner).
  const ivec2 end = ivec2(q.x == n2.x - 1 ? n1.x : 2 * q.x + 2, q.y == n2.y - 1 ? n1.y : 2 * q.y + 2);
  float l2 = 0.0;
  bool first = true;
  for (int cy = 2 * q.y; cy < end.y; ++cy) {
    for (int cx = 2 * q.x; cx < end.x; ++cx) {
      const ivec2 p = 2 * ivec2(cx, cy);
      const bool fx = cx == n1.x - 1 && p.x + 2 < base.x;  // the last texel of an odd width >= 3
      const bool fy = cy == n1.y - 1 && p.y + 2 < base.y;
      float v = gather2x2(p, inv_size);
      if (fx) v = farther(v, gather2x2(p + ivec2(2, 0), inv_size));
      if (fy) v = farther(v, gather2x2(p + ivec2(0, 2), inv_size));
      if (fx && fy) v = farther(v, gather2x2(p + 2, inv_size));
      imageStore(hiz1, ivec2(cx, cy), vec4(v));
      l2 = first ? v : farther(l2, v);
      first = false;
    }
  }
  if (two_levels) imageStore(hiz2, q, vec4(l2));
}
