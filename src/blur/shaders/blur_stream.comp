#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
// Streamed level blur (docs/BLUR.md "Streamed separable"): the same sums as
// src/blur/shaders/blur_level.comp with MODE 0 (the source at the same size) or 1 (the exact 2:1
// mean of the source), walked differently. A workgroup owns a strip of STRIP_W columns and
// `band_rows` rows (push constant) and walks it down in steps of STEP rows:
//   - the source rows of the next AHEAD steps are fetched into registers (with AHEAD 2, two sets
//     used by turns) while a step computes, so the memory latency hides behind the work of those
//     steps instead of behind a barrier (the tiled kernel loads, waits, then computes);
//   - every source row is filtered along x once and kept in a ring of STEP + 2 RADIUS rows of
//     shared memory, which the vertical pass reads: the vertical apron of 2 RADIUS rows is
//     filtered once per band (RADIUS rows above, RADIUS below), not once per tile.
// The vertical pass lags the horizontal one by 2 RADIUS rows: at step k the horizontal pass
// filters rows band - RADIUS + k STEP + [0, STEP), and the vertical pass writes rows band -
// 2 RADIUS + k STEP + [0, STEP), whose taps are all in the ring by then.
//
// Both passes are register-blocked as in blur_level.comp: an invocation convolves a run of RUN
// outputs along the pass, reading RUN + 2 RADIUS shared values. The shared arrays skew each row's
// elements by one slot every 2^SKEW (e -> e + e / 2^SKEW), so that the RUN-strided runs of one
// subgroup's invocations land on distinct banks (8-byte fp16 elements: 16 a phase of 128 bytes;
// 16-byte fp32 elements: 8). Reads outside the image clamp to its edge, as every blur kernel's.
layout(local_size_x_id = 0, local_size_y_id = 1) in;  // (STRIP_W / RUN, STEP)
layout(constant_id = 2) const int RADIUS = 4;        // taps 2 * RADIUS + 1
layout(constant_id = 3) const bool HALF_SHARED = false;  // shared copies as packed fp16
layout(constant_id = 4) const int MODE = 0;   // source read: 0 same size, 1 exact 2:1 area (2x2 mean)
layout(constant_id = 5) const int AHEAD = 2;  // steps whose source rows are in flight (1 or 2)
// MODE 1: load each 2x2 box as two column means in the order of a copy (GPUs) instead of four
// fetches per invocation (CPU devices, where it measured slower: docs/BLUR.md).
layout(constant_id = 6) const bool SPLIT_MEAN = false;

layout(binding = 0) uniform texture2D src;
#include "dst_image.glsl"
DST_LAYOUT(1) uniform writeonly image2D dst;

#include "blur_params.h"
layout(push_constant) uniform Push { BlurPush p; };
#include "blur.glsl"

const int RUN = 4;  // outputs per invocation and pass
const int STRIP_W = int(gl_WorkGroupSize.x) * RUN;
const int STEP = int(gl_WorkGroupSize.y);  // a multiple of RUN
const int GROUP_SIZE = int(gl_WorkGroupSize.x) * int(gl_WorkGroupSize.y);
const int LOAD_W = STRIP_W + 2 * RADIUS;
// Loaded values per texel of a step's rows: with SPLIT_MEAN, MODE 1 loads the two columns of each
// 2x2 source box separately, each the mean of its two rows, so that consecutive invocations fetch
// consecutive source texels (the order of a copy) and the horizontal pass averages the two.
const int HALVES = MODE == 1 && SPLIT_MEAN ? 2 : 1;
const int LOAD_V = LOAD_W * HALVES;                               // loaded values of a row
const int LOADS = (LOAD_V * STEP + GROUP_SIZE - 1) / GROUP_SIZE;  // per invocation and step
const int RING = STEP + 2 * RADIUS;
const int WINDOW = RUN + 2 * RADIUS;
const int SKEW = HALF_SHARED ? 4 : 3;
int skew(int e) { return e + (e >> SKEW); }
const int LOAD_S = LOAD_V + ((LOAD_V - 1) >> SKEW);
const int ROW_S = STRIP_W + ((STRIP_W - 1) >> SKEW);
// fp32 or packed fp16 storage, selected by HALF_SHARED (the unused array is sized 1).
const int SRC_F32 = HALF_SHARED ? 1 : LOAD_S * STEP;
const int SRC_F16 = HALF_SHARED ? LOAD_S * STEP : 1;
const int RING_F32 = HALF_SHARED ? 1 : ROW_S * RING;
const int RING_F16 = HALF_SHARED ? ROW_S * RING : 1;
shared vec4 s_src32[SRC_F32];
shared uvec2 s_src16[SRC_F16];
shared vec4 s_ring32[RING_F32];
shared uvec2 s_ring16[RING_F16];

