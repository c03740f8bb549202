#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The composite with the last two upsamples fused (docs/BLOOM.md "Dispatches"):
// out = scene + intensity / N * Up(A(0)), A(0) = level 0 + Up(A(1)), with A(0) evaluated here on
// the window of level 0 that the workgroup's tile reaches instead of being written by an
// upsample dispatch and read back: one dispatch and one write and read of level 0 fewer. With
// GLINT_BLOOM_FLAG_LEVEL0_DONE, level 0 already holds A(0) (one level, or the small levels'
// dispatch ended at level 0) and level 1 is not read. The rest is bloom_composite.comp.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1) uniform texture2D level0;
#include "dst_image.glsl"
DST_LAYOUT(2) uniform writeonly image2D result;
layout(binding = 3) uniform texture2D level1;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"

// The window of A(1) that the level 0 window reaches. Level 0's window spans at most
// gl_WorkGroupSize + 10 texels (bloom_up_tiled.glsl), level 1 is at most half of level 0 (floor)
// and the reach is at most radius 4 a side plus the bilinear neighbour: (size + 9) / 2 + 2 * 4 + 3
// texels, one more for safety.
const uint WIN1_W = (gl_WorkGroupSize.x + 9u) / 2u + 12u;
const uint WIN1_H = (gl_WorkGroupSize.y + 9u) / 2u + 12u;
// Before the upsample, the arrays of bloom_up_tiled.glsl hold the A(1) window (cod13: s_src;
// dual, gauss9: s_rows) and cod13's horizontal pass of it (s_rows), so they are made large enough.
#define UP_WIN_TEXELS ((gl_WorkGroupSize.x + 10u) * (gl_WorkGroupSize.y + 10u))
#define UP_SRC_SIZE (UP_WIN_TEXELS > WIN1_W * WIN1_H ? UP_WIN_TEXELS : WIN1_W * WIN1_H)
#define UP_ROWS_A (gl_WorkGroupSize.x * (gl_WorkGroupSize.y + 10u))
#define UP_ROWS_B ((gl_WorkGroupSize.x + 10u) * WIN1_H)
#define UP_ROWS_C (UP_ROWS_A > UP_ROWS_B ? UP_ROWS_A : UP_ROWS_B)
#define UP_ROWS_SIZE (UP_ROWS_C > WIN1_W * WIN1_H ? UP_ROWS_C : WIN1_W * WIN1_H)
#include "bloom_up_tiled.glsl"

