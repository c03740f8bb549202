#version 460
#extension GL_GOOGLE_include_directive : require
// Lens flares for compute-only engines (issue 5 "Compute path"): launched by vkCmdDispatchIndirect
// with group_count_x = instance_count * groups_per_instance (GlintFlareIndirect). Workgroup g
// serves instance g / groups_per_instance; within it, slot = r % SPRITES and chunk = r / SPRITES
// (r = g % groups_per_instance) split that sprite's pixel rectangle into interleaved runs. Each
// pixel evaluates the shared look (kernels/common/flare_look.glsl) exactly as flare.frag does and
// adds it into an fp32 accumulation buffer with a compare-and-swap loop (core Vulkan: no float
// atomics extension needed); the tiles it touched are flagged for flare_resolve.comp, which adds
// the sum to the image once. Overlapping sprites and lights race only on those atomics.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "flare_look.glsl"

layout(std430, binding = 0) readonly buffer Instances { GlintFlareInstance instances[]; };
layout(binding = 1) uniform sampler2D atlas;
layout(std430, binding = 2) buffer Accum { uint accum[]; };  // fp32 bits, RGB per pixel
layout(std430, binding = 3) buffer TileFlags { uint tile_flags[]; };
layout(push_constant) uniform Push { GlintFlarePush pc; };

void add_float(uint i, float v) {
  uint seen = accum[i];
  for (;;) {
    uint expected = seen;
    seen = atomicCompSwap(accum[i], expected, floatBitsToUint(uintBitsToFloat(expected) + v));
    if (seen == expected) break;
  }
}

void main() {
  uint group = gl_WorkGroupID.x;
  uint instance = group / pc.groups_per_instance;
  uint r = group % pc.groups_per_instance;
  uint slot = r % GLINT_FLARE_SPRITES;
  uint chunk = r / GLINT_FLARE_SPRITES;
  uint chunks = pc.groups_per_instance / GLINT_FLARE_SPRITES;
  if (instance >= uint(instances.length())) return;
  GlintFlareSprite s = glint_flare_sprite(instances[instance], slot, pc);
  if (!(s.size.x > 0.0)) return;

  // Pixels whose centres can pass the shade test, one pixel of margin (as the raster quad), clamped
  // to the image in float before converting so that far-off sprites cannot overflow an int.
  vec2 viewport = vec2(pc.viewport_w, pc.viewport_h);
  uvec2 p0 = uvec2(clamp(floor(s.lo - 1.0), vec2(0.0), viewport));
  uvec2 p1 = uvec2(clamp(ceil(s.lo + s.size + 1.0), vec2(0.0), viewport));
  if (p1.x <= p0.x || p1.y <= p0.y) return;
  uint w = p1.x - p0.x;
  uint n = w * (p1.y - p0.y);
  uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;

  if (chunk == 0u) {  // flag every resolve tile the rectangle overlaps (all writers store 1)
    uvec2 t0 = p0 / uvec2(pc.tile_w, pc.tile_h);
    uvec2 t1 = (p1 - 1u) / uvec2(pc.tile_w, pc.tile_h);
    uint tw = t1.x - t0.x + 1u;
    uint tn = tw * (t1.y - t0.y + 1u);
    for (uint i = gl_LocalInvocationIndex; i < tn; i += threads) {
      tile_flags[(t0.y + i / tw) * pc.tiles_x + t0.x + i % tw] = 1u;
    }
  }
  uint width_px = uint(pc.viewport_w);
  for (uint i = chunk * threads + gl_LocalInvocationIndex; i < n; i += chunks * threads) {
    uvec2 p = p0 + uvec2(i % w, i / w);
    vec3 v = glint_flare_shade(s, vec2(p) + 0.5, atlas).rgb;
    if (v == vec3(0.0)) continue;
    uint base = (p.y * width_px + p.x) * 3u;
    add_float(base, v.r);
    add_float(base + 1u, v.g);
    add_float(base + 2u, v.b);
  }
}
