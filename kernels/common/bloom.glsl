// Bloom building blocks (docs/BLOOM.md). A kernel that includes this defines
//   vec3 source_texel(ivec2 ij)   // the (possibly prefiltered) source texel, ij already clamped
// before including it, and declares push constants `p` of type BloomPush.
#include "bloom_params.h"
#include "image_io.glsl"

layout(constant_id = 2) const uint FILTER = GLINT_BLOOM_COD13;

float luma(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// NaN and negatives to 0, then clamp each channel to GLINT_BLOOM_SOURCE_MAX (so +Inf and 1e9
// become 65504). max_brightness is applied later, to level 0 (docs/BLOOM.md "Prefilter"): a
// per-pixel clamp below the brightness of a point depends on how the point splits over pixels.
vec3 sanitize(vec3 c) {
  bvec3 bad = isnan(c);
  c = mix(c, vec3(0.0), bad);
  return clamp(c, vec3(0.0), vec3(GLINT_BLOOM_SOURCE_MAX));
}

// Seed 001's soft knee, knee relative to threshold (docs/BLOOM.md, "Prefilter").
vec3 soft_threshold(vec3 c, float threshold, float knee) {
  float l = luma(c);
  float soft = clamp(l - threshold + knee, 0.0, 2.0 * knee);
  float contribution = soft * soft / (4.0 * knee + 1e-4);
  float factor = max(l - threshold, contribution) / max(l, 1e-4);
  return c * factor;
}

ivec2 g_src_size;

// Position in the source of size `s` of texel x of the destination of size `d`, one axis
// (docs/BLOOM.md "Notation", dual). Between n and floor(n / 2) texels the dual filter maps with the
// exact ratio 2 (or 1/2), the grids aligned at texel 0 (at odd n the larger one's last texel lies
// past the smaller grid's end and is read through the clamp). Every tap then sits on a corner
// between texels, where each sub-sum of the 2-D taps carries the same mass whatever a point's
// position; the same-UV map (ratio n / floor(n / 2), slightly above 2) lets the mass of the
// diagonal taps, which couple the axes, depend on a point's row, and moved a point's glow along x
// by up to 2 pixels at 960x540. At even n both maps are the same bit for bit.
float dual_map_1d(int x, int d, int s) {
  if (s > 1 && d == s / 2) return 2.0 * float(x) + 0.5;
  if (d > 1 && s == d / 2) return (float(x) + 0.5) * 0.5 - 0.5;
  return (float(x) + 0.5) * (float(s) / float(d)) - 0.5;
}

// map_position() for every filter but dual, dual_map_1d() per axis for dual.
vec2 level_map(ivec2 xy, ivec2 dst, ivec2 src) {
  if (FILTER != GLINT_BLOOM_DUAL) return map_position(xy, dst, src);
  return vec2(dual_map_1d(xy.x, dst.x, src.x), dual_map_1d(xy.y, dst.y, src.y));
}

vec3 src_at(ivec2 ij) { return source_texel(clamp(ij, ivec2(0), g_src_size - 1)); }

vec3 src_bilinear(vec2 pos) {
  vec2 f = floor(pos);
  vec2 w = pos - f;
  ivec2 i0 = ivec2(f);
  vec3 a = src_at(i0);
  vec3 b = src_at(i0 + ivec2(1, 0));
  vec3 c = src_at(i0 + ivec2(0, 1));
  vec3 d = src_at(i0 + ivec2(1, 1));
  return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

// Accumulates one "box" (docs/BLOOM.md, Karis guard): weight w, mean m.
void add_box(inout vec3 sum, inout float wsum, vec3 m, float w, bool karis) {
  float k = karis ? w / (1.0 + luma(m)) : w;
  sum += k * m;
  wsum += k;
}

vec3 downsample(ivec2 xy, ivec2 dst_size, bool karis) {
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  if (FILTER == GLINT_BLOOM_GAUSS9) {
    // Area average: every source texel weighted by its overlap with the destination footprint.
    vec2 s = vec2(g_src_size) / vec2(dst_size);
    vec2 lo = vec2(xy) * s;
    vec2 hi = vec2(xy + 1) * s;
    ivec2 i0 = ivec2(floor(lo));
    ivec2 i1 = ivec2(ceil(hi)) - 1;
    for (int j = i0.y; j <= i1.y; ++j) {
      float wy = min(float(j + 1), hi.y) - max(float(j), lo.y);
      for (int i = i0.x; i <= i1.x; ++i) {
        float wx = min(float(i + 1), hi.x) - max(float(i), lo.x);
        add_box(sum, wsum, src_at(ivec2(i, j)), wx * wy, karis);
      }
    }
    return sum / wsum;
  }
  vec2 c = level_map(xy, dst_size, g_src_size);
  if (FILTER == GLINT_BLOOM_DUAL) {
    add_box(sum, wsum, src_bilinear(c), 0.5, karis);
    add_box(sum, wsum, src_bilinear(c + vec2(-1, -1)), 0.125, karis);
    add_box(sum, wsum, src_bilinear(c + vec2(1, -1)), 0.125, karis);
    add_box(sum, wsum, src_bilinear(c + vec2(-1, 1)), 0.125, karis);
    add_box(sum, wsum, src_bilinear(c + vec2(1, 1)), 0.125, karis);
    return sum / wsum;
  }
  // cod13: outer 3x3 grid at +-2 and the inner 2x2 at +-1 (Jimenez 2014).
  vec3 g[9];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) g[j * 3 + i] = src_bilinear(c + vec2(2 * i - 2, 2 * j - 2));
  vec3 inner = (src_bilinear(c + vec2(-1, -1)) + src_bilinear(c + vec2(1, -1)) +
                src_bilinear(c + vec2(-1, 1)) + src_bilinear(c + vec2(1, 1))) * 0.25;
  add_box(sum, wsum, inner, 0.5, karis);
  add_box(sum, wsum, (g[0] + g[1] + g[3] + g[4]) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g[1] + g[2] + g[4] + g[5]) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g[3] + g[4] + g[6] + g[7]) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g[4] + g[5] + g[7] + g[8]) * 0.25, 0.125, karis);
  return sum / wsum;
}
