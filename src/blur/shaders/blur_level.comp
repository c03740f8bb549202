#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Fused level blur B(src, wd, hd, sigma) of docs/BLUR.md (the per-level separable Gaussian,
// in one dispatch instead of two): the workgroup loads its tile plus an apron of RADIUS texels
// into shared memory once (downsampling the source as it loads), runs the horizontal pass in
// shared memory, then the vertical pass, and writes every output texel once.
//
// Both passes are register-blocked: an invocation convolves a run of RUN texels along the pass
// direction, reading RUN + 2 RADIUS shared values instead of RUN * (2 RADIUS + 1), which is what
// bounds the kernel on a GPU (shared-memory bandwidth). With HALF_SHARED the shared copies are
// packed fp16 (half the bytes); the arithmetic stays fp32. It is used only where the result is
// stored as fp16 anyway.
layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(constant_id = 2) const int ROWS = 1;         // output rows per invocation: tile = (WG.x, WG.y * ROWS)
layout(constant_id = 3) const int RADIUS = 4;       // taps 2 * RADIUS + 1 (0: downsample only)
layout(constant_id = 4) const int MODE = 0;         // source read: 0 same size, 1 exact 2:1 area,
                                                    // 2 any-ratio area (docs/BLUR.md)
layout(constant_id = 5) const bool HALF_SHARED = false;
// Issue every source fetch of the load step before the first shared store (GPUs: the latencies
// overlap), or load in a plain loop (CPU devices: invocations run in order as SIMD lanes, so there
// is no latency to hide, and unrolling LOADS calls of load_source() - up to 16 texel fetches each
// for MODE 2 - multiplies the code the device's JIT compiles, by minutes per variant on lavapipe).
// Both store the same values.
layout(constant_id = 6) const bool PREFETCH = true;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

const int TILE_W = int(gl_WorkGroupSize.x);
const int TILE_H = int(gl_WorkGroupSize.y) * ROWS;
const int LOAD_W = TILE_W + 2 * RADIUS;
const int LOAD_H = TILE_H + 2 * RADIUS;
const int GROUP_SIZE = int(gl_WorkGroupSize.x) * int(gl_WorkGroupSize.y);
const int LOADS = (LOAD_W * LOAD_H + GROUP_SIZE - 1) / GROUP_SIZE;  // source texels per invocation
// Loads issued together by the prefetching load step: all of them where a load is one fetch (MODE
// 0) or 4 (exact 2:1 area: 139 registers on the H100, but batches of two loads took the 3-level
// BlurPyramid from 124.8 to 144.5 us at 59 registers); one at a time where a load is up to 16
// (any-ratio area), which otherwise kept all their texels in registers (255 on the H100, for the
// binomial downsample this kernel once read in its load: 253 -> 223 us at 94 in a single frame).
const int BATCH = MODE <= 1 ? LOADS : 1;
const int BATCHES = (LOADS + BATCH - 1) / BATCH;
const int RUN = 4;                        // horizontal outputs per invocation (TILE_W is a multiple)
const int H_RUNS = TILE_W / RUN;
const int H_WINDOW = RUN + 2 * RADIUS;
const int V_WINDOW = ROWS + 2 * RADIUS;

// Row strides padded to 1 mod 16 elements: the horizontal pass's invocations of one subgroup read
// runs 4 elements apart in 4 rows (and write them), which with unpadded strides (42, 32) land on
// the same shared-memory banks; with a stride of 1 mod 16 the rows shift by one element and the
// accesses spread over all banks.
const int LOAD_S = LOAD_W + (17 - LOAD_W % 16) % 16;
const int ROW_S = TILE_W + (17 - TILE_W % 16) % 16;
// fp32 or packed fp16 storage, selected by HALF_SHARED (the unused array is sized 1).
const int SRC_F32 = HALF_SHARED ? 1 : LOAD_S * LOAD_H;
const int SRC_F16 = HALF_SHARED ? LOAD_S * LOAD_H : 1;
const int ROW_F32 = HALF_SHARED ? 1 : ROW_S * LOAD_H;
const int ROW_F16 = HALF_SHARED ? ROW_S * LOAD_H : 1;
shared vec4 s_src32[SRC_F32];
shared uvec2 s_src16[SRC_F16];
shared vec4 s_row32[ROW_F32];
shared uvec2 s_row16[ROW_F16];

uvec2 pack4(vec4 v) { return uvec2(packHalf2x16(v.xy), packHalf2x16(v.zw)); }
vec4 unpack4(uvec2 u) { return vec4(unpackHalf2x16(u.x), unpackHalf2x16(u.y)); }

