// The drawing half of the lens flares, declared once for GLSL and C++ (CONTRIBUTING.md, "Shared
// structs"): the element atlas layout, the sprites every light expands to, and the push constants
// shared by flare.vert, flare.frag and flare_gather.comp. docs/FLARE.md explains
// every number here. The visibility half meets the drawing half only in flare_types.h.
#ifndef GLINT_FLARE_PARAMS_H
#define GLINT_FLARE_PARAMS_H
#include "glint/gpu/types.h"

// ---- Element atlas ------------------------------------------------------------------------------
// One RGBA16F image, premultiplied alpha, every tile surrounded by GLINT_FLARE_ATLAS_PADDING texels
// of zeros (its own edge value: every element fades to 0 at the tile border). Tile offsets and
// sizes are multiples of 2^(levels - 1) = 16, so at every mip level a texel belongs to exactly one
// tile or to padding: the 2x2 box mips never mix two tiles. The level count is the padding cap of
// include/glint/gpu/lod_impl.h plus one (floor(log2(32)) - 1 = 4, so levels 0..4): no level is built
// that the atlas-aware LOD would refuse to use.
#define GLINT_FLARE_ATLAS_WIDTH 832u
#define GLINT_FLARE_ATLAS_HEIGHT 320u
#define GLINT_FLARE_ATLAS_PADDING 32u
#define GLINT_FLARE_ATLAS_LEVELS 5u

// Tiles (level-0 texels): x, y, width, height, indexed by GLINT_FLARE_ELEMENT_* (flare_types.h).
#define GLINT_FLARE_TILE_GLOW_X 672u
#define GLINT_FLARE_TILE_GLOW_Y 32u
#define GLINT_FLARE_TILE_GLOW_W 128u
#define GLINT_FLARE_TILE_GLOW_H 128u
#define GLINT_FLARE_TILE_STREAK_X 352u
#define GLINT_FLARE_TILE_STREAK_Y 32u
#define GLINT_FLARE_TILE_STREAK_W 256u
#define GLINT_FLARE_TILE_STREAK_H 64u
#define GLINT_FLARE_TILE_HALO_X 480u
#define GLINT_FLARE_TILE_HALO_Y 160u
#define GLINT_FLARE_TILE_HALO_W 128u
#define GLINT_FLARE_TILE_HALO_H 128u
#define GLINT_FLARE_TILE_STARBURST_X 32u
#define GLINT_FLARE_TILE_STARBURST_Y 32u
#define GLINT_FLARE_TILE_STARBURST_W 256u
#define GLINT_FLARE_TILE_STARBURST_H 256u
#define GLINT_FLARE_TILE_GHOST_X 352u
#define GLINT_FLARE_TILE_GHOST_Y 160u
#define GLINT_FLARE_TILE_GHOST_W 64u
#define GLINT_FLARE_TILE_GHOST_H 64u

// ---- Sprites of one light -----------------------------------------------------------------------
// Every instance expands to GLINT_FLARE_SPRITES screen-aligned rectangles (slots), each drawn as
// two triangles. Sizes are in units of the light's size_px; every width is further multiplied by
// the anamorphic ratio (an anamorphic lens stretches every out-of-focus artefact horizontally).
#define GLINT_FLARE_SPRITES 9u
#define GLINT_FLARE_VERTICES_PER_SPRITE 6u
#define GLINT_FLARE_SLOT_MAIN 0u    // the light's own element (GlintFlareInstance::element)
#define GLINT_FLARE_SLOT_STREAK 1u  // horizontal streak, streak_length wide
#define GLINT_FLARE_SLOT_HALO 2u
#define GLINT_FLARE_SLOT_STARBURST 3u
#define GLINT_FLARE_SLOT_GHOST0 4u  // ghosts 0..4 at the config's ghost positions

#define GLINT_FLARE_MAIN_SCALE 1.0
#define GLINT_FLARE_STREAK_HEIGHT 0.5  // the streak's height; its width is streak_length
#define GLINT_FLARE_HALO_SCALE 1.6
#define GLINT_FLARE_STARBURST_SCALE 2.0
#define GLINT_FLARE_GHOST_SCALE_0 0.5
#define GLINT_FLARE_GHOST_SCALE_1 0.35
#define GLINT_FLARE_GHOST_SCALE_2 0.6
#define GLINT_FLARE_GHOST_SCALE_3 0.3
#define GLINT_FLARE_GHOST_SCALE_4 0.8
// Relative brightness of ghosts 0..4 (times ghost_weight).
#define GLINT_FLARE_GHOST_GAIN_0 0.6
#define GLINT_FLARE_GHOST_GAIN_1 0.4
#define GLINT_FLARE_GHOST_GAIN_2 0.5
#define GLINT_FLARE_GHOST_GAIN_3 0.3
#define GLINT_FLARE_GHOST_GAIN_4 0.45

