// The filter's upsample `Up` (docs/BLOOM.md) from a smaller image to a workgroup's tile of a larger
// one, through shared memory. The workgroup loads the source window its tile reaches once; cod13
// (3x3 tent of bilinear taps) and gauss9 (one bilinear tap) are separable, so a horizontal pass
// over the window rows and a vertical pass replace 36 (or 4) fetches per texel by about 10 shared
// reads; dual (not separable) reads its 8 bilinear taps from the window. Same arithmetic as the
// direct sum up to fp32 rounding.
// Bound: the source is at most as large as the destination (scale <= 1) and radius <= 4, so the
// window spans at most (W - 1) + 2 * 4 + 3 = W + 10 texels per side.
// Requires bloom.glsl (FILTER) and image_io.glsl first.

const uint WIN_W = gl_WorkGroupSize.x + 10u;
const uint WIN_H = gl_WorkGroupSize.y + 10u;
const uint UP_GROUP_SIZE = gl_WorkGroupSize.x * gl_WorkGroupSize.y;

// A kernel that also uses the two arrays for other things before the upsample
// (bloom_composite_up.comp) defines larger sizes first.
#ifndef UP_SRC_SIZE
#define UP_SRC_SIZE (WIN_W * WIN_H)
#endif
#ifndef UP_ROWS_SIZE
#define UP_ROWS_SIZE (gl_WorkGroupSize.x * WIN_H)
#endif
shared vec4 s_src[UP_SRC_SIZE];
shared vec4 s_rows[UP_ROWS_SIZE];

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

// Up from the window s_src (texels lo .. lo + win - 1 of the smaller image, clamped, as
// upsample_tiled() loads them) to the invocation's texel. Every invocation must call this (it has
// barriers, the first of which publishes s_src).
vec3 upsample_window(ivec2 small_size, ivec2 dst_size, float radius, ivec2 lo, ivec2 win) {
  vec2 scale = vec2(small_size) / vec2(dst_size);
  ivec2 first = ivec2(gl_GlobalInvocationID.xy - gl_LocalInvocationID.xy);
  barrier();
  ivec2 xy = min(ivec2(gl_GlobalInvocationID.xy), dst_size - 1);  // outside: any valid texel
  vec2 c = level_map(xy, dst_size, small_size);
  if (FILTER == GLINT_BLOOM_DUAL) {
    vec3 edges = bilinear_window(c + radius * vec2(-1, 0), lo) + bilinear_window(c + radius * vec2(1, 0), lo) +
                 bilinear_window(c + radius * vec2(0, -1), lo) + bilinear_window(c + radius * vec2(0, 1), lo);
    vec3 diagonals = bilinear_window(c + radius * vec2(-0.5, -0.5), lo) +
                     bilinear_window(c + radius * vec2(0.5, -0.5), lo) +
                     bilinear_window(c + radius * vec2(-0.5, 0.5), lo) +
                     bilinear_window(c + radius * vec2(0.5, 0.5), lo);
    return (edges + 2.0 * diagonals) / 12.0;
  }
  int taps = FILTER == GLINT_BLOOM_GAUSS9 ? 1 : 3;
  // Horizontal: for each column of the tile and each window row.
  for (uint i = gl_LocalInvocationIndex; i < gl_WorkGroupSize.x * uint(win.y); i += UP_GROUP_SIZE) {
    uint col = i % gl_WorkGroupSize.x;
    uint row = i / gl_WorkGroupSize.x;
    int x = min(first.x + int(col), dst_size.x - 1);
    float px = (float(x) + 0.5) * scale.x - 0.5;
    vec4 acc = vec4(0.0);
    for (int a = 0; a < taps; ++a) {
      float q = px + radius * tap_offset(a);
      float f = floor(q);
      uint k = row * WIN_W + uint(int(f) - lo.x);
      acc += tap_weight(a) * mix(s_src[k], s_src[k + 1u], q - f);
    }
    s_rows[row * gl_WorkGroupSize.x + col] = acc;
  }
  barrier();
  // Vertical, for this invocation's texel.
  vec3 sum = vec3(0.0);
  for (int b = 0; b < taps; ++b) {
    float q = c.y + radius * tap_offset(b);
    float f = floor(q);
    uint k = uint(int(f) - lo.y) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    sum += tap_weight(b) * mix(s_rows[k].rgb, s_rows[k + gl_WorkGroupSize.x].rgb, q - f);
  }
  return sum;
}

// The window of the smaller image that the workgroup's tile reaches: texels lo .. lo + win - 1
// (before clamping to the image).
void up_window(ivec2 small_size, ivec2 dst_size, float radius, out ivec2 lo, out ivec2 win) {
  // Vector expressions of gl_WorkGroupSize are avoided: spirv-opt's spec-constant folding (used by
  // the validation layer) miscompiles them. Runtime ids give the same values.
  ivec2 first = ivec2(gl_GlobalInvocationID.xy - gl_LocalInvocationID.xy);
  ivec2 last = min(ivec2(first.x + int(gl_WorkGroupSize.x) - 1, first.y + int(gl_WorkGroupSize.y) - 1), dst_size - 1);
  float reach = FILTER == GLINT_BLOOM_GAUSS9 ? 0.0 : radius;
  lo = ivec2(floor(level_map(first, dst_size, small_size) - reach));
  ivec2 hi = ivec2(floor(level_map(last, dst_size, small_size) + reach)) + 1;
  win = hi - lo + 1;
}

// Every invocation of the workgroup must call this (it has barriers).
vec3 upsample_tiled(texture2D small, ivec2 small_size, ivec2 dst_size, float radius) {
  ivec2 lo, win;
  up_window(small_size, dst_size, radius, lo, win);
  for (uint i = gl_LocalInvocationIndex; i < uint(win.x * win.y); i += UP_GROUP_SIZE) {
    ivec2 t = ivec2(int(i) % win.x, int(i) / win.x);
    s_src[uint(t.y) * WIN_W + uint(t.x)] = fetch_clamped(small, lo + t, small_size);
  }
  return upsample_window(small_size, dst_size, radius, lo, win);
}
