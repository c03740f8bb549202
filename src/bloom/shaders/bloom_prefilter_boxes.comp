#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Bright-pass, binomial prefilter and Karis-guarded first downsample for firefly_guard =
// karis_smooth at an exact 2:1 reduction (both source sides twice the level's) with cod13 or dual
// (docs/BLOOM.md "Karis guard"): full-resolution scene -> level 0. Same result as
// src/bloom/shaders/bloom_prefilter_smooth.comp (which handles every other case) up to fp32 rounding, with
// far less work and shared memory:
//
// At 2:1 every bilinear tap of cod13 and dual sits on a corner between four source texels, so it
// is the mean of that 2x2 box of S = B * P (B the 11-tap binomial C(10, k) / 1024 per axis, P the
// bright-passed source). Along one axis the box of corner i averages S(clamp(i)) and S(clamp(i+1)):
// where both lie inside the image that is [1, 1] / 2 * C(10, k) / 1024 = C(11, k) / 2048, a 12-tap
// binomial on P at i - 5 .. i + 6 (with P's clamp-to-edge reads); at an image edge the two
// are the same texel and the box is S there, the 11-tap binomial. So the box means are one
// separable pass per axis, without ever forming S. And only half the corners are read: output x
// sits on corner 2x (in source texels, the corner between 2x and 2x+1) and reads corners 2x + d,
// d in {-2, 0, 2} on both axes (cod13's outer grid, dual's centre) or d in {-1, 1} on both axes
// (the inner taps): a corner is read only where its two indices have the same parity, so the
// vertical pass computes only those.
//
// A workgroup of W x H invocations makes a tile of W x 2H outputs (two rows per invocation), which
// halves the apron re-read per output against a W x H tile. Shared memory holds one fp32 value per
// channel (no unused alpha) of the (2W + 14) x (4H + 14) window of P, then of the box means, and of
// the horizontal results: 44 KiB at 16 x 8. Reusing the window in place for the horizontal results
// too (25 KiB) needed them staged in registers across a barrier: 182 registers on the H100, two
// workgroups an SM (docs/PERF.md).
//
// The horizontal pass is register-blocked: an invocation sums a run of kRun consecutive corner
// columns of one window row from the kRun + 11 window values they share, read once (3 x 15 shared
// reads for 4 sums instead of 3 x 48). Consecutive invocations take consecutive window rows, and
// the window's row stride is odd, so the lanes of a read that share a run of columns hit distinct
// banks (only where a subgroup wraps to the next run can two meet).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1, DST_FORMAT) uniform writeonly image2D level0;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

#include "bloom.glsl"

const int kRadius = GLINT_BLOOM_SMOOTH_RADIUS;
const uint kTileW = gl_WorkGroupSize.x;  // outputs of a workgroup
const uint kTileH = 2u * gl_WorkGroupSize.y;
// Corners 2 * x0 - 2 .. 2 * (x0 + kTileW - 1) + 2 of the tile's taps, per axis.
const uint kCornersW = 2u * kTileW + 3u;
const uint kCornersH = 2u * kTileH + 3u;
// P at corner - 5 .. corner + 6 for each of them.
const uint kWindowW = kCornersW + 2u * uint(kRadius) + 1u;
const uint kWindowH = kCornersH + 2u * uint(kRadius) + 1u;
const uint kGroupSize = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
const uint kLoads = (kWindowW * kWindowH + kGroupSize - 1u) / kGroupSize;
// Row stride of the window in shared memory: odd, so that lanes reading one column of
// consecutive rows fall in distinct banks.
const uint kStride = kWindowW | 1u;
const uint kRowValues = kCornersW * kWindowH;  // horizontal pass results
// Step 2 in runs of kRun corner columns of one window row.
const uint kRun = 4u;
const uint kRunsPerRow = (kCornersW + kRun - 1u) / kRun;
const uint kRuns = kRunsPerRow * kWindowH;
// Corners with both indices of the same parity: rows of even index hold kTileW + 2 of them, odd
// rows kTileW + 1; enumerated as kCornersH rows of kTileW + 2 slots, the last slot of odd rows unused.
const uint kBoxSlots = kCornersH * (kTileW + 2u);
const uint kBoxesPerInvocation = (kBoxSlots + kGroupSize - 1u) / kGroupSize;

