#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// The small levels in one dispatch of one workgroup (docs/BLOOM.md "Dispatches"). From level T,
// made (and for gauss9 blurred) by earlier dispatches: the downsamples to levels T+1 .. T+count
// with their gauss9 blurs, then the upsamples with accumulation back up, A(k) = level k +
// Up(A(k+1)), ending with A(T) written over level T. Levels T+1 .. T+count live in shared memory
// in fp32, a workgroup barrier between levels; each texel is gathered by one invocation, no
// atomics. Same filters, weights, maps and clamping as bloom_down, bloom_blur and bloom_up; only
// the fp16 (or fp32) stores of the levels in between are gone.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0) uniform texture2D top;                // level T, read by the first downsample
layout(binding = 1, DST_FORMAT) uniform image2D top_out;  // the same image: A(T) is written here

#include "bloom_params.h"
layout(push_constant) uniform Push { BloomTailPush p; };

#include "bloom.glsl"

// Shared floats, 3 per texel (RGB) of levels T+1 .. T+count and, for gauss9, of the blur's
// horizontal pass of level T+1: the host sizes it from maxComputeSharedMemorySize and only runs
// this kernel when the levels fit.
layout(constant_id = 4) const uint TAIL_FLOATS = 3u;
shared float s_lv[TAIL_FLOATS];

const uint GROUP_SIZE = gl_WorkGroupSize.x * gl_WorkGroupSize.y;

ivec2 tail_size(int i) { return ivec2(p.sizes[2 * i], p.sizes[2 * i + 1]); }

// Offset (in floats) of level T+i, i >= 1; i = count + 1 is the gauss9 scratch after the last level.
uint tail_base(int i) {
  uint o = 0u;
  for (int k = 1; k < i; ++k) o += 3u * uint(tail_size(k).x * tail_size(k).y);
  return o;
}

vec3 sh_texel(uint base, ivec2 size, ivec2 ij) {
  ij = clamp(ij, ivec2(0), size - 1);
  uint i = base + 3u * uint(ij.y * size.x + ij.x);
  return vec3(s_lv[i], s_lv[i + 1u], s_lv[i + 2u]);
}

void sh_store(uint base, ivec2 size, ivec2 ij, vec3 v) {
  uint i = base + 3u * uint(ij.y * size.x + ij.x);
  s_lv[i] = v.r;
  s_lv[i + 1u] = v.g;
  s_lv[i + 2u] = v.b;
}

vec3 sh_bilinear(uint base, ivec2 size, vec2 pos) {
  vec2 f = floor(pos);
  ivec2 i0 = ivec2(f);
  return bilinear_mix(sh_texel(base, size, i0), sh_texel(base, size, i0 + ivec2(1, 0)),
                      sh_texel(base, size, i0 + ivec2(0, 1)), sh_texel(base, size, i0 + ivec2(1, 1)), pos - f);
}

// One workgroup does all of this dispatch's work, so for cod13 the two filters are evaluated as
// weights per texel instead of as bilinear taps: the same linear combination of the same texels
// (up to fp32 rounding), with fewer reads (36 instead of 52 per downsample, 16 instead of 36 per
// upsample at radius <= 1).
//
// cod13's downsample without a Karis weight is 1/2 of the 3x3 grid at +-2 with weights
// (1, 2, 1) x (1, 2, 1) / 16 plus 1/2 of the 2x2 taps at +-1, each a bilinear tap at an integer
// offset from c, so the texels are floor(c) - 2 .. floor(c) + 3 on each axis. Per axis, with
// t = fract(c): the grid's weights `o` and the inner taps' weights `i` on those six texels.
void down_axis_weights(float c, out float o[6], out float i[6], out int first) {
  float f = floor(c);
  float t = c - f;
  first = int(f) - 2;
  o = float[6](0.25 * (1.0 - t), 0.25 * t, 0.5 * (1.0 - t), 0.5 * t, 0.25 * (1.0 - t), 0.25 * t);
  i = float[6](0.0, 0.5 * (1.0 - t), 0.5 * t, 0.5 * (1.0 - t), 0.5 * t, 0.0);
}

// cod13's tent upsample (taps at c - r, c, c + r, weights 1/4, 1/2, 1/4, each linear) on one axis:
// for r <= 1 every tap lies on the texels floor(c) - 1 .. floor(c) + 2; their weights.
vec4 tent_axis_weights(float c, float r, out int first) {
  first = int(floor(c)) - 1;
  vec4 w = vec4(0.0);
  for (int a = 0; a < 3; ++a) {
    float q = c + r * float(a - 1);
    float fq = floor(q);
    float t = q - fq;
    int k = int(fq) - first;  // 0, 1 or 2
    float tw = a == 1 ? 0.5 : 0.25;
    w += tw * ((1.0 - t) * vec4(equal(ivec4(0, 1, 2, 3), ivec4(k))) + t * vec4(equal(ivec4(0, 1, 2, 3), ivec4(k + 1))));
  }
  return w;
}

