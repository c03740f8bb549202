#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The pyramid method's B-spline upsample (docs/BLUR.md, "pyramid"), the same sums as
// blur_upsample.comp in the same order (blur.glsl, bspline_row and bspline_column), walking the
// image instead of tiling it: an invocation owns one output column and every gl_WorkGroupSize.y-th
// row of a band of p.band_rows rows, from row gl_LocalInvocationID.y of the band on. At a
// magnification of 2^k >= 2 an output column reads four level texels a level row, and going down by
// one of its rows moves its four level rows by at most one (the host's workgroups are 2 high), so
// the invocation keeps the four rows' horizontal B-spline sums in registers and, when the rows
// move, forms the new row's sum: four fetches per level row, no shared memory and no barrier. Each
// output is the vertical B-spline of the four sums and its one write. Where subgroups take
// consecutive invocations, as NVIDIA's 32-wide ones do, a workgroup 16 wide and 2 high puts two
// adjacent rows in each subgroup, so a store can fill whole 32-byte sectors of a 2D tiling whose
// sectors span two rows (NVIDIA's block-linear layout, as open drivers describe it) where one row
// fills halves: on the H100, 16x2 against 64x1 took the 2x upsample from 75 to 69
// us and the 8x one from 59 to 46 us at 3840x2160, bands of 16 rows both (docs/BLUR.md).
// blur_upsample.comp instead loads a tile's footprint into shared memory and waits at two barriers
// per tile; this kernel runs where the host picks it (src/blur/blur_steps.cpp, upsample_step).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

// Level row j's horizontal B-spline sum from texel c on, with weights w.
vec4 row_sum(int j, int c, vec4 w) {
  return bspline_row(w, src_texel(ivec2(c, j)), src_texel(ivec2(c + 1, j)), src_texel(ivec2(c + 2, j)),
                     src_texel(ivec2(c + 3, j)));
}

void main() {
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  const int x = int(gl_GlobalInvocationID.x);
  const int step = int(gl_WorkGroupSize.y);
  const int band = int(gl_WorkGroupID.y) * p.band_rows;
  const int y0 = band + int(gl_LocalInvocationID.y);
  if (x >= size.x || y0 >= size.y) return;
  const int y1 = min(band + p.band_rows, size.y);
  // The column's level position (source_position's x does not depend on y) and weights.
  const float qx = source_position(ivec2(x, y0)).x;
  const int c = int(floor(qx)) - 1;
  const vec4 wx = bspline_weights(qx - floor(qx));
  // Level rows f - 1 .. f + 2 of the current f = floor(qy), summed along x.
  int f = int(floor(source_position(ivec2(x, y0)).y));
  vec4 h0 = row_sum(f - 1, c, wx), h1 = row_sum(f, c, wx), h2 = row_sum(f + 1, c, wx), h3 = row_sum(f + 2, c, wx);
  for (int y = y0; y < y1; y += step) {
    const float qy = source_position(ivec2(x, y)).y;
    const float fy = floor(qy);
    // The rows move one at a time; the test is the same in every invocation of a row, so it does
    // not diverge within a row of the workgroup.
    while (f < int(fy)) {
      ++f;
      h0 = h1, h1 = h2, h2 = h3;
      h3 = row_sum(f + 2, c, wx);
    }
    imageStore(dst, ivec2(x, y), bspline_column(bspline_weights(qy - fy), h0, h1, h2, h3));
  }
}
