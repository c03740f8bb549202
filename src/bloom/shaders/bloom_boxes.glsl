// The cod13 and dual downsample of one output texel from box means at the corners of a
// workgroup's source window (docs/BLOOM.md "Downsample"): at an exact 2:1 reduction every bilinear
// tap sits on a corner shared by four source texels, so it is the mean of that 2x2 box. `c` is the
// output's corner in the window; boxes are read at c + (dx, dy) with row stride `box_w`.
// Shared by the tiled first downsample (bloom_down_tiled.glsl) and the karis_smooth one
// (bloom_prefilter_smooth.comp), which differ only in what the boxes average.
// Requires bloom.glsl (add_box, FILTER) and, before the include, `#define BOX_MEAN(i)` giving the
// box mean (vec3) at flat index i. gauss9 reads texels, not boxes: its callers handle it.

vec3 downsample_from_boxes(ivec2 c, uint box_w, bool karis) {
#define BOX(dx, dy) BOX_MEAN(uint(c.y + (dy)) * box_w + uint(c.x + (dx)))
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  if (FILTER == GLINT_BLOOM_DUAL) {
    add_box(sum, wsum, BOX(0, 0), 0.5, karis);
    add_box(sum, wsum, BOX(-1, -1), 0.125, karis);
    add_box(sum, wsum, BOX(1, -1), 0.125, karis);
    add_box(sum, wsum, BOX(-1, 1), 0.125, karis);
    add_box(sum, wsum, BOX(1, 1), 0.125, karis);
    return sum / wsum;
  }
  vec3 inner = (BOX(-1, -1) + BOX(1, -1) + BOX(-1, 1) + BOX(1, 1)) * 0.25;
  vec3 g00 = BOX(-2, -2), g10 = BOX(0, -2), g20 = BOX(2, -2);
  vec3 g01 = BOX(-2, 0), g11 = BOX(0, 0), g21 = BOX(2, 0);
  vec3 g02 = BOX(-2, 2), g12 = BOX(0, 2), g22 = BOX(2, 2);
#undef BOX
  add_box(sum, wsum, inner, 0.5, karis);
  add_box(sum, wsum, (g00 + g10 + g01 + g11) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g10 + g20 + g11 + g21) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g01 + g11 + g02 + g12) * 0.25, 0.125, karis);
  add_box(sum, wsum, (g11 + g21 + g12 + g22) * 0.25, 0.125, karis);
  return sum / wsum;
}
