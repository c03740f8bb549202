// GPU layouts of the object occlusion cull (include/glint/object_cull.h, docs/OCCLUSION.md "Object
// culling"): the caller's object records, the push constants of the three dispatches
// (object_cull.comp: frustum + Hi-Z test; object_cull_scan.comp: one-workgroup prefix sum of the
// per-workgroup visibility masks, indirect arguments and statistics; object_cull_scatter.comp:
// payloads into their slots in object order), the indirect arguments and the statistics.
// Declared once for GLSL and C++; host/object_cull.cpp static_asserts the layouts. Self-contained
// (only glint_types.h) so that it can move to include/glint/gpu/ unchanged.
#ifndef GLINT_OBJECT_CULL_H
#define GLINT_OBJECT_CULL_H
#include "glint_types.h"

// GlintCullObject::kind
#define GLINT_OBJECT_SPHERE 0u  // sphere_or_min = centre x, y, z, radius (>= 0); box_max unused
#define GLINT_OBJECT_BOX 1u     // sphere_or_min[0..2] = min x, y, z; box_max = max x, y, z; min <= max

// One object: a world-space bounding sphere or axis-aligned box, 32 bytes (two vec4).
struct GlintCullObject {
  GLINT_FLOAT sphere_or_min[4];
  GLINT_FLOAT box_max[3];
  GLINT_UINT kind;  // GLINT_OBJECT_SPHERE or GLINT_OBJECT_BOX
};

// Per-object state in the caller's visibility buffer (one uint per object). The buffer is the
// history of the two-phase cull: phase 1 emits the objects whose state is VISIBLE. Zero (NONE) is
// "never tested", read as not visible: a zero-filled buffer is the first frame's history.
#define GLINT_OBJECT_STATE_NONE 0u
#define GLINT_OBJECT_STATE_VISIBLE 1u
#define GLINT_OBJECT_STATE_OCCLUDED 2u
#define GLINT_OBJECT_STATE_FRUSTUM 3u

// Objects per workgroup of object_cull.comp: one workgroup's emitted objects are one 64-bit mask.
#define GLINT_OBJECT_GROUP 64u
// The internal group buffer: GLINT_OBJECT_HEADER_WORDS counter words (zero between dispatches: the
// scan resets them), then one uvec4 per workgroup: emitted mask of objects 0..31 (x), 32..63 (y),
// first slot (z, written by the scan), 0.
#define GLINT_OBJECT_COUNTER_FRUSTUM 1u
#define GLINT_OBJECT_COUNTER_OCCLUDED 2u
#define GLINT_OBJECT_COUNTER_VISIBLE 3u
#define GLINT_OBJECT_COUNTER_INVALID 4u
#define GLINT_OBJECT_HEADER_WORDS 8u
// Most invocations of the scan's single workgroup.
#define GLINT_OBJECT_SCAN_MAX_THREADS 1024u

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

// Push constants of object_cull.comp (112 bytes). The camera in the form the test uses: view space
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
  GLINT_UINT reserved;
};

// Push constants of object_cull_scan.comp and object_cull_scatter.comp (32 bytes).
struct GlintObjectCompactPush {
  GLINT_UINT count;              // objects
  GLINT_UINT capacity;           // payload slots of the output list
  GLINT_UINT payload_words;      // 0: the list holds object indices (one uint); else words copied per object
  GLINT_UINT objects_per_group;  // scan: dispatch group_count_x = ceil(written / this)
  GLINT_UINT groups_x;           // scatter: workgroups per row of its 2D dispatch
  GLINT_UINT reserved[3];
};

// The indirect arguments one cull writes (16 bytes): the draw count for vkCmdDraw*IndirectCount at
// offset 0, a VkDispatchIndirectCommand at offset 4.
struct GlintObjectCullIndirect {
  GLINT_UINT draw_count;     // payloads written (min(emitted, capacity))
  GLINT_UINT group_count_x;  // ceil(draw_count / objects_per_group)
  GLINT_UINT group_count_y;  // 1
  GLINT_UINT group_count_z;  // 1
};

// Statistics of one cull (32 bytes). Single phase and phase 2: the states of all objects. Phase 1:
// only objects whose history is VISIBLE are tested (frustum only): frustum_culled counts those
// outside, visible those inside, occluded is 0.
struct GlintObjectCullStats {
  GLINT_UINT total;           // objects
  GLINT_UINT frustum_culled;  // state FRUSTUM
  GLINT_UINT occluded;        // state OCCLUDED
  GLINT_UINT visible;         // state VISIBLE (invalid objects included)
  GLINT_UINT emitted;         // objects this cull put in its list (phase 2: visible, history not VISIBLE)
  GLINT_UINT written;         // min(emitted, capacity)
  GLINT_UINT overflow;        // emitted - written: the emitted objects with the largest indices
  GLINT_UINT invalid;         // objects with a non-finite field, a negative radius, min > max or an
                              // unknown kind: counted visible (conservative)
};

#endif
