#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// The pyramid method's binomial downsample D (docs/BLUR.md, "pyramid") on an exact 2:1 step of
// the padded chain: [1 3 3 1] / 8 along each axis, destination texel x reading source texels
// 2x - 1 .. 2x + 2 (relative to the chain's origins). Equal in exact arithmetic to the mean of the
// four bilinear reads at map(x) +- 0.375 r, whose fractions are 1/4 and 3/4 on this step.
// Those four reads fetch 16 texels per output, and neighbouring outputs share half of them on
// each axis: every source texel is fetched (and sanitized) four times. Here a workgroup loads its
// tile's source block once into shared memory, sums it along x into shared rows, then along y.
// The pyramid's levels are made by blur_down_stream.comp (the same sums in the same order, walking
// bands of rows without shared memory: faster on the H100 and on lavapipe, docs/BLUR.md); this
// tiled form runs where blur_steps::SeparableKernel::tiles is selected, for the tests and
// benchmarks that compare the two. H100, 3840x2160, whole blur (glint_bench medians, same machine):
// sigma 16 283 -> 271 us and sigma 64 321 -> 312 us against the 16-fetch form at the first level
// (with every fetch in flight, 128 registers), which the levels after it had also beaten (a single
// frame's stage times had shown the first level the other way round, 93 against 147 us: not what
// the whole blur does); the last level stored here before its blur, instead of downsampled in the
// level blur's load: sigma 8 299 -> 251 us, sigma 16 272 -> 251 us.
layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(constant_id = 2) const int ROWS = 1;  // output rows per invocation: tile = (WG.x, WG.y * ROWS)
// Every fetch of the load step issued before the first shared store (GPUs: their latencies
// overlap; one at a time, the sigma-16 blur took 311 us instead of 271 on the H100 at 3840x2160), or
// a plain loop (CPU devices, as blur_level.comp's PREFETCH).
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
const int IW = 2 * TW + 2;  // the tile's source block
const int IH = 2 * TH + 2;
const int LOADS = (IW * IH + GROUP_SIZE - 1) / GROUP_SIZE;  // source texels per invocation
shared vec4 s_src[IH * IW];  // the block, row-major (clamped and sanitized as src_texel() reads)
shared vec4 s_row[IH * TW];  // block row j summed along x for output column x, at j * TW + x

void main() {
  const ivec2 size = ivec2(p.dst_width, p.dst_height);
  const ivec2 tile = ivec2(gl_WorkGroupID.xy) * ivec2(TW, TH);
  const int lx = int(gl_LocalInvocationID.x), ly = int(gl_LocalInvocationID.y);
  // Source texel of tap 0 of the tile's first output: 2 x - 1 in the virtual (padded) grids.
  const ivec2 i0 = 2 * (tile + ivec2(p.dst_origin_x, p.dst_origin_y)) - 1 - ivec2(p.src_origin_x, p.src_origin_y);
  const int local = int(gl_LocalInvocationIndex);
  if (PREFETCH) {
    vec4 fetched[LOADS];
    [[unroll]] for (int n = 0; n < LOADS; ++n) {
      const int i = min(local + n * GROUP_SIZE, IW * IH - 1);
      fetched[n] = src_texel(i0 + ivec2(i % IW, i / IW));
    }
    [[unroll]] for (int n = 0; n < LOADS; ++n) {
      const int i = local + n * GROUP_SIZE;
      if (i < IW * IH) s_src[i] = fetched[n];
    }
  } else {
    [[dont_unroll]] for (int i = local; i < IW * IH; i += GROUP_SIZE) s_src[i] = src_texel(i0 + ivec2(i % IW, i / IW));
  }
  barrier();
  for (int j = ly; j < IH; j += int(gl_WorkGroupSize.y)) {
    const int b = j * IW + 2 * lx;
    s_row[j * TW + lx] = binomial4(s_src[b], s_src[b + 1], s_src[b + 2], s_src[b + 3]);
  }
  barrier();
  for (int r = 0; r < ROWS; ++r) {
    const int y = ly * ROWS + r;
    const int b = 2 * y * TW + lx;
    const vec4 v = binomial4(s_row[b], s_row[b + TW], s_row[b + 2 * TW], s_row[b + 3 * TW]);
    const ivec2 xy = tile + ivec2(lx, y);
    if (all(lessThan(xy, size))) imageStore(dst, xy, v);
  }
}
