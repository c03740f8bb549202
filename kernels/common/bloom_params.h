// Push constants of every bloom kernel (kernels/bloom_*.comp), shared with host/bloom.cpp.
#ifndef GLINT_BLOOM_PARAMS_H
#define GLINT_BLOOM_PARAMS_H
#include "glint_types.h"

// BloomPush::flags bits.
#define GLINT_BLOOM_FLAG_KARIS 1u       // Karis average (first downsample only)
#define GLINT_BLOOM_FLAG_VERTICAL 2u    // gauss9 blur direction

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
  GLINT_FLOAT max_brightness;
  GLINT_FLOAT radius;      // upsample / gauss9 footprint scale
  GLINT_FLOAT composite_scale;  // intensity / levels
  GLINT_UINT flags;
  GLINT_UINT reserved0;
  GLINT_UINT reserved1;
};

#endif