// ---- Compute path (flare_gather.comp) ------------------------------------------------------------
// One workgroup per screen tile; each invocation shades `rows` pixels of one column (rows a
// workgroup height apart; specialization constant 4), so a 32x8 workgroup with 8 rows gathers a
// 32x64 tile (1020 tiles at 1080p). Larger tiles bin each instance against fewer tiles; the rows
// share one binning and one sprite setup per tile. The one-dispatch gather (few instances), CPU
// devices and the split gather take GLINT_FLARE_GATHER_ROWS; the pre-pass gather without the
// split on GPUs GLINT_FLARE_GATHER_PRE_PASS_ROWS, so that the sprites piled on one spot (every
// light's ghost at t = 1 lands on the image centre) are shaded by four times as many workgroups
// (docs/FLARE.md, "Speed").
// Shared lists and the binning scan are sized for at most GLINT_FLARE_GATHER_MAX_THREADS
// invocations (20 KiB).
#define GLINT_FLARE_GATHER_ROWS 8u
#define GLINT_FLARE_GATHER_PRE_PASS_ROWS 2u
#define GLINT_FLARE_GATHER_MAX_THREADS 256u
// The one-dispatch gather's workgroup on GPUs, as the pre-pass gathers': 32x8 (32x64 tiles). On
// the H200 16x16 drew BM_FlareDraw's 10 lights in 34.1 us against 34.7, but 16 mixed lights in
// 30.3 against 27.7 and the 10-light frame in 33.9 against 33.7 (docs/FLARE.md, "Speed").
#define GLINT_FLARE_ONE_DISPATCH_GROUP_X 32u
#define GLINT_FLARE_ONE_DISPATCH_GROUP_Y 8u

// Crowded tiles (the pre-pass gather on GPUs for instances buffers of at least
// GLINT_FLARE_SPLIT_FROM_INSTANCES instances, in tiles of GLINT_FLARE_GATHER_ROWS rows; smaller
// buffers take GLINT_FLARE_GATHER_PRE_PASS_ROWS rows and no split, which measured faster for up to
// 256 lights: docs/FLARE.md, "Speed"): every light's ghost at t = 1 lands on the image
// centre, so with many lights a few tiles list a thousand sprites. The sprite pre-pass counts the
// sprites whose conservative rectangle meets each tile; flare_split_plan.comp gives a tile that
// counts at least GLINT_FLARE_SPLIT_MIN_SPRITES min(count / GLINT_FLARE_SPLIT_SPRITES,
// GLINT_FLARE_SPLIT_MAX_SLICES) slices, each a contiguous range of the instances drawn by its own
// workgroup, whose sums go to a slot of partial sums; the last of a tile's workgroups to finish
// adds the slots in slice order. A frame whose split tiles would need more than
// GLINT_FLARE_SPLIT_SLOTS slots keeps 1 / scale of every tile's slices, scale = ceil(slots needed /
// GLINT_FLARE_SPLIT_SLOTS), within the slots.
#define GLINT_FLARE_SPLIT_FROM_INSTANCES 512u
#define GLINT_FLARE_SPLIT_MIN_SPRITES 256u
#define GLINT_FLARE_SPLIT_SPRITES 64u
#define GLINT_FLARE_SPLIT_MAX_SLICES 16u
#define GLINT_FLARE_SPLIT_SLOTS 256u
#define GLINT_FLARE_SPLIT_PLAN_THREADS 256u
// The split words (a buffer the LensFlare owns), for T tiles: [0, T) the pre-pass's counts (the
// plan zeroes them), [T, 2T) each tile's plan (slices | first slot << 5; slices 1: not split),
// [2T, 3T) each split tile's finished slices (the plan zeroes them before the gather counts),
// [3T, 3T + SLOTS) the slots' (tile << 5 | slice), [3T + SLOTS] the slots used.
#define GLINT_FLARE_SPLIT_WORDS(tiles) (3u * (tiles) + GLINT_FLARE_SPLIT_SLOTS + 1u)

