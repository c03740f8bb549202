// The look of one light's flare, shared by the raster path (flare.vert computes the sprites,
// flare.frag shades them) and the compute gather (flare_gather.comp does both), so both paths
// evaluate exactly the same function. docs/FLARE.md describes it; tools/reference/flare_reference.cpp
// is its float64 twin. `precise` keeps the compiler from contracting or reordering these
// expressions differently in the vertex and compute stages.
#include "glint/gpu/flare_types.h"
#include "flare_params.h"
#include "glint/gpu/lod.glsl"

// One screen-aligned rectangle of one light, in pixels (y down, pixel centres at +0.5).
struct GlintFlareSprite {
  vec2 lo;    // top-left corner
  vec2 size;  // width and height; 0: nothing to draw
  vec3 rgb;   // light colour * light intensity * visible fraction * global intensity * weight * tint
  uint tile;  // GLINT_FLARE_ELEMENT_*: the atlas tile
  float lod;  // atlas level (atlas-aware LOD of include/glint/gpu/lod_impl.h, padding-capped)
};

// x, y, w, h of a tile in level-0 texels.
vec4 glint_flare_tile(uint element) {
  if (element == GLINT_FLARE_ELEMENT_STREAK)
    return vec4(GLINT_FLARE_TILE_STREAK_X, GLINT_FLARE_TILE_STREAK_Y, GLINT_FLARE_TILE_STREAK_W, GLINT_FLARE_TILE_STREAK_H);
  if (element == GLINT_FLARE_ELEMENT_HALO)
    return vec4(GLINT_FLARE_TILE_HALO_X, GLINT_FLARE_TILE_HALO_Y, GLINT_FLARE_TILE_HALO_W, GLINT_FLARE_TILE_HALO_H);
  if (element == GLINT_FLARE_ELEMENT_STARBURST)
    return vec4(GLINT_FLARE_TILE_STARBURST_X, GLINT_FLARE_TILE_STARBURST_Y, GLINT_FLARE_TILE_STARBURST_W,
                GLINT_FLARE_TILE_STARBURST_H);
  if (element == GLINT_FLARE_ELEMENT_GHOST)
    return vec4(GLINT_FLARE_TILE_GHOST_X, GLINT_FLARE_TILE_GHOST_Y, GLINT_FLARE_TILE_GHOST_W, GLINT_FLARE_TILE_GHOST_H);
  return vec4(GLINT_FLARE_TILE_GLOW_X, GLINT_FLARE_TILE_GLOW_Y, GLINT_FLARE_TILE_GLOW_W, GLINT_FLARE_TILE_GLOW_H);
}

// The atlas tile of the sprite in `slot`: the main sprite shows the instance's `element` (the glow
// when it is out of range), every other slot its own element.
uint glint_flare_slot_tile(uint slot, uint element) {
  if (slot == GLINT_FLARE_SLOT_MAIN) return element < GLINT_FLARE_ELEMENT_COUNT ? element : GLINT_FLARE_ELEMENT_GLOW;
  if (slot == GLINT_FLARE_SLOT_STREAK) return GLINT_FLARE_ELEMENT_STREAK;
  if (slot == GLINT_FLARE_SLOT_HALO) return GLINT_FLARE_ELEMENT_HALO;
  if (slot == GLINT_FLARE_SLOT_STARBURST) return GLINT_FLARE_ELEMENT_STARBURST;
  return GLINT_FLARE_ELEMENT_GHOST;
}

// Not NaN, not +-Inf, tested on the bits: without SignedZeroInfNanPreserve a compiler may assume
// floats are finite and fold x == x or x - x == 0 to true (lavapipe does).
bool glint_flare_finite(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }

