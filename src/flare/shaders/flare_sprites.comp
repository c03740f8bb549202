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
// With kCount (the pre-pass gather splits crowded tiles: flare_params.h), each sprite adds 1 to
// the count of every gather tile (pc.tile_w x pc.tile_h) its conservative rectangle meets (the
// gather's binning test; a tile that the rectangle only touches may count it too: the counts
// only choose the plan); a sprite meeting more than kCountMaxTiles tiles adds to none (it
// weighs about the same on every tile it meets, so it makes no tile more crowded than the
// others). The counts are integers: the same in any order.
layout(constant_id = 2) const uint kCount = 0u;
layout(std430, binding = 3) buffer Split { uint split_words[]; };  // [0, tiles): the counts
const uint kCountMaxTiles = 64u;
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
    // (A rectangle outside the image meets no tile: the clamps below would count it on an edge tile.)
    const bool on_image =
        bounds.z > 0.0 && bounds.w > 0.0 && bounds.x < pc.viewport_w && bounds.y < pc.viewport_h;
    if (kCount != 0u && on_image && bounds.x <= bounds.z && bounds.y <= bounds.w) {
      // Tiles i with bounds.x < (i + 1) tile_w and bounds.z > i tile_w, clamped to the image's.
      const uvec2 tiles = (uvec2(pc.viewport_w, pc.viewport_h) + uvec2(pc.tile_w, pc.tile_h) - 1u) /
                          uvec2(pc.tile_w, pc.tile_h);
      const vec2 size = vec2(pc.tile_w, pc.tile_h), hi = vec2(tiles) - 1.0;
      const uvec2 lo_tile = uvec2(clamp(floor(bounds.xy / size), vec2(0.0), hi));
      const uvec2 hi_tile = uvec2(clamp(ceil(bounds.zw / size) - 1.0, vec2(0.0), hi));
      if (all(lessThanEqual(lo_tile, hi_tile)) &&
          (hi_tile.x - lo_tile.x + 1u) * (hi_tile.y - lo_tile.y + 1u) <= kCountMaxTiles) {
        for (uint y = lo_tile.y; y <= hi_tile.y; ++y)
          for (uint x = lo_tile.x; x <= hi_tile.x; ++x) atomicAdd(split_words[y * tiles.x + x], 1u);
      }
    }
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
