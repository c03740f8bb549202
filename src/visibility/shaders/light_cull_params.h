// Push constants and buffer layouts of the visibility stage of the lens flares: the Hi-Z build
// (hiz_stream.comp, hiz_build.comp), the cull + occlusion grid test (light_cull.comp; for few
// lights its one-workgroup variant compacts them itself, and its depth-image variant reads the
// samples' windows without a pyramid), and the ordered compaction
// shared with the object cull (compact_params.h; the same order on every run): a two-level scan of
// the cull's per-workgroup visibility masks (compact_scan_tiles.comp per tile, light_cull_scan.comp
// over the tile totals, which also writes the indirect arguments and statistics), then the scatter
// of the visible lights into the instance buffer in light-index order (light_cull_scatter.comp).
// Declared once for GLSL and C++ (CONTRIBUTING.md, "Shared structs"); src/visibility/hiz_pyramid.cpp and
// light_culler.cpp static_assert the layouts. docs/OCCLUSION.md explains the algorithms. The
// public C++ API of the same stage is include/glint/occlusion.h.
#ifndef GLINT_LIGHT_CULL_PARAMS_H
#define GLINT_LIGHT_CULL_PARAMS_H
// The compaction's layouts (src/core/shaders): GLSL finds them by name, C++ by their path in src/.
#ifdef __cplusplus
#include "core/shaders/compact_params.h"
#else
#include "compact_params.h"
#endif
#include "glint/gpu/types.h"

// Hi-Z levels: level 0 is the depth image itself, level k (k >= 1) is max(1, size >> k) on a side
// and is stored in mip k - 1 of the pyramid image. 16384 needs 14 levels.
#define GLINT_HIZ_MAX_LEVELS 14u
// On GPUs the stream pass (hiz_stream.comp) writes levels 1 to 6 from the depth image, a 64x64
// block of depth texels per workgroup (CPU devices: hiz_stream_texels.comp, levels 1 and 2). The
// tile pass (hiz_build.comp) reduces 64x64 tiles of the stream pass's last level through 6 levels;
// its last workgroup reduces up to 6 more.
#define GLINT_HIZ_STREAM_LEVELS 6u
#define GLINT_HIZ_TILE 64
#define GLINT_HIZ_TILE_LEVELS 6u

struct GlintHiZPush {
  GLINT_INT base_width;  // size of the base level this dispatch reads
  GLINT_INT base_height;
  GLINT_UINT tile_levels;    // levels every workgroup builds from its tile or block (1 to 6)
  GLINT_UINT tail_levels;    // levels the last workgroup then builds (0 to 6)
  GLINT_UINT reversed_z;     // 0: farthest = max (standard Z); 1: farthest = min (reversed Z)
  GLINT_UINT counter_index;  // which word of the counter buffer counts finished workgroups
  GLINT_UINT reserved0;      // (the tile pass's base level is its specialization constant 2)
  GLINT_UINT reserved1;
};

// Lights per workgroup of light_cull.comp: one workgroup's visibility is one 64-bit mask of the
// compaction's group buffer (compact_params.h), whose header words count the states. Counters are
// integer sums, so the order of their atomics does not matter; no atomic decides where an instance
// goes.
#define GLINT_CULL_GROUP GLINT_COMPACT_GROUP
// Counter 1 + f is count f the cull packs into its group record (compact_pack_counts).
#define GLINT_CULL_COUNTER_FRUSTUM 1u
#define GLINT_CULL_COUNTER_OCCLUDED 2u
#define GLINT_CULL_COUNTER_DISABLED 3u

// GlintCullPush::flags
#define GLINT_CULL_REVERSED_Z 1u     // depth 1 is near; farthest = min
#define GLINT_CULL_WRITE_RESULTS 2u  // write one GlintFlareLightResult per light
#define GLINT_CULL_REGULAR_GRID 4u   // samples read their whole cell (no multi-jitter; for comparison)

// Light sizes are clamped to this (pixels) so that footprint arithmetic stays exact in fp32.
#define GLINT_CULL_MAX_SIZE_PX 65536.0
// A grid cell whose window at the chosen level exceeds this many texels (only when the pyramid is
// shallower than the cell needs) is counted visible without reading: conservative and bounded.
#define GLINT_CULL_MAX_WINDOW_TEXELS 16

struct GlintCullPush {
  GLINT_FLOAT view_proj[16];  // column-major: clip = view_proj * (position, 1)
  GLINT_INT width;            // viewport = depth image size in pixels
  GLINT_INT height;
  GLINT_UINT count;        // lights in the list
  GLINT_UINT capacity;     // instances the buffer holds (the one-workgroup cull; 0 otherwise)
  GLINT_UINT grid;         // N: N x N cells per footprint (1 to 16)
  GLINT_UINT levels;       // Hi-Z levels built above level 0 (0 to 14)
  GLINT_UINT flags;        // GLINT_CULL_*
  GLINT_FLOAT margin_ndc;  // frustum margin: |ndc.xy| <= margin_ndc passes
  GLINT_FLOAT depth_bias;  // visible where stored depth is not nearer than light depth - bias
  // The indirect arguments' words, for the one-workgroup cull (light_cull_scan.comp's otherwise):
  GLINT_UINT vertex_count;         // LightCullFrame::vertex_count
  GLINT_UINT groups_per_instance;  // LightCullFrame::groups_per_instance
  GLINT_UINT max_group_count_x;    // maxComputeWorkGroupCount[0]
};

// Push constants of the light cull's compaction (light_cull_scan.comp, light_cull_scatter.comp):
// GlintCompactPush with its step words named.
struct GlintCullCompactPush {
  GLINT_UINT count;                // lights in the list
  GLINT_UINT capacity;             // GlintFlareInstance slots in the instance buffer
  GLINT_UINT tile_groups;          // 64-light groups per tile of the two-level scan
  GLINT_UINT groups_x;             // scatter: workgroups per row of its 2D dispatch
  GLINT_UINT vertex_count;         // scan: GlintFlareIndirect::vertex_count
  GLINT_UINT groups_per_instance;  // scan: the dispatch arguments cover instances x this groups
  GLINT_UINT flags;                // scatter: GLINT_CULL_WRITE_RESULTS
  GLINT_UINT max_group_count_x;    // scan: the device's maxComputeWorkGroupCount[0]
};

#endif