// Binomial weights: C(11, k) / 2048 (box of two neighbours of the 11-tap filter) and
// C(10, k) / 1024 (the 11-tap filter itself, at an edge), padded with a zero 12th tap. All are
// exact in fp32.
const float kInner[12] = float[](1.0 / 2048.0, 11.0 / 2048.0, 55.0 / 2048.0, 165.0 / 2048.0, 330.0 / 2048.0,
                                 462.0 / 2048.0, 462.0 / 2048.0, 330.0 / 2048.0, 165.0 / 2048.0, 55.0 / 2048.0,
                                 11.0 / 2048.0, 1.0 / 2048.0);
const float kEdge[12] = float[](1.0 / 1024.0, 10.0 / 1024.0, 45.0 / 1024.0, 120.0 / 1024.0, 210.0 / 1024.0,
                                252.0 / 1024.0, 210.0 / 1024.0, 120.0 / 1024.0, 45.0 / 1024.0, 10.0 / 1024.0,
                                1.0 / 1024.0, 0.0);

// The window of P (step 1, row stride kStride, plus the kRun entries the last run of the last row
// reads past its end and never uses), then the box means (step 3, stride kCornersW); the
// horizontal results (step 2, stride kCornersW).
shared float s_r[kStride * kWindowH + kRun];
shared float s_g[kStride * kWindowH + kRun];
shared float s_b[kStride * kWindowH + kRun];
shared float t_r[kRowValues];
shared float t_g[kRowValues];
shared float t_b[kRowValues];

vec3 shared_at(uint i) { return vec3(s_r[i], s_g[i], s_b[i]); }
void shared_put(uint i, vec3 v) {
  s_r[i] = v.r;
  s_g[i] = v.g;
  s_b[i] = v.b;
}
vec3 row_at(uint i) { return vec3(t_r[i], t_g[i], t_b[i]); }

// One axis of a corner's box: corner `i` (absolute, in source texels) of an axis of `n` texels.
// Its taps are window entries first + k, k = 0..11, with weights w[k]: the 12-tap binomial at
// i - 5 .. i + 6 inside, the 11-tap one around the clamped texel at an edge (i < 0 or i > n - 2,
// where clamp(i) == clamp(i + 1)). `first` is relative to the entry of corner i's own 12 taps.
int edge_shift(int i, int n) { return clamp(i, 0, n - 1) - i; }
bool at_edge(int i, int n) { return i < 0 || i > n - 2; }

#define BOX_MEAN(i) shared_at(i)
#include "bloom_boxes.glsl"

// Step 2 at one window row and corner column: the horizontal 12-tap sum, stored with row stride
// kCornersW; `x0` is the absolute corner of column 0, `w` the source width.
void put_row(uint row, uint col, vec3 v) {
  const uint q = row * kCornersW + col;
  t_r[q] = v.r;
  t_g[q] = v.g;
  t_b[q] = v.b;
}
vec3 row_value(uint row, uint col, int x0, int w) {
  int i = x0 + int(col);
  bool edge = at_edge(i, w);
  uint first = row * kStride + uint(int(col) + edge_shift(i, w));
  vec3 sum = vec3(0.0);
  [[unroll]] for (uint k = 0u; k < 12u; ++k) sum += (edge ? kEdge[k] : kInner[k]) * shared_at(first + k);
  return sum;
}

// Run q of step 2 (q < kRuns): corner columns kRun c .. kRun c + kRun - 1 of window row r, with
// r = q mod kWindowH (consecutive invocations, consecutive rows). Where none of the columns is at
// an image edge, the run's kRun + 11 window values are read once and each column sums its 12 with
// the interior weights; else each column takes row_value().
void row_run(uint q, int x0, int w) {
  const uint row = q % kWindowH, col0 = (q / kWindowH) * kRun;
  const int i0 = x0 + int(col0);
  if (!at_edge(i0, w) && !at_edge(i0 + int(kRun) - 1, w)) {
    const uint first = row * kStride + col0;
    vec3 v[kRun + 11u];
    [[unroll]] for (uint k = 0u; k < kRun + 11u; ++k) v[k] = shared_at(first + k);
    [[unroll]] for (uint r = 0u; r < kRun; ++r) {
      vec3 sum = vec3(0.0);
      [[unroll]] for (uint k = 0u; k < 12u; ++k) sum += kInner[k] * v[r + k];
      if (col0 + r < kCornersW) put_row(row, col0 + r, sum);
    }
  } else {
    for (uint r = 0u; r < kRun; ++r) {
      if (col0 + r < kCornersW) put_row(row, col0 + r, row_value(row, col0 + r, x0, w));
    }
  }
}

