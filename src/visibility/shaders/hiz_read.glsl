// Reading the Hi-Z pyramid, shared by the light cull (light_cull.comp) and the object cull
// (object_cull.comp). The includer declares `depth_tex` (level 0, the caller's depth image) and
// `hiz_tex` (mip m = Hi-Z level m + 1) as texture2D before including this file.
// Level k is max(1, size >> k) on a side; texel c of level k holds the farthest depth of source
// pixels [c * 2^k, (c + 1) * 2^k), the last texel of a row or column up to the edge (the fold rule
// of hiz_build.comp), so pixel p lies in texel min(p >> k, level size - 1).
#ifndef GLINT_HIZ_READ_GLSL
#define GLINT_HIZ_READ_GLSL

// Not NaN, not +-Inf, tested on the bits: a compiler that assumes floats are finite may fold
// x == x, or invert a comparison so that NaN passes it (docs/OCCLUSION.md, "Non-finite input").
bool cull_finite(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }

// Texel t of Hi-Z level k (0: the depth image).
float fetch_level(int k, ivec2 t) {
  return k == 0 ? texelFetch(depth_tex, t, 0).r : texelFetch(hiz_tex, t, k - 1).r;
}

// The corners of the window [t0, t1] of level k (at most 2x2 texels: a 1-texel side reads its
// texel twice): (t0.x, t0.y), (t1.x, t0.y), (t0.x, t1.y), (t1.x, t1.y). Four fetches with no
// dependence between them, so that their latencies overlap.
vec4 hiz_corners(int k, ivec2 t0, ivec2 t1) {
  if (k == 0) {
    return vec4(texelFetch(depth_tex, t0, 0).r, texelFetch(depth_tex, ivec2(t1.x, t0.y), 0).r,
                texelFetch(depth_tex, ivec2(t0.x, t1.y), 0).r, texelFetch(depth_tex, t1, 0).r);
  }
  return vec4(texelFetch(hiz_tex, t0, k - 1).r, texelFetch(hiz_tex, ivec2(t1.x, t0.y), k - 1).r,
              texelFetch(hiz_tex, ivec2(t0.x, t1.y), k - 1).r, texelFetch(hiz_tex, t1, k - 1).r);
}

// The first level at which a span of `span` >= 1 pixels touches at most 2 texels, wherever it lies:
// the smallest k with span - 1 <= 2^k (in integers, exactly).
int hiz_span_level(int span) { return span <= 2 ? 0 : findMSB(span - 2) + 1; }

// Smallest k with 2^k >= s (s >= 1), exactly: s = m * 2^e with m in [0.5, 1).
int ceil_log2(float s) {
  int e;
  const float m = frexp(s, e);
  return m == 0.5 ? e - 1 : e;
}

// Texels of level k (size `lsize`) under pixels [lo, hi) of one axis, clamped to the image (clamp
// to edge); `pixels` is the level-0 size of that axis.
ivec2 texel_range(float lo, float hi, int k, int pixels, int lsize) {
  const int p0 = clamp(int(floor(lo)), 0, pixels - 1);
  const int p1 = clamp(int(ceil(hi)) - 1, 0, pixels - 1);
  return ivec2(min(p0 >> k, lsize - 1), min(max(p0, p1) >> k, lsize - 1));
}

#endif
