// Up (docs/BLOOM.md) at an exact 2:1 ratio for the separable filters (cod13's 3x3 tent of
// bilinear taps, gauss9's one bilinear tap), one 2x2 block of outputs at a time, summed without
// shared memory (bloom_composite_2x.comp, bloom_up_2x.comp); on GPUs the outputs then go through a
// shared tile to be stored in copy order (up_2x_exchange, below). Requires bloom.glsl first.
//
// At 2:1, output x = 2k + e (e = 0, 1) sits at position k + c_e of the smaller image, with
// c_0 = -0.25 and c_1 = +0.25 (map_position: (x + 0.5) / 2 - 0.5). A bilinear tap at position q
// gives texel o the weight t(q - o), t(u) = max(0, 1 - |u|), so along one axis Up gives texel
// k + o the weight
//   cod13:  w_e(o) = 1/4 t(c_e - r - o) + 1/2 t(c_e - o) + 1/4 t(c_e + r - o)
//   gauss9: w_e(o) = t(c_e - o)
// (r the radius), the same for every block. Every texel of nonzero weight lies at an offset
// -S .. S with S = floor(r + 1/4) + 1 (cod13; 1 for gauss9): at most 5, as r <= 4. A block reads
// the (2 S + 1)^2 texels around k (neighbouring blocks share them in the cache), sums each row
// with both x weights, then the rows with both y weights. These are the weights of
// bloom_up_tiled.glsl's two passes (which form them from floor and fraction per tap), so the sums
// agree up to fp32 rounding; texels past the edge are read clamped, as there. The radius is a
// per-frame value (BloomConfig::radius; no pipeline per radius), so S is computed here.

const int kUpMaxSpan = 5;  // S at the largest radius, 4
const int kUpMaxTaps = 2 * kUpMaxSpan + 1;

float up_tent(float u) { return max(0.0, 1.0 - abs(u)); }

// w_e(o) above for offset o and the output's position c relative to k.
float up_weight(float c, int o, float r) {
  const float d = c - float(o);
  if (FILTER == GLINT_BLOOM_GAUSS9) return up_tent(d);
  return 0.25 * up_tent(d - r) + 0.5 * up_tent(d) + 0.25 * up_tent(d + r);
}

// Up of `small` (of `small_size` texels) at the four outputs 2k + (ex, ey): a[ey * 2 + ex].
void up_2x_block(texture2D small, ivec2 small_size, ivec2 k, float r, out vec3 a[4]) {
  const int span = FILTER == GLINT_BLOOM_GAUSS9 ? 1 : min(kUpMaxSpan, int(floor(r + 0.25)) + 1);
  float w0[kUpMaxTaps], w1[kUpMaxTaps];  // x weights of offset i - kUpMaxSpan
  [[unroll]] for (int i = 0; i < kUpMaxTaps; ++i) {
    w0[i] = up_weight(-0.25, i - kUpMaxSpan, r);
    w1[i] = up_weight(0.25, i - kUpMaxSpan, r);
  }
  a[0] = vec3(0.0);
  a[1] = vec3(0.0);
  a[2] = vec3(0.0);
  a[3] = vec3(0.0);
  // One row of texels at offset oy: both x sums, added with both y weights. Offsets -S .. S of
  // columns at compile time for S = 1 and 2 (gauss9, cod13 at r < 1.75: the default r = 1), where
  // rows and columns unroll fully; larger S loops over the rows.
#define UP_2X_ROW(oy, S)                                                             \
  {                                                                                  \
    vec3 h0 = vec3(0.0), h1 = vec3(0.0);                                             \
    [[unroll]] for (int i = kUpMaxSpan - (S); i <= kUpMaxSpan + (S); ++i) {          \
      if (abs(i - kUpMaxSpan) > span) continue; /* uniform: a push-constant function */ \
      const vec3 t = fetch_clamped(small, k + ivec2(i - kUpMaxSpan, oy), small_size).rgb; \
      h0 += w0[i] * t;                                                               \
      h1 += w1[i] * t;                                                               \
    }                                                                                \
    const float v0 = up_weight(-0.25, oy, r), v1 = up_weight(0.25, oy, r);           \
    a[0] += v0 * h0;                                                                 \
    a[1] += v0 * h1;                                                                 \
    a[2] += v1 * h0;                                                                 \
    a[3] += v1 * h1;                                                                 \
  }
  if (span == 1) {
    [[unroll]] for (int oy = -1; oy <= 1; ++oy) UP_2X_ROW(oy, 1)
  } else if (span == 2) {
    [[unroll]] for (int oy = -2; oy <= 2; ++oy) UP_2X_ROW(oy, 2)
  } else {
    for (int oy = -span; oy <= span; ++oy) UP_2X_ROW(oy, kUpMaxSpan)
  }
#undef UP_2X_ROW
}

// Where an invocation's four outputs go. COPY_ORDER (specialization constant 4, set by the host
// on GPUs): the workgroup's blocks form one tile of 2W x 2H outputs (W x H the workgroup size) in
// shared memory; each invocation computes the four outputs of its block (up_2x_block), and after
// up_2x_exchange takes the four outputs at (x + W i, y + H j) of the tile, i, j = 0, 1, so that
// consecutive invocations read and store consecutive texels of a row, in the order of a copy,
// where a block's own outputs lie 2 texels apart. On the H100 the 2x2-block stores alone took
// 25 us at 1920x1080 against 14.7 us for a whole copy (docs/PERF.md). CPU devices (lavapipe)
// store their own block's outputs: there the exchange's barrier cost more than the order gained
// (the composite step 39 -> 49 to 57 ms at 1920x1080).
layout(constant_id = 4) const bool COPY_ORDER = true;
const uint kUpTileW = 2u * gl_WorkGroupSize.x;
shared vec3 s_up_tile[kUpTileW * 2u * gl_WorkGroupSize.y];

// Output j (0..3) of the invocation whose block is k, in store order: its position in the image
// and where its value will be in `a` after up_2x_exchange (tile_index).
ivec2 up_2x_out(uint j, ivec2 k, out uint tile_index) {
  if (!COPY_ORDER) {
    tile_index = j;
    return 2 * k + ivec2(j & 1u, j >> 1u);
  }
  const uvec2 o = gl_LocalInvocationID.xy + uvec2((j & 1u) * gl_WorkGroupSize.x, (j >> 1u) * gl_WorkGroupSize.y);
  tile_index = o.y * kUpTileW + o.x;
  return ivec2(2u * gl_WorkGroupID.xy * gl_WorkGroupSize.xy + o);
}

// The block's outputs a[0..3] (as up_2x_block wrote them) become the outputs of up_2x_out's order:
// through the shared tile under COPY_ORDER (every invocation of the workgroup calls it), unchanged
// otherwise.
void up_2x_exchange(inout vec3 a[4], uint tile_index[4]) {
  if (!COPY_ORDER) return;  // uniform: a specialization constant
  const uvec2 o = 2u * gl_LocalInvocationID.xy;
  s_up_tile[o.y * kUpTileW + o.x] = a[0];
  s_up_tile[o.y * kUpTileW + o.x + 1u] = a[1];
  s_up_tile[(o.y + 1u) * kUpTileW + o.x] = a[2];
  s_up_tile[(o.y + 1u) * kUpTileW + o.x + 1u] = a[3];
  barrier();
  [[unroll]] for (uint j = 0u; j < 4u; ++j) a[j] = s_up_tile[tile_index[j]];
}
