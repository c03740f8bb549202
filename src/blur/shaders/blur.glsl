// Source access shared by the blur kernels (docs/BLUR.md): the sanitize rule for the caller's
// input and the exact area downsample. Requires `src` (texture2D) and the push block `p`
// (BlurPush) to be declared first.
#extension GL_EXT_samplerless_texture_functions : require

// NaN -> 0, then clamp to +-max_value (so +-Inf become finite): only for the caller's input.
vec4 sanitize(vec4 v) {
  if ((p.flags & GLINT_BLUR_FLAG_SANITIZE) == 0u) return v;
  v = mix(v, vec4(0.0), isnan(v));
  return clamp(v, vec4(-p.max_value), vec4(p.max_value));
}

vec4 src_texel(ivec2 ij) {
  return sanitize(texelFetch(src, clamp(ij, ivec2(0), ivec2(p.src_width, p.src_height) - 1), 0));
}

vec4 src_bilinear(vec2 q) {
  vec2 f = floor(q);
  vec2 w = q - f;
  ivec2 i0 = ivec2(f);
  vec4 a = src_texel(i0);
  vec4 b = src_texel(i0 + ivec2(1, 0));
  vec4 c = src_texel(i0 + ivec2(0, 1));
  vec4 d = src_texel(i0 + ivec2(1, 1));
  return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

// Area downsample A(src) at destination texel xy (docs/BLUR.md "Area downsample"); the identity
// along an axis whose sizes match. Integer arithmetic in units of 1/dst places the interval ends
// exactly: destination texel x covers [x*ws, (x+1)*ws) and source texel i covers [i*wd, (i+1)*wd).
vec4 area_sample(ivec2 xy) {
  ivec2 ws = ivec2(p.src_width, p.src_height);
  ivec2 wd = ivec2(p.dst_width, p.dst_height);
  if (ws == wd) return src_texel(xy);
  if (ws == 2 * wd) {  // exact 2:1: the mean of a 2x2 block
    ivec2 s = 2 * xy;
    return 0.25 * (src_texel(s) + src_texel(s + ivec2(1, 0)) + src_texel(s + ivec2(0, 1)) + src_texel(s + ivec2(1, 1)));
  }
  ivec2 lo = xy * ws;
  ivec2 hi = lo + ws;
  ivec2 i0 = lo / wd;
  ivec2 i1 = (hi - 1) / wd;
  // Overlaps are exact integers; each is divided by the footprint before it weighs a texel, so
  // no partial sum exceeds the largest texel (huge inputs stay finite: docs/BLUR.md "Sanitize").
  vec4 sum = vec4(0.0);
  for (int j = i0.y; j <= i1.y; ++j) {
    float wy = float(min(hi.y, (j + 1) * wd.y) - max(lo.y, j * wd.y)) / float(ws.y);
    vec4 row = vec4(0.0);
    for (int i = i0.x; i <= i1.x; ++i) {
      float wx = float(min(hi.x, (i + 1) * wd.x) - max(lo.x, i * wd.x)) / float(ws.x);
      row += wx * src_texel(ivec2(i, j));
    }
    sum += wy * row;
  }
  return sum;
}

// The source position of destination texel xy (map() of docs/BLUR.md "Notation" between the
// virtual images of a padded chain, docs/BLUR.md "Borders"), in the real source's texels: reads
// outside it clamp, which on the caller's input is the clamp-to-edge extension the padding stands for.
vec2 source_position(ivec2 xy) {
  vec2 ratio = vec2(p.ratio_x, p.ratio_y);
  return (vec2(xy + ivec2(p.dst_origin_x, p.dst_origin_y)) + 0.5) * ratio - 0.5 - vec2(p.src_origin_x, p.src_origin_y);
}

// The binomial downsample's [1 3 3 1] / 8 along one axis, of four consecutive texels (or of four
// rows' sums): every downsample kernel forms it here, so the tiled and streamed ones sum the same
// terms in the same order.
vec4 binomial4(vec4 a, vec4 b, vec4 c, vec4 d) {
  return (a + d) * 0.125 + (b + c) * 0.375;
}

// The B-spline upsample's two passes, shared by its tiled and streamed kernels: along x, the sum
// of the four texels weighed by w in one expression; along y, the four rows' sums weighed by w
// and added to zero one after the other.
vec4 bspline_row(vec4 w, vec4 t0, vec4 t1, vec4 t2, vec4 t3) {
  return w.x * t0 + w.y * t1 + w.z * t2 + w.w * t3;
}
vec4 bspline_column(vec4 w, vec4 r0, vec4 r1, vec4 r2, vec4 r3) {
  vec4 sum = vec4(0.0);
  sum += w.x * r0;
  sum += w.y * r1;
  sum += w.z * r2;
  sum += w.w * r3;
  return sum;
}

// Uniform cubic B-spline weights for the four texels around a position with fraction t.
vec4 bspline_weights(float t) {
  float s = 1.0 - t;
  return vec4(s * s * s, 3.0 * t * t * t - 6.0 * t * t + 4.0, -3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0,
              t * t * t) / 6.0;
}