// The sprite pre-pass (flare_sprites.comp) evaluates every sprite once per frame into a buffer the
// LensFlare owns, one block of GLINT_FLARE_BLOCK_VEC4S vec4 per instance:
//   [0]                 the union of the sprites' conservative rectangles (x0, y0, x1, y1; empty
//                       when x0 > x1), so a tile tests one rectangle per instance;
//   [1 + 2 slot]        lo.xy, size.xy of the sprite in `slot` (size 0: nothing to draw);
//   [2 + 2 slot]        rgb, lod.
// The atlas tile is not stored: it follows from the slot and the instance's element
// (glint_flare_slot_tile). One workgroup takes GLINT_FLARE_SPRITES_INSTANCES instances, one
// invocation per (instance, slot).
#define GLINT_FLARE_BLOCK_VEC4S (1u + 2u * GLINT_FLARE_SPRITES)
#define GLINT_FLARE_SPRITES_SLOTS 16u  // the pre-pass workgroup's x: slots, GLINT_FLARE_SPRITES of them used
#define GLINT_FLARE_SPRITES_INSTANCES 4u

// Push constants of every flare kernel (88 bytes; the per-frame settings of FlareConfig, already
// combined on the host: tint is (1, 1, 1) when the tint is off).
struct GlintFlarePush {
  GLINT_FLOAT viewport_w;  // the colour image's size in pixels
  GLINT_FLOAT viewport_h;
  GLINT_FLOAT anamorphic_ratio;
  GLINT_FLOAT intensity;  // global intensity
  GLINT_FLOAT weight_main;
  GLINT_FLOAT weight_streak;
  GLINT_FLOAT weight_halo;
  GLINT_FLOAT weight_starburst;
  GLINT_FLOAT weight_ghost;
  GLINT_FLOAT streak_length;
  GLINT_FLOAT tint_r;  // multiplies the streak and the ghosts (lens-coating colour)
  GLINT_FLOAT tint_g;
  GLINT_FLOAT tint_b;
  GLINT_FLOAT ghost_pos0;  // along light -> screen centre: 0 at the light, 1 at the centre
  GLINT_FLOAT ghost_pos1;
  GLINT_FLOAT ghost_pos2;
  GLINT_FLOAT ghost_pos3;
  GLINT_FLOAT ghost_pos4;
  GLINT_UINT tile_w;         // compute: the gather's tile in pixels (workgroup x)
  GLINT_UINT tile_h;         // (workgroup y * the gather's rows, its specialization constant 4)
  GLINT_UINT indirect_word;  // compute: index of instance_count in the bound indirect words
};

// Push constants of flare_gather_args.comp (20 bytes). It writes two VkDispatchIndirectCommand:
// the gather's at word 0 and the sprite pre-pass's at word 4.
struct GlintFlareGatherArgsPush {
  GLINT_UINT indirect_word;  // index of instance_count in the bound indirect words
  GLINT_UINT tiles_x;        // the gather's grid when any instance is visible
  GLINT_UINT tiles_y;
  GLINT_UINT capacity;       // instances the bound instance and sprite buffers hold
  GLINT_UINT max_groups_x;   // maxComputeWorkGroupCount[0]: the pre-pass's groups go in rows of it
};

// Push constants of flare_split_plan.comp (32 bytes). It rewrites the gather's
// VkDispatchIndirectCommand (words 0..2 of the arguments) with the split tiles' extra workgroups:
// rows of tiles_x workgroups before the tiles' rows.
struct GlintFlareSplitPush {
  GLINT_UINT indirect_word;      // index of instance_count in the bound indirect words
  GLINT_UINT tiles_x;            // the gather's tiles
  GLINT_UINT tiles_y;
  GLINT_UINT capacity;           // instances the bound instance and sprite buffers hold
  GLINT_UINT min_sprites;        // GLINT_FLARE_SPLIT_MIN_SPRITES (smaller in tests)
  GLINT_UINT sprites_per_slice;  // GLINT_FLARE_SPLIT_SPRITES
  GLINT_UINT max_slices;         // GLINT_FLARE_SPLIT_MAX_SLICES (at most 31)
  GLINT_UINT pad;
};

// Push constants of flare_atlas.comp (12 bytes).
struct GlintFlareAtlasPush {
  GLINT_UINT level;  // 0: evaluate the elements; k > 0: 2x2 box of level k - 1
  GLINT_UINT width;  // size of the level written
  GLINT_UINT height;
};

#endif
