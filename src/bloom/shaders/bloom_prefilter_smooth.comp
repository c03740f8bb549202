#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Bright-pass, binomial prefilter and Karis-guarded first downsample, for
// firefly_guard = karis_smooth (docs/BLOOM.md "Karis guard"): full-resolution scene -> level 0.
//
// Why a prefilter: a Karis weight 1 / (1 + luma) computed on raw 2x2 boxes compresses every box a
// bright point touches to about one unit, so the result counts the boxes, and that count changes
// as the point moves by a fraction of a pixel (docs/STABILITY.md: 44 to 94 % energy flicker).
// Weighing boxes of a source smoothed by an 11-tap binomial (sigma 1.58 px) first makes the boxes
// a point touches change smoothly with its position.
//
// A workgroup computes the bright-passed source over its window plus the prefilter's apron into
// shared memory, filters it horizontally then vertically there, and every invocation then
// downsamples that filtered window with bloom.glsl's taps and weights (downsample_from_window).
// Any ratio the mip chain makes (2:1, or up to 3:1 at odd sizes) fits the window (see kWindowW).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D scene;
layout(binding = 1, DST_FORMAT) uniform writeonly image2D level0;

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomPush p; };

// Window of the prefiltered source P a workgroup reads: with n outputs of a workgroup inside the
// level and r = src/dst <= 2 + 1/dst, their taps span under 2n + 5 texels; one more for rounding.
const uint kWindowW = 2u * gl_WorkGroupSize.x + 6u;
const uint kWindowH = 2u * gl_WorkGroupSize.y + 6u;
const int kRadius = GLINT_BLOOM_SMOOTH_RADIUS;
const uint kRawW = kWindowW + 2u * uint(kRadius);
const uint kRawH = kWindowH + 2u * uint(kRadius);
const uint kGroupSize = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
const uint kLoadsPerInvocation = (kRawW * kRawH + kGroupSize - 1u) / kGroupSize;
const float kBinomial[11] = float[](1.0 / 1024.0, 10.0 / 1024.0, 45.0 / 1024.0, 120.0 / 1024.0,
                                    210.0 / 1024.0, 252.0 / 1024.0, 210.0 / 1024.0, 120.0 / 1024.0,
                                    45.0 / 1024.0, 10.0 / 1024.0, 1.0 / 1024.0);

shared vec4 s_window[kRawW * kRawH];  // bright-passed source; then P, with row stride kWindowW
shared vec4 s_rows[kRawH * kWindowW];  // horizontal pass

#include "bloom.glsl"

// Texel ij of the prefiltered source P (clamped to the image of src_size texels) from the window
// whose entry (0, 0) is texel `window`.
vec3 window_source(ivec2 ij, ivec2 src_size, ivec2 window) {
  ij = clamp(ij, ivec2(0), src_size - 1);
  ivec2 k = clamp(ij - window, ivec2(0), ivec2(kWindowW, kWindowH) - 1);
  return s_window[uint(k.y) * kWindowW + uint(k.x)].rgb;
}

vec3 window_bilinear(vec2 pos, ivec2 src_size, ivec2 window) {
  vec2 f = floor(pos);
  ivec2 i0 = ivec2(f);
  return bilinear_mix(window_source(i0, src_size, window), window_source(i0 + ivec2(1, 0), src_size, window),
                      window_source(i0 + ivec2(0, 1), src_size, window),
                      window_source(i0 + ivec2(1, 1), src_size, window), pos - f);
}

