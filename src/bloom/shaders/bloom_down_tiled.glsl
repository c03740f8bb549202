// The downsample for an exact 2:1 reduction (both source sides even, docs/BLOOM.md): every
// bilinear tap of cod13 and dual then sits on a corner shared by four source texels, so it is the
// mean of that 2x2 box. A workgroup loads its source window once into shared memory, forms the box
// means at every corner once, and each invocation reads its 13 (cod13) or 5 (dual) boxes from
// there, instead of 52 or 20 texel fetches. Same arithmetic as downsample() up to fp32 rounding.
// Requires bloom.glsl (BloomSource, source_texel, add_box, FILTER) to be included first.
#extension GL_EXT_control_flow_attributes : require

const uint TILE_W = 2u * gl_WorkGroupSize.x + 4u;  // source texels 2*x0-2 .. 2*(x0+W-1)+3
const uint TILE_H = 2u * gl_WorkGroupSize.y + 4u;
const uint BOX_W = TILE_W - 1u;                   // corners between them
const uint BOX_H = TILE_H - 1u;
const uint GROUP_SIZE = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
const uint LOADS_PER_INVOCATION = (TILE_W * TILE_H + GROUP_SIZE - 1u) / GROUP_SIZE;

shared vec4 s_texel[TILE_W * TILE_H];
shared vec4 s_box[BOX_W * BOX_H];

#define BOX_MEAN(i) s_box[i].rgb
#include "bloom_boxes.glsl"

// Every invocation of the workgroup must call this (it has barriers), inside the image or not.
vec3 downsample_2to1(texture2D src, BloomSource s, bool karis) {
  ivec2 origin = ivec2(gl_GlobalInvocationID.xy - gl_LocalInvocationID.xy) * 2 - 2;  // (see bloom_up_tiled)
  // All fetches are issued before the first store, so their latencies overlap.
  if (PREFETCH) {
    vec3 fetched[LOADS_PER_INVOCATION];
    [[unroll]] for (uint n = 0u; n < LOADS_PER_INVOCATION; ++n) {
      uint i = min(gl_LocalInvocationIndex + n * GROUP_SIZE, TILE_W * TILE_H - 1u);
      fetched[n] = source_texel(src, s, origin + ivec2(i % TILE_W, i / TILE_W));
    }
    [[unroll]] for (uint n = 0u; n < LOADS_PER_INVOCATION; ++n) {
      uint i = gl_LocalInvocationIndex + n * GROUP_SIZE;
      if (i < TILE_W * TILE_H) s_texel[i] = vec4(fetched[n], 0.0);
    }
  } else {
    [[dont_unroll]] for (uint i = gl_LocalInvocationIndex; i < TILE_W * TILE_H; i += GROUP_SIZE) {
      s_texel[i] = vec4(source_texel(src, s, origin + ivec2(i % TILE_W, i / TILE_W)), 0.0);
    }
  }
  barrier();
  for (uint i = gl_LocalInvocationIndex; i < BOX_W * BOX_H; i += GROUP_SIZE) {
    uint t = (i / BOX_W) * TILE_W + (i % BOX_W);
    s_box[i] = 0.25 * (s_texel[t] + s_texel[t + 1u] + s_texel[t + TILE_W] + s_texel[t + TILE_W + 1u]);
  }
  barrier();
  // Output (x, y) is centred on the corner between source texels 2x and 2x+1, which is corner
  // 2*lx + 2 of the window.
  ivec2 c = ivec2(gl_LocalInvocationID.xy) * 2 + 2;
  if (FILTER == GLINT_BLOOM_GAUSS9) {
    if (!karis) return s_box[uint(c.y) * BOX_W + uint(c.x)].rgb;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) add_box(sum, wsum, s_texel[uint(c.y + j) * TILE_W + uint(c.x + i)].rgb, 0.25, true);
    return sum / wsum;
  }
  return downsample_from_boxes(c, BOX_W, karis);
}

// The downsample of the invocation's texel: the shared-memory 2:1 path when it applies (a
// uniform branch), else the general one. Call from every invocation.
vec3 downsample_any(texture2D src, BloomSource s, ivec2 xy, ivec2 dst_size, bool inside, bool karis) {
  if (s.size == 2 * dst_size) return downsample_2to1(src, s, karis);
  return inside ? downsample(src, s, xy, dst_size, karis) : vec3(0.0);
}
