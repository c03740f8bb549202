#version 460
#extension GL_GOOGLE_include_directive : require
// The compute path's sprite pre-pass (docs/FLARE.md, "The two paths": compute): every sprite of
// every visible instance is evaluated once per frame with glint_flare_sprite (the function
// flare.vert evaluates) into a block per instance (layout in flare_params.h), with the union of the
// sprites' conservative rectangles (glint_flare_sprite_bounds). The gather then tests one rectangle
// per instance and tile, and nine only for the instances that meet the tile, and shades from the
// stored sprites instead of evaluating them again in every tile.
// Invocation (x, y) takes slot x of instance GLINT_FLARE_SPRITES_INSTANCES * group + y, the group
// being the linear index of rows of workgroups (flare_gather_args.comp writes the launch).
#include "flare_look.glsl"

layout(local_size_x = GLINT_FLARE_SPRITES_SLOTS, local_size_y = GLINT_FLARE_SPRITES_INSTANCES) in;

layout(std430, binding = 0) readonly buffer Instances { GlintFlareInstance instances[]; };
layout(std430, binding = 1) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(std430, binding = 2) writeonly buffer Sprites { vec4 blocks[]; };
layout(push_constant) uniform Push { GlintFlarePush pc; };

shared vec4 s_bounds[GLINT_FLARE_SPRITES_INSTANCES][GLINT_FLARE_SPRITES_SLOTS];

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint i = group * GLINT_FLARE_SPRITES_INSTANCES + gl_LocalInvocationID.y;
  const uint slot = gl_LocalInvocationID.x;
  uint count = indirect_words[pc.indirect_word];  // GlintFlareIndirect::instance_count
  count = min(min(count, uint(instances.length())), uint(blocks.length()) / GLINT_FLARE_BLOCK_VEC4S);

  vec4 bounds = vec4(1.0, 1.0, -1.0, -1.0);  // empty
  if (i < count && slot < GLINT_FLARE_SPRITES) {
    GlintFlareSprite s = glint_flare_sprite(instances[i], slot, pc);
    blocks[i * GLINT_FLARE_BLOCK_VEC4S + 1u + 2u * slot] = vec4(s.lo, s.size);
    blocks[i * GLINT_FLARE_BLOCK_VEC4S + 2u + 2u * slot] = vec4(s.rgb, s.lod);
    bounds = glint_flare_sprite_bounds(s);
  }
  s_bounds[gl_LocalInvocationID.y][slot] = bounds;
  barrier();
  if (i < count && slot == 0u) {
    // The union of the non-empty rectangles; a NaN one (an overflowing sprite) is left out, as
    // the gather's own test of that sprite would leave it out.
    vec4 u = vec4(1.0, 1.0, -1.0, -1.0);
    bool any = false;
    for (uint k = 0u; k < GLINT_FLARE_SPRITES; ++k) {
      vec4 b = s_bounds[gl_LocalInvocationID.y][k];
      if (!(b.x <= b.z && b.y <= b.w)) continue;
      u = any ? vec4(min(u.xy, b.xy), max(u.zw, b.zw)) : b;
      any = true;
    }
    blocks[i * GLINT_FLARE_BLOCK_VEC4S] = u;
  }
}