void put_src(int i, vec4 v) {
  if (HALF_SHARED) s_src16[i] = pack4(v); else s_src32[i] = v;
}
vec4 get_src(int i) { return HALF_SHARED ? unpack4(s_src16[i]) : s_src32[i]; }
void put_row(int i, vec4 v) {
  if (HALF_SHARED) s_row16[i] = pack4(v); else s_row32[i] = v;
}
vec4 get_row(int i) { return HALF_SHARED ? unpack4(s_row16[i]) : s_row32[i]; }

vec4 load_source(ivec2 q) {
  if (MODE == 0) return src_texel(q);
  if (MODE == 1) {
    ivec2 s = 2 * q;
    return 0.25 * (src_texel(s) + src_texel(s + ivec2(1, 0)) + src_texel(s + ivec2(0, 1)) + src_texel(s + ivec2(1, 1)));
  }
  return area_sample(q);
}

void main() {
  ivec2 dst_size = ivec2(p.dst_width, p.dst_height);
  ivec2 tile = ivec2(gl_WorkGroupID.xy) * ivec2(TILE_W, TILE_H);
  int local = int(gl_LocalInvocationIndex);

  // 1. Load: destination-grid texels tile - RADIUS .. tile + TILE + RADIUS, clamped to the level.
  // Every fetch is issued before the first shared store, so their latencies overlap (H100,
  // 3840x2160: 9 taps 244 -> 178 us; the 3-level pyramid, which reads 4 texels per loaded one,
  // 147 us without this and 124 us with it).
  if (PREFETCH) {
    [[dont_unroll]] for (int b = 0; b < BATCHES; ++b) {
      vec4 fetched[BATCH];
      [[unroll]] for (int n = 0; n < BATCH; ++n) {
        int i = min(local + (b * BATCH + n) * GROUP_SIZE, LOAD_W * LOAD_H - 1);
        fetched[n] = load_source(clamp(tile - RADIUS + ivec2(i % LOAD_W, i / LOAD_W), ivec2(0), dst_size - 1));
      }
      [[unroll]] for (int n = 0; n < BATCH; ++n) {
        int i = local + (b * BATCH + n) * GROUP_SIZE;
        if (i < LOAD_W * LOAD_H) put_src((i / LOAD_W) * LOAD_S + i % LOAD_W, fetched[n]);
      }
    }
  } else {
    [[dont_unroll]] for (int i = local; i < LOAD_W * LOAD_H; i += GROUP_SIZE) {
      vec4 v = load_source(clamp(tile - RADIUS + ivec2(i % LOAD_W, i / LOAD_W), ivec2(0), dst_size - 1));
      put_src((i / LOAD_W) * LOAD_S + i % LOAD_W, v);
    }
  }
  barrier();

  // 2. Horizontal pass: every loaded row, the tile's columns, RUN outputs per invocation.
  for (int item = local; item < H_RUNS * LOAD_H; item += GROUP_SIZE) {
    int row = item / H_RUNS;
    int x0 = (item % H_RUNS) * RUN;
    vec4 window[H_WINDOW];
    [[unroll]] for (int k = 0; k < H_WINDOW; ++k) window[k] = get_src(row * LOAD_S + x0 + k);
    [[unroll]] for (int r = 0; r < RUN; ++r) {
      vec4 sum = p.weights[0] * window[r + RADIUS];
      [[unroll]] for (int t = 1; t <= RADIUS; ++t) sum += p.weights[t] * (window[r + RADIUS - t] + window[r + RADIUS + t]);
      put_row(row * ROW_S + x0 + r, sum);
    }
  }
  barrier();

  // 3. Vertical pass: ROWS outputs of one column per invocation, and the one write of each.
  int x = int(gl_LocalInvocationID.x);
  int y0 = int(gl_LocalInvocationID.y) * ROWS;
  vec4 window[V_WINDOW];
  [[unroll]] for (int k = 0; k < V_WINDOW; ++k) window[k] = get_row((y0 + k) * ROW_S + x);
  [[unroll]] for (int r = 0; r < ROWS; ++r) {
    ivec2 xy = tile + ivec2(x, y0 + r);
    vec4 sum = p.weights[0] * window[r + RADIUS];
    [[unroll]] for (int t = 1; t <= RADIUS; ++t) sum += p.weights[t] * (window[r + RADIUS - t] + window[r + RADIUS + t]);
    if (all(lessThan(xy, dst_size))) imageStore(dst, xy, sum);
  }
}
