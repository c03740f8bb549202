// Push constants of every bloom kernel (src/bloom/shaders/bloom_*.comp), shared with src/bloom/bloom.cpp.
#ifndef GLINT_BLOOM_PARAMS_H
#define GLINT_BLOOM_PARAMS_H
#include "glint/gpu/types.h"

// BloomPush::flags bits.
#define GLINT_BLOOM_FLAG_KARIS 1u       // Karis average (first downsample only)
#define GLINT_BLOOM_FLAG_VERTICAL 2u    // gauss9 blur direction

// Per-channel clamp of every full-resolution source texel (the largest fp16 value); max_brightness
// clamps level 0 (docs/BLOOM.md "Prefilter").
#define GLINT_BLOOM_SOURCE_MAX 65504.0

// Radius of the binomial prefilter of the karis_smooth guard (11 taps, weights C(10, k) / 1024).
#define GLINT_BLOOM_SMOOTH_RADIUS 5

// Filter ids (specialization constant 2); the same values as glint::BloomFilter.
#define GLINT_BLOOM_COD13 0u
#define GLINT_BLOOM_DUAL 1u
#define GLINT_BLOOM_GAUSS9 2u

struct BloomPush {
  GLINT_INT src_width;     // size of the image read
  GLINT_INT src_height;
  GLINT_INT dst_width;     // size of the image written
  GLINT_INT dst_height;
  GLINT_FLOAT threshold;   // prefilter: luminance threshold
  GLINT_FLOAT knee;        // prefilter: threshold * soft_knee
  GLINT_FLOAT max_brightness;  // per-channel clamp of level 0
  GLINT_FLOAT radius;      // upsample / gauss9 footprint scale
  GLINT_FLOAT composite_scale;  // intensity / levels
  GLINT_UINT flags;
  GLINT_UINT reserved0;
  GLINT_UINT reserved1;
};

#endif
