#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// Lens flares for compute-only engines (docs/FLARE.md, "The two paths": compute), accumulated by gathering: one
// workgroup per screen tile of workgroup x by (workgroup y * kRows) pixels (each invocation keeps
// its column's kRows pixels in registers), no atomics on the image (with kSplit, one counter per
// split tile counts its finished slices). The sprites
// were evaluated once for the frame by flare_sprites.comp (layout in flare_params.h), or, for few
// instances (kFused), by the gather's own invocations, one sprite each: the whole draw is then
// this one dispatch.
// 1. Binning: invocation t takes instance base + t (the count is instance_count of the indirect
//    arguments, read here; indices past the buffers are skipped), tests the union of its sprites'
//    conservative rectangles against the tile and, when it meets the tile, each sprite's own
//    rectangle (glint_flare_sprite_bounds). The sprites that meet the tile go into a shared list,
//    at a position given by an exclusive prefix sum of the invocations' hit counts
//    (Hillis & Steele 1986, in shared memory): the list is in (instance, slot) order, the order the
//    raster path draws in, on every run: no atomic decides the order of the sums, so every run gives the same bits.
//    kFused: invocation t evaluates sprite t % GLINT_FLARE_SPRITES of instance
//    base + t / GLINT_FLARE_SPRITES and tests that sprite's rectangle; the same prefix sum, of at
//    most one sprite per invocation, is counted from a bit mask of the invocations whose sprite
//    meets the tile (set with atomicOr, which gives the same bits in any order), so the list has
//    the same order.
// 2. Sprites: the listed sprites are read into shared memory in chunks of one per invocation
//    (kFused: the invocation that listed a sprite stores it there itself; one chunk per batch).
// 3. Shading: every invocation adds glint_flare_shade (the function flare.frag evaluates) of every
//    listed sprite at each of its pixel centres, in fp32.
// Finally a pixel that received light is read, gains the sum and is written once (alpha kept);
// pixels that received none are not touched (bit-identical).
// With kSplit (the pre-pass gather on GPUs), flare_split_plan.comp has given each tile slices: a
// tile of one slice is drawn as above; a crowded one by one workgroup per slice (the slots'
// workgroups come first in the launch, then the tiles'), each drawing a
// contiguous range of the instances into a slot of partial sums, and the last of them to finish
// adds the slots in slice order (p0 + p1 + ...: the same order on every run) and writes the
// pixels. Its sums are then grouped by slice, so a split tile's bits differ from an unsplit one's
// by the fp32 rounding of that grouping, within the same bound. docs/FLARE.md "The two paths" says
// why this replaced a per-sprite splat with a float compare-and-swap per pixel.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "flare_look.glsl"

#ifndef DST_FORMAT
#define DST_FORMAT rgba16f
#endif

layout(std430, binding = 0) readonly buffer Instances { GlintFlareInstance instances[]; };
layout(binding = 1) uniform sampler2D atlas;
layout(std430, binding = 2) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(binding = 3, DST_FORMAT) uniform image2D color;
layout(std430, binding = 4) readonly buffer Sprites { vec4 blocks[]; };  // flare_sprites.comp's output
layout(push_constant) uniform Push { GlintFlarePush pc; };
// 1 when the instances buffer holds more instances than the sprite store (LensFlare::record_compute
// picks this variant only then): the sprites of the instances beyond it are evaluated here.
layout(constant_id = 2) const uint kBeyondStore = 0u;
// 1 for the one-dispatch draw of few instances (LensFlare::record_compute picks it on GPUs when the
// instances buffer holds at most threads / GLINT_FLARE_SPRITES instances): there is no pre-pass,
// invocation t evaluates sprite t % GLINT_FLARE_SPRITES of instance t / GLINT_FLARE_SPRITES itself
// and lists it where it meets the tile, so the list is in the same (instance, slot) order and the
// sums are the same as the pre-pass's draw gives. `blocks` is not read.
layout(constant_id = 3) const uint kFused = 0u;
// Pixels each invocation shades, one per row, rows gl_WorkGroupSize.y apart (at most
// GLINT_FLARE_GATHER_ROWS; flare_params.h says which path takes how many).
layout(constant_id = 4) const uint kRows = GLINT_FLARE_GATHER_ROWS;

