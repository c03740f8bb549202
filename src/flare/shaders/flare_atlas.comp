#version 460
#extension GL_GOOGLE_include_directive : require
// Builds the lens-flare element atlas (docs/FLARE.md, "Atlas layout, mips, LOD and padding": generated
// procedurally by a compute shader at start-up). Level 0: every texel inside a tile evaluates its
// element (src/flare/shaders/flare_elements.glsl), every other texel (padding, unused space) is 0.
// Level k > 0: the 2x2 box average of level k - 1 (tile offsets and sizes are multiples of 16, so
// no box straddles two tiles). One dispatch per level, with a barrier in between.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "flare_elements.glsl"
#include "flare_params.h"

layout(binding = 0, rgba16f) uniform readonly image2D src;  // level - 1 (unused at level 0)
layout(binding = 1, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { GlintFlareAtlasPush pc; };

vec4 level0(uvec2 p) {
  for (uint e = 0u; e < GLINT_FLARE_ELEMENT_COUNT; ++e) {
    uvec4 t = e == GLINT_FLARE_ELEMENT_GLOW ? uvec4(GLINT_FLARE_TILE_GLOW_X, GLINT_FLARE_TILE_GLOW_Y, GLINT_FLARE_TILE_GLOW_W, GLINT_FLARE_TILE_GLOW_H)
            : e == GLINT_FLARE_ELEMENT_STREAK ? uvec4(GLINT_FLARE_TILE_STREAK_X, GLINT_FLARE_TILE_STREAK_Y, GLINT_FLARE_TILE_STREAK_W, GLINT_FLARE_TILE_STREAK_H)
            : e == GLINT_FLARE_ELEMENT_HALO ? uvec4(GLINT_FLARE_TILE_HALO_X, GLINT_FLARE_TILE_HALO_Y, GLINT_FLARE_TILE_HALO_W, GLINT_FLARE_TILE_HALO_H)
            : e == GLINT_FLARE_ELEMENT_STARBURST ? uvec4(GLINT_FLARE_TILE_STARBURST_X, GLINT_FLARE_TILE_STARBURST_Y, GLINT_FLARE_TILE_STARBURST_W, GLINT_FLARE_TILE_STARBURST_H)
            : uvec4(GLINT_FLARE_TILE_GHOST_X, GLINT_FLARE_TILE_GHOST_Y, GLINT_FLARE_TILE_GHOST_W, GLINT_FLARE_TILE_GHOST_H);
    if (p.x >= t.x && p.y >= t.y && p.x < t.x + t.z && p.y < t.y + t.w) {
      vec2 q = (vec2(p - t.xy) + 0.5) / vec2(t.zw) * 2.0 - 1.0;
      return glint_flare_element(e, q);
    }
  }
  return vec4(0.0);
}

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  vec4 v;
  if (pc.level == 0u) {
    v = level0(p);
  } else {
    ivec2 s = ivec2(p * 2u);
    v = 0.25 * (imageLoad(src, s) + imageLoad(src, s + ivec2(1, 0)) + imageLoad(src, s + ivec2(0, 1)) +
                imageLoad(src, s + ivec2(1, 1)));
  }
  imageStore(dst, ivec2(p), v);
}
