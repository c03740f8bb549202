#version 460
#extension GL_GOOGLE_include_directive : require
// The split of crowded tiles (flare_params.h, "Crowded tiles"; docs/FLARE.md, "Speed"): one
// workgroup reads the sprite pre-pass's count of every tile, gives each tile its slices and the
// split tiles their slots of partial sums in tile order (an exclusive prefix sum, so the plan is
// the same on every run), zeroes the counts and every tile's count of finished slices (which the
// gather's last slice reads) for this frame and the next, and writes the gather's launch:
// rows of tiles_x workgroups for the slots, then every tile (a slot's workgroup draws its slice
// when the slice is not the tile's first, which the tile's own workgroup draws; the slots come
// first so that the crowded tiles' slices start first).
#include "flare_params.h"

layout(local_size_x = GLINT_FLARE_SPLIT_PLAN_THREADS) in;

layout(std430, binding = 0) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(std430, binding = 1) buffer Split { uint split_words[]; };                  // layout in flare_params.h
layout(std430, binding = 2) writeonly buffer Args { uint args[8]; };              // the gather's at words 0..2
layout(push_constant) uniform Push { GlintFlareSplitPush pc; };

const uint kThreads = GLINT_FLARE_SPLIT_PLAN_THREADS;
#define GLINT_WORKGROUP_SCAN_MAX_THREADS GLINT_FLARE_SPLIT_PLAN_THREADS
#include "workgroup_scan.glsl"

uint slices_of(uint sprites) {
  return sprites >= pc.min_sprites ? clamp(sprites / pc.sprites_per_slice, 1u, pc.max_slices) : 1u;
}

// The slices of tile i when every tile keeps 1 / scale of its own (rounded down); a tile left with
// fewer than 2 is not split.
uint slices_scaled(uint i, uint scale) {
  const uint s = slices_of(split_words[i]) / scale;
  return s > 1u ? s : 1u;
}

// The slots of the run of tiles [first, last) (a split tile takes one per slice).
uint run_slots(uint first, uint last, uint scale) {
  uint slots = 0u;
  for (uint i = first; i < last; ++i) {
    const uint s = slices_scaled(i, scale);
    if (s > 1u) slots += s;
  }
  return slots;
}

void main() {
  const uint t = gl_LocalInvocationIndex;
  const uint tiles = pc.tiles_x * pc.tiles_y;
  // Invocation t plans a run of consecutive tiles.
  const uint per = (tiles + kThreads - 1u) / kThreads;
  const uint first = min(tiles, t * per), last = min(tiles, first + per);
  uint slots = run_slots(first, last, 1u);
  uint total;
  uint inclusive = workgroup_scan(slots, total);
  // More slots than there are: every tile keeps 1 / scale of its slices, scale = ceil(total /
  // GLINT_FLARE_SPLIT_SLOTS), so that the slots add up to at most total / scale (each tile's
  // floor(s / scale) <= s / scale). One scale for all tiles: the plan stays a function of the counts.
  uint scale = 1u;
  if (total > GLINT_FLARE_SPLIT_SLOTS) {  // uniform
    scale = (total + GLINT_FLARE_SPLIT_SLOTS - 1u) / GLINT_FLARE_SPLIT_SLOTS;
    slots = run_slots(first, last, scale);
    inclusive = workgroup_scan(slots, total);
  }
  const bool split = total <= GLINT_FLARE_SPLIT_SLOTS;  // always, by the bound above
  uint slot = inclusive - slots;
  for (uint i = first; i < last; ++i) {
    const uint s = split ? slices_scaled(i, scale) : 1u;
    split_words[tiles + i] = s > 1u ? (slot << 5u) | s : 1u;
    for (uint k = 0u; k < s && s > 1u; ++k) split_words[3u * tiles + slot + k] = (i << 5u) | k;
    if (s > 1u) slot += s;
    split_words[i] = 0u;              // the next frame's pre-pass counts from zero
    split_words[2u * tiles + i] = 0u;  // the gather's count of finished slices, from zero
  }
  if (t == 0u) {
    const uint used = split ? total : 0u;
    split_words[3u * tiles + GLINT_FLARE_SPLIT_SLOTS] = used;
    const uint count = min(indirect_words[pc.indirect_word], pc.capacity);  // GlintFlareIndirect::instance_count
    args[0] = count > 0u ? pc.tiles_x : 0u;
    args[1] = pc.tiles_y + (used + pc.tiles_x - 1u) / pc.tiles_x;
    args[2] = 1u;
  }
}
