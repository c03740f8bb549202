#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// The pyramid method's last step (docs/BLUR.md, "pyramid"): the blurred level brought to full
// resolution at the same normalized coordinate by a uniform cubic B-spline (4x4 texels, exact
// fp32 weights). Unlike bilinear magnification it leaves no kinks at level texel centres (C2),
// and its variance is part of the method's sigma bookkeeping.
//
// The B-spline is separable, and a tile of outputs magnified by 2^k >= 2 reads a small footprint
// of the level, so a workgroup computes its tile in three steps instead of 16 fetches per output:
// 1. it loads the footprint (at most TW / 2 + 4 by TH / 2 + 4 texels) into shared memory;
// 2. for each footprint row and each output column, the row's 4-tap horizontal B-spline;
// 3. for each output, the 4-tap vertical B-spline of those rows, and the one write.
// The sums are the direct form's, in its order (each row's four products, then the rows' weighted
// sum), so the result is the same up to the compiler's contraction. The magnification is 2^k on
// both axes (the padded chain, docs/BLUR.md "Borders"; upsample_step() checks it is at least 2).
// H100, 3840x2160 RGBA16F output: 159 us with 16 fetches per output, 57 to 69 us this way
// (single-frame stage marks, docs/PERF.md).
layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(constant_id = 2) const int ROWS = 1;  // output rows per invocation: tile = (WG.x, WG.y * ROWS)
// Every fetch of the load step issued before the first shared store (GPUs), or a plain loop (CPU
// devices), as blur_down.comp.
layout(constant_id = 3) const bool PREFETCH = true;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

const int TW = int(gl_WorkGroupSize.x);
const int TH = int(gl_WorkGroupSize.y) * ROWS;
const int GROUP_SIZE = int(gl_WorkGroupSize.x) * int(gl_WorkGroupSize.y);
// Footprint of a tile at a magnification of at least 2: its outputs' positions span at most
// (TW - 1) / 2 level texels, so floor() takes at most TW / 2 + 1 values, each reading 4 texels
// from floor - 1 on.
const int FW = TW / 2 + 4;
const int FH = TH / 2 + 4;
const int LOADS = (FW * FH + GROUP_SIZE - 1) / GROUP_SIZE;  // most footprint texels per invocation
shared vec4 s_src[FH * FW];                                 // the footprint, row-major
shared vec4 s_row[FH * TW];  // step 2: footprint row j, output column x at j * TW + x

void main() {
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  const ivec2 tile = ivec2(gl_WorkGroupID.xy) * ivec2(TW, TH);
  const ivec2 last = min(tile + ivec2(TW, TH), size) - 1;  // the tile's last output inside the image
  const int lx = int(gl_LocalInvocationID.x), ly = int(gl_LocalInvocationID.y);
  // The source position is monotone along each axis: the footprint runs from the first output's
  // floor - 1 to the last one's floor + 2.
  const ivec2 f0 = ivec2(floor(source_position(tile))) - 1;
  const ivec2 fs = ivec2(floor(source_position(last))) + 3 - f0;  // <= (FW, FH)
  // 1. The footprint, clamped to the level as the direct form's fetches are.
  const int local = int(gl_LocalInvocationIndex), count = fs.x * fs.y;
  if (PREFETCH) {
    vec4 fetched[LOADS];
    [[unroll]] for (int n = 0; n < LOADS; ++n) {
      const int i = min(local + n * GROUP_SIZE, count - 1);
      fetched[n] = src_texel(f0 + ivec2(i % fs.x, i / fs.x));
    }
    [[unroll]] for (int n = 0; n < LOADS; ++n) {
      const int i = local + n * GROUP_SIZE;
      if (i < count) s_src[(i / fs.x) * FW + i % fs.x] = fetched[n];
    }
  } else {
    [[dont_unroll]] for (int i = local; i < count; i += GROUP_SIZE) {
      s_src[(i / fs.x) * FW + i % fs.x] = src_texel(f0 + ivec2(i % fs.x, i / fs.x));
    }
  }
  barrier();
  // 2. Column tile.x + lx of every footprint row. A column beyond the image (not written) reads
  //    the footprint's last four texels.
  const float qx = source_position(ivec2(min(tile.x + lx, last.x), tile.y)).x;
  const float fx = floor(qx);
  const vec4 wx = bspline_weights(qx - fx);
  const int c = int(fx) - 1 - f0.x;
  for (int j = ly; j < fs.y; j += int(gl_WorkGroupSize.y)) {
    const int b = j * FW + c;
    s_row[j * TW + lx] = bspline_row(wx, s_src[b], s_src[b + 1], s_src[b + 2], s_src[b + 3]);
  }
  barrier();
  // 3. ROWS outputs of column tile.x + lx.
  for (int r = 0; r < ROWS; ++r) {
    const ivec2 xy = tile + ivec2(lx, ly * ROWS + r);
    const float qy = source_position(ivec2(tile.x, min(xy.y, last.y))).y;
    const float fy = floor(qy);
    const vec4 wy = bspline_weights(qy - fy);
    const int b = (int(fy) - 1 - f0.y) * TW + lx;
    const vec4 sum = bspline_column(wy, s_row[b], s_row[b + TW], s_row[b + 2 * TW], s_row[b + 3 * TW]);
    if (all(lessThanEqual(xy, last))) imageStore(dst, xy, sum);
  }
}