// Bilinear from the A(1) window held in `s_rows` (dual, gauss9).
vec3 bilinear_next(vec2 q, ivec2 lo) {
  vec2 f = floor(q);
  vec2 w = q - f;
  uint i = uint(int(f.y) - lo.y) * WIN1_W + uint(int(f.x) - lo.x);
  vec3 a = s_rows[i].rgb, b = s_rows[i + 1u].rgb, c = s_rows[i + WIN1_W].rgb, d = s_rows[i + WIN1_W + 1u].rgb;
  return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

// Up(A(1)) at level 0 texel ij for dual and gauss9 (docs/BLOOM.md "Upsample and accumulate"): the
// sum of the definition, from the window.
vec3 up_next_direct(ivec2 ij, ivec2 size0, ivec2 size1, ivec2 lo1, float radius) {
  vec2 c = level_map(ij, size0, size1);
  if (FILTER == GLINT_BLOOM_GAUSS9) return bilinear_next(c, lo1);
  vec3 edges = bilinear_next(c + radius * vec2(-1, 0), lo1) + bilinear_next(c + radius * vec2(1, 0), lo1) +
               bilinear_next(c + radius * vec2(0, -1), lo1) + bilinear_next(c + radius * vec2(0, 1), lo1);
  vec3 diagonals = bilinear_next(c + radius * vec2(-0.5, -0.5), lo1) + bilinear_next(c + radius * vec2(0.5, -0.5), lo1) +
                   bilinear_next(c + radius * vec2(-0.5, 0.5), lo1) + bilinear_next(c + radius * vec2(0.5, 0.5), lo1);
  return (edges + 2.0 * diagonals) / 12.0;
}

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(p.dst_width, p.dst_height);
  ivec2 size0 = ivec2(p.src_width, p.src_height);
  vec4 s = texelFetch(scene, min(xy, size - 1), 0);  // issued first: its latency overlaps the tile work
  ivec2 lo, win;
  up_window(size0, size, p.radius, lo, win);
  // Level 0 texels of the window, clamped: the ones A(0) is needed at.
  ivec2 c_lo = clamp(lo, ivec2(0), size0 - 1);
  ivec2 c_hi = clamp(lo + win - 1, ivec2(0), size0 - 1);
  bool done = (p.flags & GLINT_BLOOM_FLAG_LEVEL0_DONE) != 0u;  // uniform
  ivec2 size1 = ivec2(p.next_width, p.next_height);
  ivec2 lo1 = ivec2(0);
  if (!done) {
    float reach = FILTER == GLINT_BLOOM_GAUSS9 ? 0.0 : p.radius;
    lo1 = ivec2(floor(level_map(c_lo, size0, size1) - reach));
    ivec2 win1 = ivec2(floor(level_map(c_hi, size0, size1) + reach)) + 2 - lo1;
    for (uint i = gl_LocalInvocationIndex; i < uint(win1.x * win1.y); i += UP_GROUP_SIZE) {
      ivec2 t = ivec2(int(i) % win1.x, int(i) / win1.x);
      vec4 v = fetch_clamped(level1, lo1 + t, size1);
      if (FILTER == GLINT_BLOOM_COD13) {
        s_src[uint(t.y) * WIN1_W + uint(t.x)] = v;
      } else {
        s_rows[uint(t.y) * WIN1_W + uint(t.x)] = v;
      }
    }
    barrier();
    if (FILTER == GLINT_BLOOM_COD13) {
      // The 3x3 tent is separable (bloom_up_tiled.glsl): horizontally, for each window column of
      // level 0 and each row of the A(1) window, into s_rows (row stride WIN_W) ...
      float sx = float(size1.x) / float(size0.x);
      for (uint i = gl_LocalInvocationIndex; i < uint(win.x * win1.y); i += UP_GROUP_SIZE) {
        int col = int(i) % win.x, row = int(i) / win.x;
        float px = (float(clamp(lo.x + col, 0, size0.x - 1)) + 0.5) * sx - 0.5;
        vec4 acc = vec4(0.0);
        for (int a = 0; a < 3; ++a) {
          float q = px + p.radius * tap_offset(a);
          float f = floor(q);
          uint k = uint(row) * WIN1_W + uint(int(f) - lo1.x);
          acc += tap_weight(a) * mix(s_src[k], s_src[k + 1u], q - f);
        }
        s_rows[uint(row) * WIN_W + uint(col)] = acc;
      }
      barrier();
    }
  }
  // ... then A(0) = level 0 + Up(A(1)) at each texel of the level 0 window (cod13: the vertical
  // pass), into s_src for the upsample to full resolution.
  float sy = float(size1.y) / float(size0.y);
  for (uint i = gl_LocalInvocationIndex; i < uint(win.x * win.y); i += UP_GROUP_SIZE) {
    ivec2 t = ivec2(int(i) % win.x, int(i) / win.x);
    ivec2 ij = clamp(lo + t, ivec2(0), size0 - 1);
    vec4 a = fetch_clamped(level0, ij, size0);
    if (!done) {
      if (FILTER == GLINT_BLOOM_COD13) {
        float py = (float(ij.y) + 0.5) * sy - 0.5;
        vec3 sum = vec3(0.0);
        for (int b = 0; b < 3; ++b) {
          float q = py + p.radius * tap_offset(b);
          float f = floor(q);
          uint k = uint(int(f) - lo1.y) * WIN_W + uint(t.x);
          sum += tap_weight(b) * mix(s_rows[k].rgb, s_rows[k + WIN_W].rgb, q - f);
        }
        a.rgb += sum;
      } else {
        a.rgb += up_next_direct(ij, size0, size1, lo1, p.radius);
      }
    }
    s_src[uint(t.y) * WIN_W + uint(t.x)] = a;
  }
  vec3 bloom = upsample_window(size0, size, p.radius, lo, win);
  if (any(greaterThanEqual(xy, size))) return;  // after the barriers inside upsample_window
  imageStore(result, xy, composite_texel(s, bloom, p.composite_scale));
}
