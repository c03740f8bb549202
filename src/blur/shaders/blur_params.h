// Push constants of the blur kernels (src/blur/shaders/blur_*.comp), shared with src/blur/blur_steps.h
// (CONTRIBUTING.md, "Shared structs"). The algorithms are in docs/BLUR.md.
#ifndef GLINT_BLUR_PARAMS_H
#define GLINT_BLUR_PARAMS_H
#include "glint/gpu/types.h"

// BlurPush::flags bits.
#define GLINT_BLUR_FLAG_SANITIZE 1u  // the source is the caller's input: NaN -> 0, clamp to +-max_value
#define GLINT_BLUR_FLAG_VERTICAL 2u  // line / linear kernels: filter along y

// Largest radius whose half-taps fit BlurPush::weights (the fused kernel's taps).
#define GLINT_BLUR_PUSH_TAPS 16

struct BlurPush {
  GLINT_INT src_width;   // size of the image read
  GLINT_INT src_height;
  GLINT_INT dst_width;   // size of the image written
  GLINT_INT dst_height;
  GLINT_FLOAT max_value; // sanitize clamp
  GLINT_UINT flags;
  GLINT_FLOAT offset;    // dual: tap offset o
  GLINT_UINT tap_count;  // line: radius R (weights in the tap buffer); linear: fetches per side
  GLINT_FLOAT weights[GLINT_BLUR_PUSH_TAPS];  // fused: w[0..R]
  // Where a destination texel reads the source (docs/BLUR.md "Borders"): destination texel xy is
  // texel xy + dst_origin of a virtual destination, whose position maps to the virtual source at
  // (xy + dst_origin + 0.5) * ratio - 0.5 (ratio = virtual source size / virtual destination
  // size), which is the real source's texel position minus src_origin. All zero origins and
  // ratio = src size / dst size unless the step reads or writes a padded chain's caller image.
  GLINT_INT src_origin_x;
  GLINT_INT src_origin_y;
  GLINT_INT dst_origin_x;
  GLINT_INT dst_origin_y;
  GLINT_FLOAT ratio_x;
  GLINT_FLOAT ratio_y;
  GLINT_INT band_rows;   // streamed kernels (blur_*stream.comp): rows each workgroup walks
};

#endif
