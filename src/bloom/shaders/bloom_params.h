// Push constants of every bloom kernel (src/bloom/shaders/bloom_*.comp), shared with src/bloom/bloom.cpp.
#ifndef GLINT_BLOOM_PARAMS_H
#define GLINT_BLOOM_PARAMS_H
#include "glint/gpu/types.h"

// BloomPush::flags bits.
#define GLINT_BLOOM_FLAG_KARIS 1u       // Karis average (first downsample only)
#define GLINT_BLOOM_FLAG_VERTICAL 2u    // gauss9 blur direction
#define GLINT_BLOOM_FLAG_LEVEL0_DONE 4u  // bloom_composite_up: level 0 already holds A(0); level 1 is not read

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
  GLINT_INT next_width;    // bloom_composite_up: size of level 1 (A(1)), read to evaluate A(0)
  GLINT_INT next_height;
};

// The most levels a bloom has (BloomConfig::iterations).
#define GLINT_BLOOM_MAX_LEVELS 8

// Push constants of src/bloom/shaders/bloom_tail.comp, the small levels in one workgroup
// (docs/BLOOM.md "Dispatches"). Level T is the image the kernel reads and accumulates into;
// levels T+1 .. T+count live in shared memory.
struct BloomTailPush {
  GLINT_INT count;         // levels below T (1 to GLINT_BLOOM_MAX_LEVELS - 1)
  GLINT_FLOAT radius;      // upsample / gauss9 footprint scale
  GLINT_UINT reserved0;
  GLINT_UINT reserved1;
  GLINT_INT sizes[2 * GLINT_BLOOM_MAX_LEVELS];  // (width, height) of level T, then of T+1 .. T+count
};

#endif
