// The filter's upsample `Up` (docs/BLOOM.md) from a smaller image to a tile of a larger one,
// through shared memory. Each invocation computes a 2x2 block of outputs, so a workgroup of
// W x H invocations covers 2W x 2H texels: four independent fetches per invocation keep more
// memory requests in flight (the full-resolution composite is latency-bound otherwise), and the
// source window is shared by four times as many outputs.
// The workgroup loads the source window its tile reaches once; cod13 (3x3 tent of bilinear taps)
// and gauss9 (one bilinear tap) are separable, so a horizontal pass over the window rows and a
// vertical pass replace 36 (or 4) fetches per texel by about 10 shared reads; dual (not separable)
// reads its 8 bilinear taps from the window. Same arithmetic as the direct sum up to fp32 rounding.
// Bound: the tiled path runs when the source is at most half the destination on each axis
// (scale <= 0.5; true for every level, and for the composite unless a side of the input is 1)
// and radius <= 4, so the window spans at most (2W - 1) * 0.5 + 2 * 4 + 3 < W + 11 texels.
// Otherwise upsample_direct() reads the source through texelFetch.
// Requires bloom.glsl (FILTER) and image_io.glsl first.

const uint OUT_W = 2u * gl_WorkGroupSize.x;  // outputs per workgroup and axis
const uint OUT_H = 2u * gl_WorkGroupSize.y;
const uint WIN_W = gl_WorkGroupSize.x + 11u;
const uint WIN_H = gl_WorkGroupSize.y + 11u;
const uint UP_GROUP_SIZE = gl_WorkGroupSize.x * gl_WorkGroupSize.y;

shared vec4 s_src[WIN_W * WIN_H];
shared vec4 s_rows[OUT_W * WIN_H];

