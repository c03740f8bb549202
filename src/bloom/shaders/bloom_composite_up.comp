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
#include "bloom_up_tiled.glsl"

// The window of A(1) that the level 0 window reaches. Level 0's window spans at most WIN_W texels
// (bloom_up_tiled.glsl), level 1 is at most half of level 0 (floor) and the reach is at most
// radius 4 a side plus the bilinear neighbour: (WIN_W - 1) / 2 + 2 * 4 + 3 texels, rounded up.
const uint WIN1_W = (WIN_W - 1u) / 2u + 12u;
const uint WIN1_H = (WIN_H - 1u) / 2u + 12u;
shared vec4 s_next[WIN1_W * WIN1_H];

vec3 bilinear_next(vec2 q, ivec2 lo) {
  vec2 f = floor(q);
  vec2 w = q - f;
  uint i = uint(int(f.y) - lo.y) * WIN1_W + uint(int(f.x) - lo.x);
  vec3 a = s_next[i].rgb, b = s_next[i + 1u].rgb, c = s_next[i + WIN1_W].rgb, d = s_next[i + WIN1_W + 1u].rgb;
  return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

// Up(A(1)) at level 0 texel ij (docs/BLOOM.md "Upsample and accumulate"), the 2-D sum of the
// definition from the A(1) window.
vec3 up_next(ivec2 ij, ivec2 size0, ivec2 size1, ivec2 lo1, float radius) {
  vec2 c = level_map(ij, size0, size1);
  if (FILTER == GLINT_BLOOM_GAUSS9) return bilinear_next(c, lo1);
  if (FILTER == GLINT_BLOOM_DUAL) {
    vec3 edges = bilinear_next(c + radius * vec2(-1, 0), lo1) + bilinear_next(c + radius * vec2(1, 0), lo1) +
                 bilinear_next(c + radius * vec2(0, -1), lo1) + bilinear_next(c + radius * vec2(0, 1), lo1);
    vec3 diagonals = bilinear_next(c + radius * vec2(-0.5, -0.5), lo1) +
                     bilinear_next(c + radius * vec2(0.5, -0.5), lo1) +
                     bilinear_next(c + radius * vec2(-0.5, 0.5), lo1) + bilinear_next(c + radius * vec2(0.5, 0.5), lo1);
    return (edges + 2.0 * diagonals) / 12.0;
  }
  vec3 sum = vec3(0.0);
  for (int b = 0; b < 3; ++b) {
    vec3 row = vec3(0.0);
    for (int a = 0; a < 3; ++a) row += tap_weight(a) * bilinear_next(c + radius * vec2(a - 1, b - 1), lo1);
    sum += tap_weight(b) * row;
  }
  return sum;
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
      s_next[uint(t.y) * WIN1_W + uint(t.x)] = fetch_clamped(level1, lo1 + t, size1);
    }
    barrier();
  }
  for (uint i = gl_LocalInvocationIndex; i < uint(win.x * win.y); i += UP_GROUP_SIZE) {
    ivec2 t = ivec2(int(i) % win.x, int(i) / win.x);
    ivec2 ij = clamp(lo + t, ivec2(0), size0 - 1);
    vec4 a = fetch_clamped(level0, ij, size0);
    if (!done) a.rgb += up_next(ij, size0, size1, lo1, p.radius);
    s_src[uint(t.y) * WIN_W + uint(t.x)] = a;
  }
  vec3 bloom = upsample_window(size0, size, p.radius, lo, win);
  if (any(greaterThanEqual(xy, size))) return;  // after the barriers inside upsample_window
  s = mix(s, vec4(0.0), isnan(s));
  vec4 o = vec4(s.rgb + p.composite_scale * bloom, s.a);
  imageStore(result, xy, clamp(o, vec4(-OUTPUT_MAX), vec4(OUTPUT_MAX)));
}