// The first downsample, from level T (a texture), for cod13 by the weights above.
vec3 top_down(ivec2 top_size, ivec2 xy, ivec2 dst_size) {
  if (FILTER != GLINT_BLOOM_COD13) return downsample(top, BloomSource(top_size, false, 0.0, 0.0), xy, dst_size, false);
  vec2 c = level_map(xy, dst_size, top_size);
  float ox[6], ix[6], oy[6], iy[6];
  int x0, y0;
  down_axis_weights(c.x, ox, ix, x0);
  down_axis_weights(c.y, oy, iy, y0);
  vec3 sum = vec3(0.0);
  for (int j = 0; j < 6; ++j) {
    vec3 outer = vec3(0.0), inner = vec3(0.0);
    for (int i = 0; i < 6; ++i) {
      vec3 v = texelFetch(top, clamp(ivec2(x0 + i, y0 + j), ivec2(0), top_size - 1), 0).rgb;
      outer += ox[i] * v;
      inner += ix[i] * v;
    }
    sum += oy[j] * outer + iy[j] * inner;
  }
  return 0.5 * sum;
}

// downsample() of bloom.glsl (no Karis weight: only the first downsample has one) on a level in
// shared memory: the same expressions on the same texels (cod13: by the weights above). Keep the
// two the same.
vec3 sh_down(uint base, ivec2 src_size, ivec2 xy, ivec2 dst_size) {
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  if (FILTER == GLINT_BLOOM_GAUSS9) {
    vec2 lo, hi;
    ivec2 i0, i1;
    area_footprint(xy, dst_size, src_size, lo, hi, i0, i1);
    for (int j = i0.y; j <= i1.y; ++j) {
      float wy = area_overlap(lo.y, hi.y, j);
      for (int i = i0.x; i <= i1.x; ++i) {
        add_box(sum, wsum, sh_texel(base, src_size, ivec2(i, j)), area_overlap(lo.x, hi.x, i) * wy, false);
      }
    }
    return sum / wsum;
  }
  vec2 c = level_map(xy, dst_size, src_size);
  if (FILTER == GLINT_BLOOM_COD13) {
    float ox[6], ix[6], oy[6], iy[6];
    int x0, y0;
    down_axis_weights(c.x, ox, ix, x0);
    down_axis_weights(c.y, oy, iy, y0);
    for (int j = 0; j < 6; ++j) {
      vec3 outer = vec3(0.0), inner = vec3(0.0);
      for (int i = 0; i < 6; ++i) {
        vec3 v = sh_texel(base, src_size, ivec2(x0 + i, y0 + j));
        outer += ox[i] * v;
        inner += ix[i] * v;
      }
      sum += oy[j] * outer + iy[j] * inner;
    }
    return 0.5 * sum;
  }
  if (FILTER == GLINT_BLOOM_DUAL) {
    add_box(sum, wsum, sh_bilinear(base, src_size, c), 0.5, false);
    add_box(sum, wsum, sh_bilinear(base, src_size, c + vec2(-1, -1)), 0.125, false);
    add_box(sum, wsum, sh_bilinear(base, src_size, c + vec2(1, -1)), 0.125, false);
    add_box(sum, wsum, sh_bilinear(base, src_size, c + vec2(-1, 1)), 0.125, false);
    add_box(sum, wsum, sh_bilinear(base, src_size, c + vec2(1, 1)), 0.125, false);
    return sum / wsum;
  }
  return vec3(0.0);  // not reached: the filters are cod13, dual and gauss9
}


// One direction of bloom_blur.comp's 9-tap Gaussian on a level in shared memory.
const float kWeights[5] = float[5](0.2270270270, 0.1945945946, 0.1216216216, 0.0540540541, 0.0162162162);

vec3 sh_linear_along(uint base, ivec2 size, ivec2 xy, float offset, bool vertical) {
  float q = float(vertical ? xy.y : xy.x) + offset;
  float f = floor(q);
  float w = q - f;
  ivec2 step_dir = vertical ? ivec2(0, 1) : ivec2(1, 0);
  ivec2 b = vertical ? ivec2(xy.x, int(f)) : ivec2(int(f), xy.y);
  return mix(sh_texel(base, size, b), sh_texel(base, size, b + step_dir), w);
}

vec3 sh_blur(uint base, ivec2 size, ivec2 xy, bool vertical) {
  vec3 sum = kWeights[0] * sh_texel(base, size, xy);
  for (int t = 1; t < 5; ++t) {
    float o = float(t) * p.radius;
    sum += kWeights[t] * (sh_linear_along(base, size, xy, o, vertical) + sh_linear_along(base, size, xy, -o, vertical));
  }
  return sum;
}

// Up (docs/BLOOM.md "Upsample and accumulate") from a level in shared memory to texel xy of a
// dst_size level: the 2-D sum of the definition (bloom_up_tiled.glsl evaluates the same sum in two
// separable passes).
float tap_w(int a) { return a == 1 ? 0.5 : 0.25; }

