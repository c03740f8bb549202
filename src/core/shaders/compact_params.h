// The ordered compaction shared by the object cull and the light cull (docs/OCCLUSION.md,
// "The shared compaction core"): a test kernel sets one bit per emitted item in its workgroup's 64-bit
// mask; a two-level scan (compact_scan_tiles.comp per tile of groups, then a cull's top-level scan
// built on compact.glsl; the object cull scans its tiles itself and its scatter adds the earlier
// tiles' totals) turns the masks into slots; a scatter writes each emitted item's record
// into its slot, so the output holds the emitted items in increasing index on every run. Declared
// once for GLSL and C++; src/core/compaction.cpp static_asserts the layouts.
#ifndef GLINT_COMPACT_PARAMS_H
#define GLINT_COMPACT_PARAMS_H
#include "glint/gpu/types.h"

// Items per group: one group's emitted items are one 64-bit mask (two 32-bit words).
#define GLINT_COMPACT_GROUP 64u
// The group buffer: GLINT_COMPACT_HEADER_WORDS counter words (the users' statistics; zero between
// runs: the top-level scan resets them), then one uvec4 per group: emitted mask of items 0..31
// (x) and 32..63 (y), written by the test; emitted items of the tile before the group (z), written
// by compact_scan_tiles.comp; on a tile's first group the tile's total, then the tile's first slot
// (w), written by the two scans.
#define GLINT_COMPACT_HEADER_WORDS 8u
// Most invocations of a scan workgroup (its shared arrays are sized for it); a tile is that many
// groups.
#define GLINT_COMPACT_SCAN_MAX_THREADS 1024u
// 64-item groups per workgroup of the object cull's scatter (object_cull_scatter.comp; 16 x 64 =
// 1024 items, 4 KiB of shared list).
#define GLINT_COMPACT_SCATTER_GROUPS 16u

// Push constants of every compaction dispatch (32 bytes). The first four words are the
// compaction's; `step` holds the words of the user's top-level scan and scatter (each user's
// params header declares a struct of the same layout that names them).
struct GlintCompactPush {
  GLINT_UINT count;        // items
  GLINT_UINT capacity;     // slots of the output
  GLINT_UINT tile_groups;  // groups per tile of the two-level scan (the scan workgroup's size)
  GLINT_UINT groups_x;     // scatter: workgroups per row of its 2D dispatch
  GLINT_UINT step[4];
};

#endif
