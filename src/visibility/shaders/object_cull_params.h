// Internal layouts of the object occlusion cull (not installed): the push constants of its three
// dispatches: object_cull.comp (frustum + Hi-Z test: masks and counts per group of 64 objects),
// object_cull_scan.comp (each tile's slots, total and counts) and object_cull_scatter.comp
// (payloads into their slots in object order; the arguments and statistics). The previous test
// kernel, object_cull_v1.comp, runs with the same scan and scatter.
// Declared once for GLSL and C++; src/visibility/object_cull.cpp static_asserts the layouts.
#ifndef GLINT_OBJECT_CULL_PARAMS_H
#define GLINT_OBJECT_CULL_PARAMS_H
// The compaction's layouts (src/core/shaders): GLSL finds them by name, C++ by their path in src/.
#ifdef __cplusplus
#include "core/shaders/compact_params.h"
#else
#include "compact_params.h"
#endif
#include "glint/gpu/object_cull.h"

// Objects per group of object_cull.comp (a workgroup is several groups): one group's emitted
// objects are one 64-bit mask of the compaction's group buffer (compact_params.h).
#define GLINT_OBJECT_GROUP GLINT_COMPACT_GROUP
// Count 1 + f is byte f the test packs into its group record (compact_pack_counts), and word f of
// a tile's counts (object_cull_scan.comp); the scatter's shared totals use the same indices.
#define GLINT_OBJECT_COUNTER_FRUSTUM 1u
#define GLINT_OBJECT_COUNTER_OCCLUDED 2u
#define GLINT_OBJECT_COUNTER_VISIBLE 3u
#define GLINT_OBJECT_COUNTER_INVALID 4u

// GlintObjectCullPush::flags: the mode in the low two bits, then options.
#define GLINT_OBJECT_MODE_MASK 3u
#define GLINT_OBJECT_MODE_SINGLE 0u  // test all objects, emit the visible ones, write their state
#define GLINT_OBJECT_MODE_PHASE1 1u  // emit history-VISIBLE objects inside the frustum; no state write
#define GLINT_OBJECT_MODE_PHASE2 2u  // test all, emit visible ones whose history was not VISIBLE, write state
#define GLINT_OBJECT_REVERSED_Z 4u   // depth 1 is near; the pyramid holds the minimum

// Relative rounding margin of every fp32 quantity of the test (2^-18 = 64 units in the last place
// of fp32): each is moved by at least twice its worst fp32 error towards "visible"
// (docs/OCCLUSION.md, "Conservativeness").
#define GLINT_OBJECT_EPS (1.0 / 262144.0)
// Most Hi-Z texels one object reads; only reached when the pyramid is capped (HiZConfig::
// max_cell_px) below the level an object needs. A larger window counts as visible without reading.
#define GLINT_OBJECT_MAX_WINDOW 64

// Push constants of object_cull.comp (128 bytes: the most Vulkan guarantees). The camera in the form the test uses: view space
// with w = P32 * z_view (the clip w), and the projection's non-zero terms
// (ndc.x = proj_x * x / w + proj_ox, ndc.y = proj_y * y / w + proj_oy, depth = depth_a + depth_b / w).
struct GlintObjectCullPush {
  GLINT_FLOAT view_x[4];  // row 0 of the view matrix: x = dot(view_x, (p, 1))
  GLINT_FLOAT view_y[4];  // row 1
  GLINT_FLOAT view_w[4];  // P32 x row 2: w = dot(view_w, (p, 1)), > 0 in front of the camera
  GLINT_FLOAT proj_x;     // P00
  GLINT_FLOAT proj_ox;    // P02 x P32
  GLINT_FLOAT proj_y;     // P11
  GLINT_FLOAT proj_oy;    // P12 x P32
  GLINT_FLOAT depth_a;    // P22 x P32
  GLINT_FLOAT depth_b;    // P23
  GLINT_FLOAT near_w;     // w of the near plane (> 0)
  GLINT_FLOAT far_w;      // w of the far plane; FLT_MAX when the far plane is at infinity
  GLINT_FLOAT radius_scale;  // largest column norm of the view's 3x3, rounded up: view-space radius bound
  GLINT_INT width;           // depth image size in pixels
  GLINT_INT height;
  GLINT_UINT count;     // objects
  GLINT_UINT levels;    // Hi-Z levels built above level 0
  GLINT_UINT flags;     // GLINT_OBJECT_MODE_* | GLINT_OBJECT_REVERSED_Z
  GLINT_UINT groups_x;  // workgroups per row of the 2D dispatch (group = y * groups_x + x)
  GLINT_UINT tile_groups;  // groups per tile of the compaction's scan (object_cull.comp scans its tiles)
  // Lengths of the side planes' normals (proj_x, 1 + proj_ox), (-proj_x, 1 - proj_ox), then the
  // same of y, computed in double and rounded up (a per-frame constant the test would otherwise
  // take 2 square roots per plane evaluation for).
  GLINT_FLOAT plane_len[4];
};

// Push constants of the object cull's scan and scatter (32 bytes): GlintCompactPush with its step
// words named.
struct GlintObjectCompactPush {
  GLINT_UINT count;              // objects
  GLINT_UINT capacity;           // payload slots of the output list
  GLINT_UINT tile_groups;        // 64-object groups per tile of the two-level scan
  GLINT_UINT groups_x;           // scatter: workgroups per row of its 2D dispatch
  GLINT_UINT payload_words;      // 0: the list holds object indices (one uint); else words copied per object
  GLINT_UINT objects_per_group;  // scatter: dispatch group_count_x = ceil(written / this)
  GLINT_UINT reserved[2];
};

#endif