uvec2 pack4(vec4 v) { return uvec2(packHalf2x16(v.xy), packHalf2x16(v.zw)); }
vec4 unpack4(uvec2 u) { return vec4(unpackHalf2x16(u.x), unpackHalf2x16(u.y)); }

void put_src(int i, vec4 v) {
  if (HALF_SHARED) s_src16[i] = pack4(v); else s_src32[i] = v;
}
vec4 get_src(int i) { return HALF_SHARED ? unpack4(s_src16[i]) : s_src32[i]; }
void put_ring(int i, vec4 v) {
  if (HALF_SHARED) s_ring16[i] = pack4(v); else s_ring32[i] = v;
}
vec4 get_ring(int i) { return HALF_SHARED ? unpack4(s_ring16[i]) : s_ring32[i]; }

// Per-invocation constants of the walk, set once by main().
ivec2 size;
int x0, band, band_end, local_index, steps, ring_base, hx, hrow, vx, vrow;
bool column_in;

// Loaded value i of the STEP rows from image row `row0` (row i / LOAD_V; c = i % LOAD_V), clamped
// to the destination grid: MODE 0's value c is the source texel of destination texel
// q = (x0 - RADIUS + c, row), MODE 1's the mean of q's 2x2 source box; with SPLIT_MEAN each
// destination texel has two values: value c is column c & 1 of the 2x2 source box of
// q = (x0 - RADIUS + c / 2, row), averaged over its two rows, and the mean of q's two values is
// the box's mean (step_texel()). Means, not sums, so that a value
// never exceeds the largest texel (the fp16 shared copies hold the level's range; the scaling by
// 0.5 is exact).
vec4 load_value(int i, int row0) {
  const int c = i % LOAD_V, r = row0 + i / LOAD_V;
  if (HALVES == 1) {
    const ivec2 q = clamp(ivec2(x0 - RADIUS + c, r), ivec2(0), size - 1);
    if (MODE == 0) return src_texel(q);
    const ivec2 s = 2 * q;  // MODE 1 in four fetches
    return 0.25 * (src_texel(s) + src_texel(s + ivec2(1, 0)) + src_texel(s + ivec2(0, 1)) + src_texel(s + ivec2(1, 1)));
  }
  const ivec2 s = 2 * clamp(ivec2(x0 - RADIUS + c / 2, r), ivec2(0), size - 1) + ivec2(c & 1, 0);
  return 0.5 * (src_texel(s) + src_texel(s + ivec2(0, 1)));
}

// The loaded values of the STEP rows from image row `row0`, each invocation's LOADS of them.
void fetch(out vec4 fetched[LOADS], int row0) {
  [[unroll]] for (int n = 0; n < LOADS; ++n) fetched[n] = load_value(min(local_index + n * GROUP_SIZE, LOAD_V * STEP - 1), row0);
}

// The horizontal pass's texel e of row `row` of the step's source rows.
vec4 step_texel(int row, int e) {
  if (HALVES == 1) return get_src(row * LOAD_S + skew(e));
  return 0.5 * (get_src(row * LOAD_S + skew(2 * e)) + get_src(row * LOAD_S + skew(2 * e + 1)));
}