const uint kMaxThreads = GLINT_FLARE_GATHER_MAX_THREADS;
shared uint s_scan[2][kMaxThreads];                     // hit counts, then their prefix sums
shared uint s_list[kMaxThreads * GLINT_FLARE_SPRITES];  // instance * 16 + slot (not used with kFused)
shared vec4 s_rect[kMaxThreads];                        // lo.xy, size.xy of the listed sprites
shared vec4 s_rgb_lod[kMaxThreads];
shared uint s_tile[kMaxThreads];
shared uint s_hit[(kMaxThreads + 31u) / 32u];  // kFused: bit t % 32 of word t / 32 is set when invocation t's sprite meets the tile

// The sprite in `slot` of instance i: read from the pre-pass's block when the instance has one,
// else evaluated.
GlintFlareSprite gather_sprite(uint i, uint slot, uint stored) {
  if (kBeyondStore != 0u && i >= stored) return glint_flare_sprite(instances[i], slot, pc);
  GlintFlareSprite s;
  vec4 rect = blocks[i * GLINT_FLARE_BLOCK_VEC4S + 1u + 2u * slot];
  vec4 rgb_lod = blocks[i * GLINT_FLARE_BLOCK_VEC4S + 2u + 2u * slot];
  s.lo = rect.xy;
  s.size = rect.zw;
  s.rgb = rgb_lod.rgb;
  s.lod = rgb_lod.w;
  s.tile = glint_flare_slot_tile(slot, instances[i].element);
  return s;
}