// Step 3's value n: the vertical 12-tap sum at one corner whose two indices have the same parity;
// `y0` is the absolute corner of row 0, `h` the source height.
vec3 box_value(uint n, int y0, int h) {
  uint q = min(gl_LocalInvocationIndex + n * kGroupSize, kBoxSlots - 1u);
  uint cy = q / (kTileW + 2u);
  uint cx = min(2u * (q % (kTileW + 2u)) + (cy & 1u), kCornersW - 1u);  // the unused slot repeats a corner
  int j = y0 + int(cy);
  bool edge = at_edge(j, h);
  uint first = uint(int(cy) + edge_shift(j, h)) * kCornersW + cx;
  vec3 sum = vec3(0.0);
  [[unroll]] for (uint k = 0u; k < 12u; ++k) sum += (edge ? kEdge[k] : kInner[k]) * row_at(first + k * kCornersW);
  return sum;
}
void put_box(uint n, vec3 v) {
  uint q = gl_LocalInvocationIndex + n * kGroupSize;
  if (q < kBoxSlots) {
    uint cy = q / (kTileW + 2u);
    uint cx = 2u * (q % (kTileW + 2u)) + (cy & 1u);
    if (cx < kCornersW) shared_put(cy * kCornersW + cx, v);
  }
}

void main() {
  ivec2 src_size = ivec2(p.src_width, p.src_height);
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  BloomSource bright = BloomSource(src_size, true, p.threshold, p.knee);
  // Scalar expressions of the workgroup size only (see bloom_up_tiled.glsl).
  ivec2 tile = ivec2(int(gl_WorkGroupID.x * kTileW), int(gl_WorkGroupID.y * kTileH));
  ivec2 corner0 = 2 * tile - 2;                 // absolute corner of corner entry (0, 0)
  ivec2 window0 = corner0 - kRadius;            // absolute texel of window entry (0, 0)

  // 1. P over the window, clamped to the image. On GPUs every fetch is issued before the first
  // store; CPU devices take a plain loop (bloom.glsl, PREFETCH), which they compile far faster.
  if (PREFETCH) {
    vec3 fetched[kLoads];
    [[unroll]] for (uint n = 0u; n < kLoads; ++n) {
      uint i = min(gl_LocalInvocationIndex + n * kGroupSize, kWindowW * kWindowH - 1u);
      fetched[n] = source_texel(scene, bright, window0 + ivec2(i % kWindowW, i / kWindowW));
    }
    [[unroll]] for (uint n = 0u; n < kLoads; ++n) {
      uint i = gl_LocalInvocationIndex + n * kGroupSize;
      if (i < kWindowW * kWindowH) shared_put((i / kWindowW) * kStride + i % kWindowW, fetched[n]);
    }
  } else {
    [[dont_unroll]] for (uint i = gl_LocalInvocationIndex; i < kWindowW * kWindowH; i += kGroupSize) {
      shared_put((i / kWindowW) * kStride + i % kWindowW,
                 source_texel(scene, bright, window0 + ivec2(i % kWindowW, i / kWindowW)));
    }
  }
  barrier();

  // 2. Horizontal: every window row at every corner column, stored with row stride kCornersW, in
  // runs of kRun columns (row_run()).
  [[dont_unroll]] for (uint q = gl_LocalInvocationIndex; q < kRuns; q += kGroupSize) row_run(q, corner0.x, src_size.x);
  barrier();

  // 3. Vertical, at the corners the taps read, stored at their place in the kCornersW x kCornersH
  // grid over the window (read no more).
  if (PREFETCH) {
    [[unroll]] for (uint n = 0u; n < kBoxesPerInvocation; ++n) put_box(n, box_value(n, corner0.y, src_size.y));
  } else {
    [[dont_unroll]] for (uint n = 0u; n < kBoxesPerInvocation; ++n) put_box(n, box_value(n, corner0.y, src_size.y));
  }
  barrier();

  // 4. Two outputs per invocation, rows ly and ly + H of the tile: output (x, y) sits on corner
  // (2 x, 2 y), entry (2 lx + 2, 2 ly + 2) of the grid.
  [[unroll]] for (uint half_ = 0u; half_ < 2u; ++half_) {
    uint ly = gl_LocalInvocationID.y + half_ * gl_WorkGroupSize.y;
    ivec2 xy = tile + ivec2(gl_LocalInvocationID.x, ly);
    if (any(greaterThanEqual(xy, dst_size))) continue;
    vec3 c = downsample_from_boxes(ivec2(2u * gl_LocalInvocationID.x + 2u, 2u * ly + 2u), kCornersW, true);
    imageStore(level0, xy, vec4(min(c, vec3(p.max_brightness)), 1.0));
  }
}