vec3 bilinear_window(vec2 q, ivec2 lo) {
  vec2 f = floor(q);
  vec2 w = q - f;
  uint i = uint(int(f.y) - lo.y) * WIN_W + uint(int(f.x) - lo.x);
  vec3 a = s_src[i].rgb, b = s_src[i + 1u].rgb, c = s_src[i + WIN_W].rgb, d = s_src[i + WIN_W + 1u].rgb;
  return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

// Separable taps: offsets radius * {-1, 0, 1} with weights {1, 2, 1} / 4 (cod13), or one tap at 0
// (gauss9), on each axis. (Functions rather than spec-constant arrays: lavapipe 22.3 crashes on
// a specialization-constant select of arrays.)
float tap_offset(int a) { return FILTER == GLINT_BLOOM_GAUSS9 ? 0.0 : float(a - 1); }
float tap_weight(int a) { return FILTER == GLINT_BLOOM_GAUSS9 ? 1.0 : (a == 1 ? 0.5 : 0.25); }
int tap_count() { return FILTER == GLINT_BLOOM_GAUSS9 ? 1 : 3; }

vec3 dual_up(vec2 c, float radius, ivec2 lo) {
  vec3 edges = bilinear_window(c + radius * vec2(-1, 0), lo) + bilinear_window(c + radius * vec2(1, 0), lo) +
               bilinear_window(c + radius * vec2(0, -1), lo) + bilinear_window(c + radius * vec2(0, 1), lo);
  vec3 diagonals = bilinear_window(c + radius * vec2(-0.5, -0.5), lo) +
                   bilinear_window(c + radius * vec2(0.5, -0.5), lo) +
                   bilinear_window(c + radius * vec2(-0.5, 0.5), lo) +
                   bilinear_window(c + radius * vec2(0.5, 0.5), lo);
  return (edges + 2.0 * diagonals) / 12.0;
}

// The direct form of Up at one texel, for sources larger than half the destination.
vec3 upsample_direct(texture2D small, ivec2 small_size, ivec2 xy, ivec2 dst_size, float radius) {
  vec2 c = map_position(xy, dst_size, small_size);
  if (FILTER == GLINT_BLOOM_GAUSS9) return bilinear(small, c, small_size);
  if (FILTER == GLINT_BLOOM_DUAL) {
    vec3 edges = bilinear(small, c + radius * vec2(-1, 0), small_size) + bilinear(small, c + radius * vec2(1, 0), small_size) +
                 bilinear(small, c + radius * vec2(0, -1), small_size) + bilinear(small, c + radius * vec2(0, 1), small_size);
    vec3 diagonals = bilinear(small, c + radius * vec2(-0.5, -0.5), small_size) +
                     bilinear(small, c + radius * vec2(0.5, -0.5), small_size) +
                     bilinear(small, c + radius * vec2(-0.5, 0.5), small_size) +
                     bilinear(small, c + radius * vec2(0.5, 0.5), small_size);
    return (edges + 2.0 * diagonals) / 12.0;
  }
  vec3 sum = vec3(0.0);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      sum += (tap_weight(i) * tap_weight(j)) * bilinear(small, c + radius * vec2(i - 1, j - 1), small_size);
  return sum;
}

// The first of the four outputs of this invocation; the others are +(1,0), +(0,1), +(1,1).
ivec2 block_origin() {
  // Vector expressions of gl_WorkGroupSize are avoided: spirv-opt's spec-constant folding (used by
  // the validation layer) miscompiles them. Scalar ones are fine.
  return ivec2(int(gl_WorkGroupID.x * OUT_W), int(gl_WorkGroupID.y * OUT_H)) + 2 * ivec2(gl_LocalInvocationID.xy);
}

// Up at the 2x2 block of block_origin(): result[dy * 2 + dx]. Every invocation of the workgroup
// must call this (it has barriers), inside the image or not.
void upsample_block(texture2D small, ivec2 small_size, ivec2 dst_size, float radius, out vec3 result[4]) {
  vec2 scale = vec2(small_size) / vec2(dst_size);
  ivec2 origin = block_origin();
  if (scale.x > 0.5 || scale.y > 0.5) {  // uniform: only when a side of the destination is 1
    for (int k = 0; k < 4; ++k) {
      result[k] = upsample_direct(small, small_size, min(origin + ivec2(k & 1, k >> 1), dst_size - 1), dst_size, radius);
    }
    return;
  }
  ivec2 first = ivec2(int(gl_WorkGroupID.x * OUT_W), int(gl_WorkGroupID.y * OUT_H));
  ivec2 last = min(ivec2(first.x + int(OUT_W) - 1, first.y + int(OUT_H) - 1), dst_size - 1);
  float reach = FILTER == GLINT_BLOOM_GAUSS9 ? 0.0 : radius;
  ivec2 lo = ivec2(floor((vec2(first) + 0.5) * scale - 0.5 - reach));
  ivec2 hi = ivec2(floor((vec2(last) + 0.5) * scale - 0.5 + reach)) + 1;
  ivec2 win = hi - lo + 1;
  for (uint i = gl_LocalInvocationIndex; i < uint(win.x * win.y); i += UP_GROUP_SIZE) {
    ivec2 t = ivec2(int(i) % win.x, int(i) / win.x);
    s_src[uint(t.y) * WIN_W + uint(t.x)] = fetch_clamped(small, lo + t, small_size);
  }
  barrier();
  if (FILTER == GLINT_BLOOM_DUAL) {
    for (int k = 0; k < 4; ++k) {
      ivec2 xy = min(origin + ivec2(k & 1, k >> 1), dst_size - 1);
      result[k] = dual_up(map_position(xy, dst_size, small_size), radius, lo);
    }
    return;
  }
  // Horizontal: for each output column of the tile and each window row.
  int taps = tap_count();
  for (uint i = gl_LocalInvocationIndex; i < OUT_W * uint(win.y); i += UP_GROUP_SIZE) {
    uint col = i % OUT_W;
    uint row = i / OUT_W;
    int x = min(first.x + int(col), dst_size.x - 1);
    float px = (float(x) + 0.5) * scale.x - 0.5;
    vec4 acc = vec4(0.0);
    for (int a = 0; a < taps; ++a) {
      float q = px + radius * tap_offset(a);
      float f = floor(q);
      uint k = row * WIN_W + uint(int(f) - lo.x);
      acc += tap_weight(a) * mix(s_src[k], s_src[k + 1u], q - f);
    }
    s_rows[row * OUT_W + col] = acc;
  }
  barrier();
  // Vertical, for this invocation's four texels.
  for (int k = 0; k < 4; ++k) {
    ivec2 xy = min(origin + ivec2(k & 1, k >> 1), dst_size - 1);
    uint col = uint(xy.x - first.x);
    float cy = (float(xy.y) + 0.5) * scale.y - 0.5;
    vec3 sum = vec3(0.0);
    for (int b = 0; b < taps; ++b) {
      float q = cy + radius * tap_offset(b);
      float f = floor(q);
      uint r = uint(int(f) - lo.y) * OUT_W + col;
      sum += tap_weight(b) * mix(s_rows[r].rgb, s_rows[r + OUT_W].rgb, q - f);
    }
    result[k] = sum;
  }
}
