#version 460
#extension GL_GOOGLE_include_directive : require
// The split of crowded tiles (flare_params.h, "Crowded tiles"; docs/FLARE.md, "Speed"): one
// workgroup reads the sprite pre-pass's count of every tile, gives each tile its slices and the
// split tiles their slots of partial sums in tile order (an exclusive prefix sum, so the plan is
// the same on every run), zeroes the counts for the next frame and writes the gather's launch:
// every tile, then rows of tiles_x workgroups for the slots (a slot's workgroup draws its slice
// when the slice is not the tile's first, which the tile's own workgroup draws).
#include "flare_params.h"

layout(local_size_x = GLINT_FLARE_SPLIT_PLAN_THREADS) in;

layout(std430, binding = 0) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(std430, binding = 1) buffer Split { uint split_words[]; };                  // layout in flare_params.h
layout(std430, binding = 2) writeonly buffer Args { uint args[8]; };              // the gather's at words 0..2
layout(push_constant) uniform Push { GlintFlareSplitPush pc; };

const uint kThreads = GLINT_FLARE_SPLIT_PLAN_THREADS;
shared uint s_scan[2][kThreads];

uint slices_of(uint sprites) {
  return sprites >= pc.min_sprites ? clamp(sprites / pc.sprites_per_slice, 1u, pc.max_slices) : 1u;
}

void main() {
  const uint t = gl_LocalInvocationIndex;
  const uint tiles = pc.tiles_x * pc.tiles_y;
  // Invocation t plans a run of consecutive tiles.
  const uint per = (tiles + kThreads - 1u) / kThreads;
  const uint first = min(tiles, t * per), last = min(tiles, first + per);
  uint slots = 0u;  // slots of this run's split tiles (a split tile takes one per slice)
  for (uint i = first; i < last; ++i) {
    const uint s = slices_of(split_words[i]);
    if (s > 1u) slots += s;
  }
  // Inclusive scan of the runs' slots (Hillis & Steele 1986).
  s_scan[0][t] = slots;
  barrier();
  uint src = 0u;
  for (uint d = 1u; d < kThreads; d <<= 1u) {
    uint v = s_scan[src][t];
    if (t >= d) v += s_scan[src][t - d];
    s_scan[src ^ 1u][t] = v;
    barrier();
    src ^= 1u;
  }
  const uint total = s_scan[src][kThreads - 1u];
  const bool split = total <= GLINT_FLARE_SPLIT_SLOTS;  // else no tile is split this frame
  uint slot = s_scan[src][t] - slots;
  for (uint i = first; i < last; ++i) {
    uint s = slices_of(split_words[i]);
    if (!split) s = 1u;
    split_words[tiles + i] = s > 1u ? (slot << 5u) | s : 1u;
    for (uint k = 0u; k < s && s > 1u; ++k) split_words[3u * tiles + slot + k] = (i << 5u) | k;
    if (s > 1u) slot += s;
    split_words[i] = 0u;  // the next frame's pre-pass counts from zero
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
