// The GPU layouts of the object occlusion cull that its API names (include/glint/object_cull.h,
// docs/OCCLUSION.md "Object culling"): the caller's object records, the per-object states, the
// indirect arguments and the statistics. Installed with the library: C++ includes
// <glint/gpu/object_cull.h>, GLSL "glint/gpu/object_cull.h"; the C++ side static_asserts the
// layouts (src/visibility/object_cull.cpp).
#ifndef GLINT_GPU_OBJECT_CULL_H
#define GLINT_GPU_OBJECT_CULL_H
#include "types.h"

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
