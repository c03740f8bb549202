#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Fused level blur B(src, wd, hd, sigma) of docs/BLUR.md (seed 003's per-level separable Gaussian,
// in one dispatch instead of two): the workgroup loads its tile plus an apron of RADIUS texels
// into shared memory once (downsampling the source as it loads), runs the horizontal pass in
// shared memory, then the vertical pass, and writes every output texel once.
layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(constant_id = 2) const int ROWS = 1;    // output rows per invocation: tile = (WG.x, WG.y * ROWS)
layout(constant_id = 3) const int RADIUS = 4;  // taps 2 * RADIUS + 1 (0: downsample only)
layout(constant_id = 4) const int DOWN = 0;    // 0: area downsample, 1: binomial (docs/BLUR.md)

layout(binding = 0) uniform texture2D src;
layout(binding = 1, DST_FORMAT) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

const int TILE_W = int(gl_WorkGroupSize.x);
const int TILE_H = int(gl_WorkGroupSize.y) * ROWS;
const int LOAD_W = TILE_W + 2 * RADIUS;
const int LOAD_H = TILE_H + 2 * RADIUS;
const int GROUP_SIZE = int(gl_WorkGroupSize.x) * int(gl_WorkGroupSize.y);

shared vec4 s_src[LOAD_W * LOAD_H];  // area-downsampled source, tile + apron
shared vec4 s_row[TILE_W * LOAD_H];  // after the horizontal pass

void main() {
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  ivec2 tile = ivec2(gl_WorkGroupID.xy) * ivec2(TILE_W, TILE_H);
  int local = int(gl_LocalInvocationIndex);

  // 1. Load: destination-grid texels tile - RADIUS .. tile + TILE + RADIUS, clamped to the level.
  for (int i = local; i < LOAD_W * LOAD_H; i += GROUP_SIZE) {
    ivec2 q = tile - RADIUS + ivec2(i % LOAD_W, i / LOAD_W);
    q = clamp(q, ivec2(0), dst_size - 1);
    s_src[i] = DOWN == 1 ? binomial_sample(q) : area_sample(q);
  }
  barrier();

  // 2. Horizontal pass over every loaded row, for the tile's columns.
  for (int i = local; i < TILE_W * LOAD_H; i += GROUP_SIZE) {
    int row = i / TILE_W;
    int base = row * LOAD_W + (i % TILE_W) + RADIUS;
    vec4 sum = p.weights[0] * s_src[base];
    [[unroll]] for (int t = 1; t <= RADIUS; ++t) sum += p.weights[t] * (s_src[base - t] + s_src[base + t]);
    s_row[i] = sum;
  }
  barrier();

  // 3. Vertical pass and the one write of each output texel.
  int x = int(gl_LocalInvocationID.x);
  [[unroll]] for (int r = 0; r < ROWS; ++r) {
    int y = int(gl_LocalInvocationID.y) * ROWS + r;
    ivec2 xy = tile + ivec2(x, y);
    if (any(greaterThanEqual(xy, dst_size))) continue;
    int base = (y + RADIUS) * TILE_W + x;
    vec4 sum = p.weights[0] * s_row[base];
    [[unroll]] for (int t = 1; t <= RADIUS; ++t) sum += p.weights[t] * (s_row[base - t * TILE_W] + s_row[base + t * TILE_W]);
    imageStore(dst, xy, sum);
  }
}
