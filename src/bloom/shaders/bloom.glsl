// Bloom building blocks (docs/BLOOM.md). Every function takes what it reads as parameters: the
// including kernel declares its own bindings and push constants and passes them in. FILTER (the
// BloomFilter, specialization constant 2) selects the filter at pipeline creation.
#include "bloom_params.h"
#include "image_io.glsl"

layout(constant_id = 2) const uint FILTER = GLINT_BLOOM_COD13;
// The tiled kernels' load step: every fetch issued before the first shared store (GPUs: the
// latencies overlap), or a plain loop (CPU devices: invocations run in order as SIMD lanes, there
// is no latency to hide, and the unrolled loads multiply the code the device's JIT compiles).
// Both store the same values; the host sets it from the device type (specialization constant 3).
layout(constant_id = 3) const bool PREFETCH = true;

float luma(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// NaN and negatives to 0, then clamp each channel to GLINT_BLOOM_SOURCE_MAX (so +Inf and 1e9
// become 65504). max_brightness is applied later, to level 0 (docs/BLOOM.md "Prefilter"): a
// per-pixel clamp below the brightness of a point depends on how the point splits over pixels.
vec3 sanitize(vec3 c) {
  bvec3 bad = isnan(c);
  c = mix(c, vec3(0.0), bad);
  return clamp(c, vec3(0.0), vec3(GLINT_BLOOM_SOURCE_MAX));
}

// Soft knee, knee relative to the threshold as in Unity and Bevy (docs/BLOOM.md, "Prefilter").
vec3 soft_threshold(vec3 c, float threshold, float knee) {
  float l = luma(c);
  float soft = clamp(l - threshold + knee, 0.0, 2.0 * knee);
  float contribution = soft * soft / (4.0 * knee + 1e-4);
  float factor = max(l - threshold, contribution) / max(l, 1e-4);
  return c * factor;
}

// Where downsample() reads its source: texels of a texture of `size` texels, clamped to the image,
// and with bright_pass the prefilter of docs/BLOOM.md (sanitize, then soft_threshold with
// threshold and knee) applied to each texel before any filtering.
struct BloomSource {
  ivec2 size;
  bool bright_pass;
  float threshold;
  float knee;
};

vec3 source_texel(texture2D src, BloomSource s, ivec2 ij) {
  vec3 c = texelFetch(src, clamp(ij, ivec2(0), s.size - 1), 0).rgb;
  return s.bright_pass ? soft_threshold(sanitize(c), s.threshold, s.knee) : c;
}

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

// Bilinear blend of the four texels around a position whose fractional part is w.
vec3 bilinear_mix(vec3 a, vec3 b, vec3 c, vec3 d, vec2 w) { return mix(mix(a, b, w.x), mix(c, d, w.x), w.y); }

vec3 source_bilinear(texture2D src, BloomSource s, vec2 pos) {
  vec2 f = floor(pos);
  ivec2 i0 = ivec2(f);
  return bilinear_mix(source_texel(src, s, i0), source_texel(src, s, i0 + ivec2(1, 0)),
                      source_texel(src, s, i0 + ivec2(0, 1)), source_texel(src, s, i0 + ivec2(1, 1)), pos - f);
}

// Accumulates one "box" (docs/BLOOM.md, Karis guard): weight w, mean m.
void add_box(inout vec3 sum, inout float wsum, vec3 m, float w, bool karis) {
  float k = karis ? w / (1.0 + luma(m)) : w;
  sum += k * m;
  wsum += k;
}

// gauss9's area footprint of destination texel xy: the source interval [lo, hi) in texel-edge
// coordinates and the texels i0..i1 (inclusive) it touches; area_overlap() is the length of texel
// i's overlap with [lo, hi) on one axis. A texel's weight is the product of its two overlaps.
void area_footprint(ivec2 xy, ivec2 dst_size, ivec2 src_size, out vec2 lo, out vec2 hi, out ivec2 i0, out ivec2 i1) {
  vec2 s = vec2(src_size) / vec2(dst_size);
  lo = vec2(xy) * s;
  hi = vec2(xy + 1) * s;
  i0 = ivec2(floor(lo));
  i1 = ivec2(ceil(hi)) - 1;
}

float area_overlap(float lo, float hi, int i) { return min(float(i + 1), hi) - max(float(i), lo); }

// The filter's downsample of `src` to destination texel xy of a dst_size image (docs/BLOOM.md
// "Downsample"): gauss9's area average, dual's 5 bilinear taps, or cod13's 13 (Jimenez 2014).
// src/bloom/shaders/bloom_prefilter_smooth.comp repeats this arithmetic, expression for expression, on a
// source held in shared memory: keep the two the same.
vec3 downsample(texture2D src, BloomSource s, ivec2 xy, ivec2 dst_size, bool karis) {
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  if (FILTER == GLINT_BLOOM_GAUSS9) {
    vec2 lo, hi;
    ivec2 i0, i1;
    area_footprint(xy, dst_size, s.size, lo, hi, i0, i1);
    for (int j = i0.y; j <= i1.y; ++j) {
      float wy = area_overlap(lo.y, hi.y, j);
      for (int i = i0.x; i <= i1.x; ++i) {
        add_box(sum, wsum, source_texel(src, s, ivec2(i, j)), area_overlap(lo.x, hi.x, i) * wy, karis);
      }
    }
    return sum / wsum;
  }
  vec2 c = level_map(xy, dst_size, s.size);
  if (FILTER == GLINT_BLOOM_DUAL) {
    add_box(sum, wsum, source_bilinear(src, s, c), 0.5, karis);
    add_box(sum, wsum, source_bilinear(src, s, c + vec2(-1, -1)), 0.125, karis);
    add_box(sum, wsum, source_bilinear(src, s, c + vec2(1, -1)), 0.125, karis);
    add_box(sum, wsum, source_bilinear(src, s, c + vec2(-1, 1)), 0.125, karis);
    add_box(sum, wsum, source_bilinear(src, s, c + vec2(1, 1)), 0.125, karis);
    return sum / wsum;
  }
  // cod13: outer 3x3 grid at +-2 and the inner 2x2 at +-1.
  vec3 g[9];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) g[j * 3 + i] = source_bilinear(src, s, c + vec2(2 * i - 2, 2 * j - 2));
  vec3 inner = (source_bilinear(src, s, c + vec2(-1, -1)) + source_bilinear(src, s, c + vec2(1, -1)) +
                source_bilinear(src, s, c + vec2(-1, 1)) + source_bilinear(src, s, c + vec2(1, 1))) * 0.25;
  add_box(sum, wsum, inner, 0.5, karis);
  add_box(sum, wsum, (g[0] + g[1] + g[3] + g[4]) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g[1] + g[2] + g[4] + g[5]) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g[3] + g[4] + g[6] + g[7]) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g[4] + g[5] + g[7] + g[8]) * 0.25, 0.125, karis);
  return sum / wsum;
}

#ifdef OUTPUT_MAX
// The composite's rule for one output texel (docs/BLOOM.md "Composite"): scene + scale * bloom on
// RGB, the scene's alpha; a NaN scene channel counts as 0 and every channel is clamped to
// +-OUTPUT_MAX (the output format's largest finite value, set per kernel variant), so the output
// is finite even where the scene is not.
vec4 composite_texel(vec4 scene, vec3 bloom, float scale) {
  scene = mix(scene, vec4(0.0), isnan(scene));
  return clamp(vec4(scene.rgb + scale * bloom, scene.a), vec4(-OUTPUT_MAX), vec4(OUTPUT_MAX));
}
#endif