// bloom.glsl's downsample() with the Karis guard, expression for expression, on P read from the
// window: any ratio.
vec3 downsample_from_window(ivec2 xy, ivec2 dst_size, ivec2 src_size, ivec2 window) {
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  if (FILTER == GLINT_BLOOM_GAUSS9) {
    vec2 lo, hi;
    ivec2 i0, i1;
    area_footprint(xy, dst_size, src_size, lo, hi, i0, i1);
    for (int j = i0.y; j <= i1.y; ++j) {
      float wy = area_overlap(lo.y, hi.y, j);
      for (int i = i0.x; i <= i1.x; ++i) {
        add_box(sum, wsum, window_source(ivec2(i, j), src_size, window), area_overlap(lo.x, hi.x, i) * wy, true);
      }
    }
    return sum / wsum;
  }
  vec2 c = level_map(xy, dst_size, src_size);
  if (FILTER == GLINT_BLOOM_DUAL) {
    add_box(sum, wsum, window_bilinear(c, src_size, window), 0.5, true);
    add_box(sum, wsum, window_bilinear(c + vec2(-1, -1), src_size, window), 0.125, true);
    add_box(sum, wsum, window_bilinear(c + vec2(1, -1), src_size, window), 0.125, true);
    add_box(sum, wsum, window_bilinear(c + vec2(-1, 1), src_size, window), 0.125, true);
    add_box(sum, wsum, window_bilinear(c + vec2(1, 1), src_size, window), 0.125, true);
    return sum / wsum;
  }
  vec3 g[9];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) g[j * 3 + i] = window_bilinear(c + vec2(2 * i - 2, 2 * j - 2), src_size, window);
  vec3 inner = (window_bilinear(c + vec2(-1, -1), src_size, window) + window_bilinear(c + vec2(1, -1), src_size, window) +
                window_bilinear(c + vec2(-1, 1), src_size, window) + window_bilinear(c + vec2(1, 1), src_size, window)) *
               0.25;
  add_box(sum, wsum, inner, 0.5, true);
  add_box(sum, wsum, (g[0] + g[1] + g[3] + g[4]) * 0.25, 0.125, true);
  add_box(sum, wsum, (g[1] + g[2] + g[4] + g[5]) * 0.25, 0.125, true);
  add_box(sum, wsum, (g[3] + g[4] + g[6] + g[7]) * 0.25, 0.125, true);
  add_box(sum, wsum, (g[4] + g[5] + g[7] + g[8]) * 0.25, 0.125, true);
  return sum / wsum;
}

// The exact 2:1 case (both sides even, the common one), as src/bloom/shaders/bloom_down_tiled.glsl
// does it: every bilinear tap of cod13 and dual sits on a corner of four texels, so it is the mean
// of that 2x2 box; the box means at every corner of the window are formed once, into s_rows (free
// after the vertical pass), and each invocation reads its 13 (cod13) or 5 (dual) boxes
// (bloom_boxes.glsl, shared with the tiled downsample), instead of 13 bilinear taps with their
// index arithmetic. Texels outside the image read their clamped
// neighbour, as downsample_from_window() does. The window starts at 2 * group origin - 2, as the tiled one.
const uint kBoxW = 2u * gl_WorkGroupSize.x + 3u;
const uint kBoxH = 2u * gl_WorkGroupSize.y + 3u;

#define BOX_MEAN(i) s_rows[i].rgb
#include "bloom_boxes.glsl"

// Window entry (i, j), clamped to the image as texels.
vec3 window_texel(int i, int j, ivec2 src_size, ivec2 window) {
  ivec2 t = clamp(window + ivec2(i, j), ivec2(0), src_size - 1) - window;
  return s_window[uint(t.y) * kWindowW + uint(t.x)].rgb;
}

// Every invocation of the workgroup must call this (it has a barrier).
vec3 downsample_2to1_from_window(ivec2 src_size, ivec2 window) {
  for (uint i = gl_LocalInvocationIndex; i < kBoxW * kBoxH; i += kGroupSize) {
    int x = int(i % kBoxW), y = int(i / kBoxW);
    s_rows[i] = vec4(0.25 * (window_texel(x, y, src_size, window) + window_texel(x + 1, y, src_size, window) +
                             window_texel(x, y + 1, src_size, window) + window_texel(x + 1, y + 1, src_size, window)),
                     0.0);
  }
  barrier();
  ivec2 c = ivec2(gl_LocalInvocationID.xy) * 2 + 2;  // output (x, y) sits on window corner 2x + 2
  if (FILTER == GLINT_BLOOM_GAUSS9) {
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) add_box(sum, wsum, window_texel(c.x + i, c.y + j, src_size, window), 0.25, true);
    return sum / wsum;
  }
  return downsample_from_boxes(c, kBoxW, true);
}