// Step k: store its fetched rows, fetch those of step k + 2 into the same registers, filter the
// rows along x into the ring, then write the step's outputs from the ring.
void walk_step(int k, inout vec4 fetched[LOADS]) {
  const int hy = band - RADIUS + k * STEP;  // first row filtered along x in this step
  [[unroll]] for (int n = 0; n < LOADS; ++n) {
    int i = local_index + n * GROUP_SIZE;
    if (i < LOAD_V * STEP) put_src((i / LOAD_V) * LOAD_S + skew(i % LOAD_V), fetched[n]);
  }
  barrier();  // also orders the previous step's vertical reads before this step's ring writes
  if (k + AHEAD < steps) fetch(fetched, hy + AHEAD * STEP);

  // Horizontal pass: RUN outputs of row hy + hrow into its ring slot.
  {
    vec4 window[WINDOW];
    [[unroll]] for (int t = 0; t < WINDOW; ++t) window[t] = step_texel(hrow, hx + t);
    const int slot = (hy + hrow + ring_base) % RING;
    [[unroll]] for (int r = 0; r < RUN; ++r) {
      vec4 sum = p.weights[0] * window[r + RADIUS];
      [[unroll]] for (int t = 1; t <= RADIUS; ++t) sum += p.weights[t] * (window[r + RADIUS - t] + window[r + RADIUS + t]);
      put_ring(slot * ROW_S + skew(hx + r), sum);
    }
  }
  barrier();

  // Vertical pass: RUN outputs of column vx, rows oy .. oy + RUN - 1, each written once.
  const int oy = hy - RADIUS + vrow;
  if (column_in && oy + RUN > band && oy < band_end) {
    vec4 window[WINDOW];
    int slot = (oy - RADIUS + ring_base) % RING;
    [[unroll]] for (int t = 0; t < WINDOW; ++t) {
      window[t] = get_ring(slot * ROW_S + skew(vx));
      slot = slot + 1 == RING ? 0 : slot + 1;
    }
    [[unroll]] for (int r = 0; r < RUN; ++r) {
      vec4 sum = p.weights[0] * window[r + RADIUS];
      [[unroll]] for (int t = 1; t <= RADIUS; ++t) sum += p.weights[t] * (window[r + RADIUS - t] + window[r + RADIUS + t]);
      const int y = oy + r;
      if (y >= band && y < band_end) imageStore(dst, ivec2(x0 + vx, y), sum);
    }
  }
}

void main() {
  size = ivec2(p.dst_width, p.dst_height);
  x0 = int(gl_WorkGroupID.x) * STRIP_W;
  band = int(gl_WorkGroupID.y) * p.band_rows;
  band_end = min(band + p.band_rows, size.y);
  local_index = int(gl_LocalInvocationIndex);
  // Steps until the vertical pass has written the band's last row (see the header).
  steps = (band_end - band + 2 * RADIUS + STEP - 1) / STEP;
  // Ring slot of image row y: rows band - 3 RADIUS and up are read, so y - band + 3 RADIUS >= 0.
  ring_base = 3 * RADIUS - band;
  hx = int(gl_LocalInvocationID.x) * RUN;  // horizontal run: columns hx .. hx + RUN - 1
  hrow = int(gl_LocalInvocationID.y);      // of the step's row hrow
  vx = local_index % STRIP_W;              // vertical run: column vx,
  vrow = (local_index / STRIP_W) * RUN;    // rows vrow .. vrow + RUN - 1 of the step's outputs
  column_in = x0 + vx < size.x;

  // One register set (AHEAD 1), or two used by turns: the rows of the next AHEAD steps are in
  // flight while a step computes.
  vec4 fetched_a[LOADS];
  fetch(fetched_a, band - RADIUS);
  if (AHEAD == 1) {
    for (int k = 0; k < steps; ++k) walk_step(k, fetched_a);
  } else {
    vec4 fetched_b[LOADS];
    if (steps > 1) fetch(fetched_b, band - RADIUS + STEP);
    for (int k = 0; k < steps; k += 2) {
      walk_step(k, fetched_a);
      if (k + 1 < steps) walk_step(k + 1, fetched_b);
    }
  }
}
