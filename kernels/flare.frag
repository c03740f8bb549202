#version 460
#extension GL_GOOGLE_include_directive : require
// Shades one lens-flare sprite (issue 5 "Raster path"): the shared look function at the pixel
// centre, premultiplied alpha, added to the HDR image by ONE/ONE blending (flares only add light;
// alpha is masked out of the write, so the image's alpha is kept).
#include "flare_look.glsl"

layout(binding = 1) uniform sampler2D atlas;

layout(location = 0) flat in vec4 v_rect;
layout(location = 1) flat in vec4 v_atlas;
layout(location = 2) flat in vec4 v_rgb_lod;
layout(location = 0) out vec4 color;

void main() { color = glint_flare_shade(GlintFlareShading(v_rect, v_atlas, v_rgb_lod), gl_FragCoord.xy, atlas); }