// With kCentreFirst, workgroup k of n along one axis takes tile centre_out(k, n): the middle tile
// first, then its neighbours alternately on either side (n / 2, n / 2 - 1, n / 2 + 1, ...; a
// bijection of 0 .. n - 1). The H200 starts a dispatch's workgroups about in the order of their IDs
// (as measured; Vulkan promises no order), and every light's ghost at t = 1 lands on the image
// centre, so with many lights the tiles that list the most sprites start first instead of halfway
// through the dispatch (1000 lights at 1080p: 488.9 -> 375.2 us). The host sets it for the
// pre-pass gather on GPUs; the one-dispatch gather (10 lights: 34.9 us against 36.6 centre first)
// and lavapipe were faster in the IDs' order (docs/FLARE.md, "Speed").
layout(constant_id = 5) const uint kCentreFirst = 0u;
// 1: tiles are split as flare_split_plan.comp planned (the launch has rows of the slots'
// workgroups before the tiles' rows); 0: every tile is one slice (bindings 5 and 6 are not read).
layout(constant_id = 6) const uint kSplit = 0u;
layout(std430, binding = 5) coherent buffer Split { uint split_words[]; };  // layout in flare_params.h
layout(std430, binding = 6) coherent buffer Partials { vec4 partials[]; };  // GLINT_FLARE_SPLIT_SLOTS slots
shared bool s_last;  // this workgroup is the last of its tile's slices to finish
uint centre_out(uint k, uint n) { return (k & 1u) == 0u ? (n >> 1u) + (k >> 1u) : (n >> 1u) - ((k + 1u) >> 1u); }

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  // The tile, and this invocation's column of pixels in it (rows gl_WorkGroupSize.y apart).
  const uint tiles_x = gl_NumWorkGroups.x;
  const uint tiles_y = kSplit != 0u ? (uint(pc.viewport_h) + pc.tile_h - 1u) / pc.tile_h : gl_NumWorkGroups.y;
  const uint tiles = tiles_x * tiles_y;
  uvec2 tile_id;
  uint slice = 0u;  // which of its tile's slices this workgroup draws
  if (kSplit != 0u) {  // (a specialization constant: the gathers that split nothing keep none of this)
    // The launch's first rows are the slots' workgroups, so that the slices of the crowded tiles
    // start first; the tiles' workgroups follow.
    const uint slots_used = split_words[3u * tiles + GLINT_FLARE_SPLIT_SLOTS];
    const uint slot_rows = (slots_used + tiles_x - 1u) / tiles_x;
    if (gl_WorkGroupID.y < slot_rows) {
      // A slot's workgroup: it draws the slot's slice unless that is its tile's first.
      const uint h = gl_WorkGroupID.y * tiles_x + gl_WorkGroupID.x;
      if (h >= slots_used) return;  // uniform
      const uint e = split_words[3u * tiles + h];
      slice = e & 31u;
      if (slice == 0u) return;
      tile_id = uvec2((e >> 5u) % tiles_x, (e >> 5u) / tiles_x);
    } else {
      const uvec2 id = uvec2(gl_WorkGroupID.x, gl_WorkGroupID.y - slot_rows);
      tile_id = kCentreFirst == 0u ? id : uvec2(centre_out(id.x, tiles_x), centre_out(id.y, tiles_y));
    }
  } else {
    tile_id = kCentreFirst == 0u ? gl_WorkGroupID.xy
                                 : uvec2(centre_out(gl_WorkGroupID.x, tiles_x), centre_out(gl_WorkGroupID.y, tiles_y));
  }
  const uint tile_index = tile_id.y * tiles_x + tile_id.x;
  uint slices = 1u, slot0 = 0u;
  if (kSplit != 0u) {
    const uint plan = split_words[tiles + tile_index];
    slices = max(plan & 31u, 1u);
    slot0 = plan >> 5u;
  }
  const uvec2 tile0 = tile_id * uvec2(pc.tile_w, pc.tile_h);
  const vec2 tile_lo = vec2(tile0), tile_hi = vec2(tile0 + uvec2(pc.tile_w, pc.tile_h));
  const uvec2 p0 = tile0 + gl_LocalInvocationID.xy;

  uint count = indirect_words[pc.indirect_word];  // GlintFlareIndirect::instance_count
  count = min(count, uint(instances.length()));
  // Instances below `stored` have their sprites in `blocks`; the rest (only with kBeyondStore:
  // an instances buffer larger than one descriptor of blocks holds) are evaluated here, with the
  // same function.
  const uint stored = kFused != 0u ? 0u : min(count, uint(blocks.length()) / GLINT_FLARE_BLOCK_VEC4S);
  if (kBeyondStore == 0u && kFused == 0u) count = stored;
  // Instances per batch: one per invocation, or (kFused) one per GLINT_FLARE_SPRITES invocations.
  const uint batch = kFused != 0u ? threads / GLINT_FLARE_SPRITES : threads;
  // This slice's instances: the count in `slices` near-equal contiguous ranges.
  uint begin = 0u, end = count;
  if (slices > 1u) {
    const uint q = count / slices, rem = count % slices;
    begin = slice * q + min(slice, rem);
    end = begin + q + (slice < rem ? 1u : 0u);
  }

  vec3 sum[GLINT_FLARE_GATHER_ROWS];  // indexed by unrolled loops only, so it stays in registers
  [[unroll]] for (uint r = 0u; r < kRows; ++r) sum[r] = vec3(0.0);

  for (uint base = begin; base < end; base += batch) {
    // 1. Binning: the instance's union rectangle, then each of its sprites, against the tile
    //    (kFused: this invocation's own sprite).
    uint i = base + t;
    uint hits = 0u;  // bit `slot`: that sprite meets the tile
    GlintFlareSprite mine;  // kFused: the sprite this invocation evaluated
    if (kFused != 0u) {
      // The previous batch's last barrier ended its reads of the mask.
      if (t < (threads + 31u) / 32u) s_hit[t] = 0u;
      const uint slot = t % GLINT_FLARE_SPRITES;
      i = base + t / GLINT_FLARE_SPRITES;
      if (t / GLINT_FLARE_SPRITES < batch && i < end) {
        mine = glint_flare_sprite(instances[i], slot, pc);
        vec4 b = glint_flare_sprite_bounds(mine);
        if (b.x < tile_hi.x && b.z > tile_lo.x && b.y < tile_hi.y && b.w > tile_lo.y) hits = 1u << slot;
      }
    } else if (i < end) {
      vec4 u = kBeyondStore != 0u && i >= stored ? vec4(tile_lo, tile_hi) : blocks[i * GLINT_FLARE_BLOCK_VEC4S];
      if (u.x < tile_hi.x && u.z > tile_lo.x && u.y < tile_hi.y && u.w > tile_lo.y) {
        [[unroll]] for (uint slot = 0u; slot < GLINT_FLARE_SPRITES; ++slot) {
          vec4 b = glint_flare_sprite_bounds(gather_sprite(i, slot, stored));
          if (b.x < tile_hi.x && b.z > tile_lo.x && b.y < tile_hi.y && b.w > tile_lo.y) hits |= 1u << slot;
        }
      }
    }
    uint listed;  // sprites in this batch's list: the same in every invocation
    if (kFused != 0u) {
      // At most one sprite per invocation: its place in the list is the number of invocations
      // before it whose sprite meets the tile, counted in a mask of one bit per invocation that
      // the invocations set with atomicOr (OR gives the same bits in any order): two barriers,
      // where the scan below takes one per power of two up to the workgroup size.
      barrier();
      if (hits != 0u) atomicOr(s_hit[t >> 5u], 1u << (t & 31u));
      barrier();
      uint at = uint(bitCount(s_hit[t >> 5u] & ((1u << (t & 31u)) - 1u)));
      listed = 0u;
      [[unroll]] for (uint w = 0u; w < (threads + 31u) / 32u; ++w) {  // a specialization constant: no loop left
        const uint c = uint(bitCount(s_hit[w]));
        listed += c;
        if (w < (t >> 5u)) at += c;
      }
      if (hits != 0u) {  // one chunk: stored as it is
        s_rect[at] = vec4(mine.lo, mine.size);
        s_rgb_lod[at] = vec4(mine.rgb, mine.lod);
        s_tile[at] = mine.tile;
      }
    } else {
      // Inclusive scan of the hit counts (the previous batch's last barrier ended its reads), one
      // step per power of two below the workgroup size (at most GLINT_FLARE_GATHER_MAX_THREADS =
      // 256), written out: `threads` is a specialization constant, so the steps past it fold away
      // and no loop is left (lavapipe ends a shader after 65535 loop iterations in all, which the
      // loop over batches would otherwise reach with a few hundred thousand instances).
      const uint own = uint(bitCount(hits));
      s_scan[0][t] = own;
      barrier();
      uint src = 0u;
#define GLINT_SCAN_STEP(d)                        \
  if ((d) < threads) {                            \
    uint v = s_scan[src][t];                      \
    if (t >= (d)) v += s_scan[src][t - (d)];      \
    s_scan[src ^ 1u][t] = v;                      \
    barrier();                                    \
    src ^= 1u;                                    \
  }
      GLINT_SCAN_STEP(1u)
      GLINT_SCAN_STEP(2u)
      GLINT_SCAN_STEP(4u)
      GLINT_SCAN_STEP(8u)
      GLINT_SCAN_STEP(16u)
      GLINT_SCAN_STEP(32u)
      GLINT_SCAN_STEP(64u)
      GLINT_SCAN_STEP(128u)
#undef GLINT_SCAN_STEP
      listed = s_scan[src][threads - 1u];  // the same in every invocation
      for (uint at = s_scan[src][t] - own; hits != 0u; ++at) {
        uint slot = uint(findLSB(hits));
        hits &= hits - 1u;
        s_list[at] = i * 16u + slot;
      }
    }
    for (uint e0 = 0u; e0 < listed; e0 += threads) {
      barrier();  // the previous chunk's sprites have been shaded (and every invocation read `listed`)
      // 2. Sprites: one per invocation, mostly as flare_sprites.comp stored it.
      if (kFused == 0u && e0 + t < listed) {
        uint packed = s_list[e0 + t];
        GlintFlareSprite s = gather_sprite(packed >> 4u, packed & 15u, stored);
        s_rect[t] = vec4(s.lo, s.size);
        s_rgb_lod[t] = vec4(s.rgb, s.lod);
        s_tile[t] = s.tile;
      }
      if (kFused == 0u) barrier();  // kFused: the list was stored before the barrier above
      // 3. Shading: each listed sprite at each of this invocation's pixel centres.
      uint n = min(threads, listed - e0);
      for (uint k = 0u; k < n; ++k) {
        GlintFlareSprite s;
        s.lo = s_rect[k].xy;
        s.size = s_rect[k].zw;
        s.rgb = s_rgb_lod[k].rgb;
        s.lod = s_rgb_lod[k].w;
        s.tile = s_tile[k];
        if (!(s.size.x > 0.0)) continue;
        // glint_flare_shade's own horizontal test (the same expression), once for the column.
        precise float u = (float(p0.x) + 0.5 - s.lo.x) / s.size.x;
        if (u < 0.0 || u >= 1.0) continue;
        // Rows whose centre lies outside the sprite's conservative rectangle get 0 from
        // glint_flare_shade, and adding 0 leaves a sum unchanged: two comparisons (the same for a
        // whole row of the workgroup) skip its divisions and the sample. A small sprite meets one
        // or two of 8 rows.
        const vec4 b = glint_flare_sprite_bounds(s);
        [[unroll]] for (uint r = 0u; r < kRows; ++r) {
          vec2 pixel = vec2(p0.x, p0.y + r * gl_WorkGroupSize.y) + 0.5;
          if (pixel.y > b.y && pixel.y < b.w) sum[r] += glint_flare_shade(s, pixel, atlas).rgb;
        }
      }
    }
    barrier();  // the list is consumed before the next batch resets it
  }

  if (slices > 1u) {  // uniform: the tile's plan
    // This slice's sums to its slot, then count the slice (the image barrier pattern of
    // hiz_build.comp: the stores are made visible before the atomic that the last workgroup reads).
    const uint slot_size = threads * kRows;
    [[unroll]] for (uint r = 0u; r < kRows; ++r) partials[(slot0 + slice) * slot_size + r * threads + t] = vec4(sum[r], 0.0);
    memoryBarrierBuffer();
    barrier();
    if (t == 0u) s_last = atomicAdd(split_words[2u * tiles + tile_index], 1u) == slices - 1u;
    barrier();
    if (!s_last) return;  // uniform: a shared value read after a barrier
    memoryBarrierBuffer();
    // (The counter is zeroed by the next frame's plan, not here: a counter left wrong, by a frame
    // that did not finish, cannot outlive one frame.)
    [[unroll]] for (uint r = 0u; r < kRows; ++r) {
      vec3 total = vec3(0.0);
      for (uint k = 0u; k < slices; ++k)
        total += k == slice ? sum[r] : partials[(slot0 + k) * slot_size + r * threads + t].rgb;
      sum[r] = total;
    }
  }
  [[unroll]] for (uint r = 0u; r < kRows; ++r) {
    uvec2 p = uvec2(p0.x, p0.y + r * gl_WorkGroupSize.y);
    if (sum[r] == vec3(0.0) || p.x >= uint(pc.viewport_w) || p.y >= uint(pc.viewport_h)) continue;
    vec4 c = imageLoad(color, ivec2(p));
    imageStore(color, ivec2(p), vec4(c.rgb + sum[r], c.a));
  }
}