void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  BloomSource bright = BloomSource(ivec2(p.src_width, p.src_height), true, p.threshold, p.knee);
  ivec2 src_size = bright.size;
  ivec2 group_origin = ivec2(gl_GlobalInvocationID.xy - gl_LocalInvocationID.xy);
  ivec2 window = ivec2(floor(level_map(group_origin, dst_size, src_size))) - 2;  // P's entry (0, 0)
  ivec2 raw_origin = window - kRadius;

  // Every fetch is issued before the first shared store, so their latencies overlap.
  if (PREFETCH) {  // (bloom.glsl)
    vec3 fetched[kLoadsPerInvocation];
    [[unroll]] for (uint n = 0u; n < kLoadsPerInvocation; ++n) {
      uint i = min(gl_LocalInvocationIndex + n * kGroupSize, kRawW * kRawH - 1u);
      fetched[n] = source_texel(scene, bright, raw_origin + ivec2(i % kRawW, i / kRawW));
    }
    [[unroll]] for (uint n = 0u; n < kLoadsPerInvocation; ++n) {
      uint i = gl_LocalInvocationIndex + n * kGroupSize;
      if (i < kRawW * kRawH) s_window[i] = vec4(fetched[n], 0.0);
    }
  } else {
    [[dont_unroll]] for (uint i = gl_LocalInvocationIndex; i < kRawW * kRawH; i += kGroupSize) {
      s_window[i] = vec4(source_texel(scene, bright, raw_origin + ivec2(i % kRawW, i / kRawW)), 0.0);
    }
  }
  barrier();
  // P(t) = sum_m C(10, m) / 1024 * B(clamp(t + m - 5)) per axis. Entries of texels outside the
  // image are computed too but never read (window_source clamps its indices). Each invocation
  // computes two neighbours per step, reading 12 shared values for 2 outputs instead of 22
  // (shared-memory reads bound this kernel on a GPU). kWindowW and kWindowH are even.
  for (uint i = gl_LocalInvocationIndex; i < kRawH * (kWindowW / 2u); i += kGroupSize) {
    uint row = i / (kWindowW / 2u), col = 2u * (i % (kWindowW / 2u));
    vec4 a = vec4(0.0), b = vec4(0.0);
    vec4 prev = s_window[row * kRawW + col];
    [[unroll]] for (int m = 0; m <= 2 * kRadius; ++m) {
      vec4 next = s_window[row * kRawW + col + uint(m) + 1u];
      a += kBinomial[m] * prev;
      b += kBinomial[m] * next;
      prev = next;
    }
    s_rows[row * kWindowW + col] = a;
    s_rows[row * kWindowW + col + 1u] = b;
  }
  barrier();
  for (uint i = gl_LocalInvocationIndex; i < (kWindowH / 2u) * kWindowW; i += kGroupSize) {
    uint row = 2u * (i / kWindowW), col = i % kWindowW;
    vec4 a = vec4(0.0), b = vec4(0.0);
    vec4 prev = s_rows[row * kWindowW + col];
    [[unroll]] for (int m = 0; m <= 2 * kRadius; ++m) {
      vec4 next = s_rows[(row + uint(m) + 1u) * kWindowW + col];
      a += kBinomial[m] * prev;
      b += kBinomial[m] * next;
      prev = next;
    }
    s_window[row * kWindowW + col] = a;
    s_window[(row + 1u) * kWindowW + col] = b;
  }
  barrier();

  vec3 c;
  if (src_size == 2 * dst_size) {
    c = downsample_2to1_from_window(src_size, window);  // uniform branch; has a barrier
  } else {
    if (any(greaterThanEqual(xy, dst_size))) return;
    c = downsample_from_window(xy, dst_size, src_size, window);
  }
  if (any(greaterThanEqual(xy, dst_size))) return;
  imageStore(level0, xy, vec4(min(c, vec3(p.max_brightness)), 1.0));
}