// The sprite in `slot` (GLINT_FLARE_SLOT_*) of one instance. Instances with a non-finite field, a
// size, fraction or intensity <= 0, and slots whose weight is 0, give size 0 (nothing drawn).
GlintFlareSprite glint_flare_sprite(GlintFlareInstance inst, uint slot, GlintFlarePush p) {
  GlintFlareSprite s;
  s.lo = vec2(0.0);
  s.size = vec2(0.0);
  s.rgb = vec3(0.0);
  s.tile = GLINT_FLARE_ELEMENT_GLOW;
  s.lod = 0.0;
  bool ok = glint_flare_finite(inst.center_x_px) && glint_flare_finite(inst.center_y_px) &&
            glint_flare_finite(inst.size_px) && glint_flare_finite(inst.visible_fraction) &&
            glint_flare_finite(inst.intensity) && glint_flare_finite(inst.color_r) &&
            glint_flare_finite(inst.color_g) && glint_flare_finite(inst.color_b) && inst.size_px > 0.0 &&
            inst.visible_fraction > 0.0 && inst.intensity > 0.0;
  if (!ok) return s;

  vec2 light = vec2(inst.center_x_px, inst.center_y_px);
  vec2 centre = light;
  vec2 extent;  // in units of size_px, before the anamorphic ratio
  float weight;
  bool tinted = false;
  s.tile = glint_flare_slot_tile(slot, inst.element);
  if (slot == GLINT_FLARE_SLOT_MAIN) {
    extent = vec2(GLINT_FLARE_MAIN_SCALE);
    weight = p.weight_main;
  } else if (slot == GLINT_FLARE_SLOT_STREAK) {
    extent = vec2(p.streak_length, GLINT_FLARE_STREAK_HEIGHT);
    weight = p.weight_streak;
    tinted = true;
  } else if (slot == GLINT_FLARE_SLOT_HALO) {
    extent = vec2(GLINT_FLARE_HALO_SCALE);
    weight = p.weight_halo;
  } else if (slot == GLINT_FLARE_SLOT_STARBURST) {
    extent = vec2(GLINT_FLARE_STARBURST_SCALE);
    weight = p.weight_starburst;
  } else {
    uint k = slot - GLINT_FLARE_SLOT_GHOST0;
    float t = k == 0u ? p.ghost_pos0 : k == 1u ? p.ghost_pos1 : k == 2u ? p.ghost_pos2 : k == 3u ? p.ghost_pos3 : p.ghost_pos4;
    float scale = k == 0u ? GLINT_FLARE_GHOST_SCALE_0
                  : k == 1u ? GLINT_FLARE_GHOST_SCALE_1
                  : k == 2u ? GLINT_FLARE_GHOST_SCALE_2
                  : k == 3u ? GLINT_FLARE_GHOST_SCALE_3
                            : GLINT_FLARE_GHOST_SCALE_4;
    float gain = k == 0u ? GLINT_FLARE_GHOST_GAIN_0
                 : k == 1u ? GLINT_FLARE_GHOST_GAIN_1
                 : k == 2u ? GLINT_FLARE_GHOST_GAIN_2
                 : k == 3u ? GLINT_FLARE_GHOST_GAIN_3
                           : GLINT_FLARE_GHOST_GAIN_4;
    precise vec2 screen_centre = 0.5 * vec2(p.viewport_w, p.viewport_h);
    centre = light + (screen_centre - light) * t;  // Kilgard's ghost line: E = L + (C - L) * t
    extent = vec2(scale);
    weight = p.weight_ghost * gain;
    tinted = true;
  }
  if (!(weight > 0.0)) return s;

  precise vec2 size = extent * inst.size_px * vec2(p.anamorphic_ratio, 1.0);
  precise vec2 lo = centre - 0.5 * size;
  vec3 colour = max(vec3(inst.color_r, inst.color_g, inst.color_b), vec3(0.0));
  precise vec3 rgb = colour * (inst.intensity * inst.visible_fraction * p.intensity * weight);
  if (tinted) rgb *= vec3(p.tint_r, p.tint_g, p.tint_b);

  // Atlas-aware LOD from the analytic derivatives: the sub-UV runs 0..1 across `size` pixels, so
  // du/dx = 1 / width and dv/dy = 1 / height, no cross terms (docs/LOD.md, docs/FLARE.md).
  vec4 tile = glint_flare_tile(s.tile);
  GlintLodQuery q = GlintLodQuery(1.0 / size.x, 0.0, 0.0, 1.0 / size.y, tile.z, tile.w, tile.x, tile.y);
  GlintLodAtlas a = GlintLodAtlas(float(GLINT_FLARE_ATLAS_WIDTH), float(GLINT_FLARE_ATLAS_HEIGHT),
                                  float(GLINT_FLARE_ATLAS_LEVELS), 0.0, 1.0, float(GLINT_FLARE_ATLAS_PADDING),
                                  GLINT_LOD_PADDING_CAP, 0u);
  s.lod = glint_lod(q, a);
  s.lo = lo;
  s.size = size;
  s.rgb = rgb;
  return s;
}

// A conservative screen rectangle (x0, y0, x1, y1) around a sprite, for binning: it contains
// every pixel centre c that glint_flare_shade lights, so a tile it misses needs no test. Empty
// (x0 > x1) for a sprite that draws nothing; a rectangle that overflows fp32 gives infinite bounds
// (the sprite is tested everywhere, as glint_flare_shade would) or NaN ones (no test passes). Why the margin m = 2 + 1e-6 (|lo| + size) suffices: glint_flare_shade lights c
// only when u = fl(fl(c - lo) / size) is in [0, 1). For c <= lo - m, c - lo <= -m < 0 stays
// negative after rounding. For c >= lo + size + m, fl(c - lo) / size >= 1 + (m - 2^-24 (size + m))
// / size > 1 + 9e-7, more than the 2.5 ulp (3e-7) a Vulkan division may be off, so u >= 1. The
// rounding of the bounds themselves, 2^-24 (|lo| + size + m) each, is far inside the rest of m.
vec4 glint_flare_sprite_bounds(GlintFlareSprite s) {
  if (!(s.size.x > 0.0)) return vec4(1.0, 1.0, -1.0, -1.0);
  vec2 m = 2.0 + 1e-6 * (abs(s.lo) + s.size);
  return vec4(s.lo - m, s.lo + s.size + m);
}

// Premultiplied light that `s` adds at the pixel whose centre is `pixel` (gl_FragCoord.xy in the
// raster path, (x, y) + 0.5 in the gather). Zero outside [lo, lo + size): this test, not the
// rasterizer's coverage, decides which pixels a sprite touches, so both paths agree exactly.
vec4 glint_flare_shade(GlintFlareSprite s, vec2 pixel, sampler2D atlas) {
  if (!(s.size.x > 0.0)) return vec4(0.0);
  precise vec2 uv = (pixel - s.lo) / s.size;
  if (uv.x < 0.0 || uv.y < 0.0 || uv.x >= 1.0 || uv.y >= 1.0) return vec4(0.0);
  vec4 tile = glint_flare_tile(s.tile);
  precise vec2 atlas_uv = (tile.xy + uv * tile.zw) / vec2(GLINT_FLARE_ATLAS_WIDTH, GLINT_FLARE_ATLAS_HEIGHT);
  vec4 t = textureLod(atlas, atlas_uv, s.lod);
  return vec4(s.rgb * t.rgb, t.a);
}