vec3 sh_up(uint base, ivec2 small_size, ivec2 xy, ivec2 dst_size) {
  vec2 c = level_map(xy, dst_size, small_size);
  float r = p.radius;
  if (FILTER == GLINT_BLOOM_GAUSS9) return sh_bilinear(base, small_size, c);
  if (FILTER == GLINT_BLOOM_DUAL) {
    vec3 edges = sh_bilinear(base, small_size, c + r * vec2(-1, 0)) + sh_bilinear(base, small_size, c + r * vec2(1, 0)) +
                 sh_bilinear(base, small_size, c + r * vec2(0, -1)) + sh_bilinear(base, small_size, c + r * vec2(0, 1));
    vec3 diagonals = sh_bilinear(base, small_size, c + r * vec2(-0.5, -0.5)) +
                     sh_bilinear(base, small_size, c + r * vec2(0.5, -0.5)) +
                     sh_bilinear(base, small_size, c + r * vec2(-0.5, 0.5)) +
                     sh_bilinear(base, small_size, c + r * vec2(0.5, 0.5));
    return (edges + 2.0 * diagonals) / 12.0;
  }
  vec3 sum = vec3(0.0);
  if (r <= 1.0) {
    int x0, y0;
    vec4 wx = tent_axis_weights(c.x, r, x0), wy = tent_axis_weights(c.y, r, y0);
    for (int j = 0; j < 4; ++j) {
      vec3 row = wx.x * sh_texel(base, small_size, ivec2(x0, y0 + j)) +
                 wx.y * sh_texel(base, small_size, ivec2(x0 + 1, y0 + j)) +
                 wx.z * sh_texel(base, small_size, ivec2(x0 + 2, y0 + j)) +
                 wx.w * sh_texel(base, small_size, ivec2(x0 + 3, y0 + j));
      sum += wy[j] * row;
    }
    return sum;
  }
  for (int b = 0; b < 3; ++b) {
    vec3 row = vec3(0.0);
    for (int a = 0; a < 3; ++a) row += tap_w(a) * sh_bilinear(base, small_size, c + r * vec2(a - 1, b - 1));
    sum += tap_w(b) * row;
  }
  return sum;
}

void main() {
  const int count = p.count;
  const ivec2 top_size = tail_size(0);
  const uint scratch = tail_base(count + 1);
  // Downsamples, largest level first. Loops over a level's texels are plain loops (their trip
  // counts are push constants): nothing is unrolled for CPU devices to compile.
  for (int k = 1; k <= count; ++k) {
    ivec2 size = tail_size(k);
    uint base = tail_base(k);
    uint texels = uint(size.x * size.y);
    if (k == 1) {
      for (uint i = gl_LocalInvocationIndex; i < texels; i += GROUP_SIZE) {
        ivec2 xy = ivec2(int(i) % size.x, int(i) / size.x);
        sh_store(base, size, xy, top_down(top_size, xy, size));
      }
    } else {
      ivec2 src_size = tail_size(k - 1);
      uint src_base = tail_base(k - 1);
      for (uint i = gl_LocalInvocationIndex; i < texels; i += GROUP_SIZE) {
        ivec2 xy = ivec2(int(i) % size.x, int(i) / size.x);
        sh_store(base, size, xy, sh_down(src_base, src_size, xy, size));
      }
    }
    barrier();
    if (FILTER == GLINT_BLOOM_GAUSS9) {
      // Horizontal into the scratch, vertical back into the level (bloom_blur.comp twice).
      for (uint i = gl_LocalInvocationIndex; i < texels; i += GROUP_SIZE) {
        ivec2 xy = ivec2(int(i) % size.x, int(i) / size.x);
        sh_store(scratch, size, xy, sh_blur(base, size, xy, false));
      }
      barrier();
      for (uint i = gl_LocalInvocationIndex; i < texels; i += GROUP_SIZE) {
        ivec2 xy = ivec2(int(i) % size.x, int(i) / size.x);
        sh_store(base, size, xy, sh_blur(scratch, size, xy, true));
      }
      barrier();
    }
  }
  // Upsamples with accumulation, smallest level first: each invocation reads and writes only its
  // own texels of level k and reads level k+1.
  for (int k = count - 1; k >= 1; --k) {
    ivec2 size = tail_size(k);
    uint base = tail_base(k);
    ivec2 small_size = tail_size(k + 1);
    uint small_base = tail_base(k + 1);
    for (uint i = gl_LocalInvocationIndex; i < uint(size.x * size.y); i += GROUP_SIZE) {
      ivec2 xy = ivec2(int(i) % size.x, int(i) / size.x);
      sh_store(base, size, xy, sh_texel(base, size, xy) + sh_up(small_base, small_size, xy, size));
    }
    barrier();
  }
  // A(T) = level T + Up(A(T+1)), in place in the image. Every read of level T through `top`
  // happened before the barriers above.
  ivec2 small_size = tail_size(1);
  for (uint i = gl_LocalInvocationIndex; i < uint(top_size.x * top_size.y); i += GROUP_SIZE) {
    ivec2 xy = ivec2(int(i) % top_size.x, int(i) / top_size.x);
    vec3 own = imageLoad(top_out, xy).rgb;
    imageStore(top_out, xy, vec4(own + sh_up(0u, small_size, xy, top_size), 1.0));
  }
}
