#version 460
#extension GL_GOOGLE_include_directive : require
// Shades one lens-flare sprite (docs/FLARE.md, "The two paths": raster): the shared look function at the pixel
// centre, premultiplied alpha, added to the HDR image by ONE/ONE blending (flares only add light;
// alpha is masked out of the write, so the image's alpha is kept).
#include "flare_look.glsl"

layout(binding = 1) uniform sampler2D atlas;

layout(location = 0) flat in vec4 v_rect;
layout(location = 1) flat in vec4 v_rgb_lod;
layout(location = 2) flat in uint v_tile;
layout(location = 0) out vec4 color;

void main() {
  GlintFlareSprite s;
  s.lo = v_rect.xy;
  s.size = v_rect.zw;
  s.rgb = v_rgb_lod.rgb;
  s.lod = v_rgb_lod.w;
  s.tile = v_tile;
  color = glint_flare_shade(s, gl_FragCoord.xy, atlas);
}
