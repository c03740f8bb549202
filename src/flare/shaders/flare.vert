#version 460
#extension GL_GOOGLE_include_directive : require
// Lens-flare billboards (docs/FLARE.md, "The two paths": raster, instanced): one instanced
// draw for all lights. The instance buffer is read by gl_InstanceIndex (no vertex buffers); each
// instance expands to GLINT_FLARE_SPRITES screen-aligned rectangles, gl_VertexIndex / 6 picking
// the sprite and gl_VertexIndex % 6 the corner. The rectangle is drawn one pixel larger on every
// side; flare.frag decides coverage with the same test as the compute gather.
#include "flare_look.glsl"

layout(std430, binding = 0) readonly buffer Instances { GlintFlareInstance instances[]; };
layout(push_constant) uniform Push { GlintFlarePush pc; };

layout(location = 0) flat out vec4 v_rect;  // lo.xy, size.xy
layout(location = 1) flat out vec4 v_rgb_lod;
layout(location = 2) flat out uint v_tile;

void main() {
  uint slot = uint(gl_VertexIndex) / GLINT_FLARE_VERTICES_PER_SPRITE;
  uint corner = uint(gl_VertexIndex) % GLINT_FLARE_VERTICES_PER_SPRITE;
  GlintFlareSprite s;
  s.size = vec2(0.0);
  if (uint(gl_InstanceIndex) < uint(instances.length())) s = glint_flare_sprite(instances[gl_InstanceIndex], slot, pc);
  v_rect = vec4(s.lo, s.size);
  v_rgb_lod = vec4(s.rgb, s.lod);
  v_tile = s.tile;
  if (!(s.size.x > 0.0)) {  // nothing to draw: a degenerate triangle outside the view volume
    gl_Position = vec4(-2.0, -2.0, 0.0, 1.0);
    return;
  }
  // Triangles (0, 1, 2) and (2, 1, 3) of the corners 0 = top-left, 1 = top-right, 2 = bottom-left,
  // 3 = bottom-right.
  const uint corners[6] = uint[6](0u, 1u, 2u, 2u, 1u, 3u);
  uint c = corners[corner];
  vec2 pixel = vec2((c & 1u) != 0u ? s.lo.x + s.size.x + 1.0 : s.lo.x - 1.0,
                    (c & 2u) != 0u ? s.lo.y + s.size.y + 1.0 : s.lo.y - 1.0);
  vec2 viewport = vec2(pc.viewport_w, pc.viewport_h);
  // Far-off sprites: clamp to a guard band so the rasterizer never sees huge coordinates.
  pixel = clamp(pixel, -viewport, 2.0 * viewport);
  gl_Position = vec4(pixel / viewport * 2.0 - 1.0, 0.0, 1.0);  // NDC y = -1 is the first row
}
