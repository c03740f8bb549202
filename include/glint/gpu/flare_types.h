// The buffers that connect the lens-flare stages, declared once for GLSL and C++: the caller's
// light list, the instance buffer that the cull/occlusion/compaction kernel appends visible lights
// to, the indirect arguments it writes, its statistics, and one result per input light. The
// raster draw (vkCmdDrawIndirect) and the compute gather (which reads group_count_x) both read
// GlintFlareInstance and GlintFlareIndirect and nothing else from the visibility stage, so the two
// halves meet only here.
// Installed with the library: C++ includes <glint/gpu/flare_types.h>, GLSL "glint/gpu/flare_types.h"
// and declares buffers as `layout(std430) buffer X { GlintFlareInstance instances[]; };`.
// Only 4-byte scalars, so std430 and C++ layouts agree; the C++ side static_asserts them below.
#ifndef GLINT_GPU_FLARE_TYPES_H
#define GLINT_GPU_FLARE_TYPES_H
#include "types.h"

// Flare elements: the tiles of the element atlas, and GlintFlareLight::element.
#define GLINT_FLARE_ELEMENT_GLOW 0u
#define GLINT_FLARE_ELEMENT_STREAK 1u
#define GLINT_FLARE_ELEMENT_HALO 2u
#define GLINT_FLARE_ELEMENT_STARBURST 3u
#define GLINT_FLARE_ELEMENT_GHOST 4u
#define GLINT_FLARE_ELEMENT_COUNT 5u

// GlintFlareLightResult::culled
#define GLINT_FLARE_VISIBLE 0u    // drawn (visible_fraction > 0)
#define GLINT_FLARE_FRUSTUM 1u    // w <= 0 (behind the camera) or outside the frustum + margin
#define GLINT_FLARE_OCCLUDED 2u   // every grid sample occluded (visible_fraction == 0)
#define GLINT_FLARE_DISABLED 3u   // enabled == 0 or a non-finite float field; counted in total, in no
                                  // other statistic
#define GLINT_FLARE_OVERFLOW 4u   // visible, but the instance buffer was full

// One light, as the caller writes it (48 bytes).
struct GlintFlareLight {
  GLINT_FLOAT position_x;  // world position; clip = view_proj * (position, 1)
  GLINT_FLOAT position_y;
  GLINT_FLOAT position_z;
  GLINT_FLOAT intensity;   // >= 0, scales the whole flare
  GLINT_FLOAT color_r;     // linear RGB, >= 0
  GLINT_FLOAT color_g;
  GLINT_FLOAT color_b;
  GLINT_FLOAT size_px;     // flare size in pixels (the occlusion footprint is a size_px square)
  GLINT_UINT element;      // GLINT_FLARE_ELEMENT_*: the light's main element
  GLINT_UINT enabled;      // 0: skipped (as is a light with a non-finite float field)
  GLINT_UINT reserved0;
  GLINT_UINT reserved1;
};

// One visible light, as the compaction writes it for the draw (48 bytes). Instances are in
// increasing light_index (the compaction preserves order), so the additive draw sums in
// the same order, and gives the same bits, on every run.
struct GlintFlareInstance {
  GLINT_FLOAT center_x_px;       // the light's pixel position, (ndc.xy * 0.5 + 0.5) * viewport
  GLINT_FLOAT center_y_px;
  GLINT_FLOAT size_px;           // from the light
  GLINT_FLOAT visible_fraction;  // (0, 1]: fraction of grid samples not occluded
  GLINT_FLOAT color_r;           // from the light (not yet multiplied by intensity or fraction)
  GLINT_FLOAT color_g;
  GLINT_FLOAT color_b;
  GLINT_FLOAT intensity;         // from the light
  GLINT_UINT light_index;        // index into the light buffer
  GLINT_UINT element;            // from the light
  GLINT_FLOAT ndc_depth;         // the light's NDC z in [0, 1]
  GLINT_UINT reserved;
};

// Indirect arguments, 32 bytes: a VkDrawIndirectCommand at offset 0 and a
// VkDispatchIndirectCommand at offset 16. The compaction writes instance_count = visible
// (clamped to the capacity), vertex_count as the draw side gave it, and G = instance_count *
// groups_per_instance workgroups as rows of at most maxComputeWorkGroupCount[0]:
// group_count_x = min(G, maxComputeWorkGroupCount[0]), group_count_y = ceil(G / group_count_x)
// (1 when G = 0). A kernel dispatched with them takes the linear workgroup index
// gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x and returns when it is G or more,
// G being read from instance_count; so a million instances launch on every conformant device.
struct GlintFlareIndirect {
  GLINT_UINT vertex_count;
  GLINT_UINT instance_count;
  GLINT_UINT first_vertex;
  GLINT_UINT first_instance;
  GLINT_UINT group_count_x;
  GLINT_UINT group_count_y;
  GLINT_UINT group_count_z;
  GLINT_UINT reserved;
};

// Statistics of one cull (32 bytes), left in a GPU buffer for the caller to read when it wants.
struct GlintFlareStats {
  GLINT_UINT total;           // lights in the list
  GLINT_UINT frustum_culled;  // GLINT_FLARE_FRUSTUM
  GLINT_UINT occluded;        // GLINT_FLARE_OCCLUDED
  GLINT_UINT visible;         // visible lights, including those that overflowed
  GLINT_UINT overflow;        // visible lights not written because the instance buffer was full
  GLINT_UINT disabled;        // GLINT_FLARE_DISABLED
  GLINT_UINT reserved0;
  GLINT_UINT reserved1;
};

// One result per input light, in input order (8 bytes).
struct GlintFlareLightResult {
  GLINT_FLOAT visible_fraction;  // [0, 1]; 0 when culled for any reason
  GLINT_UINT culled;             // GLINT_FLARE_VISIBLE / _FRUSTUM / _OCCLUDED / _DISABLED / _OVERFLOW
};

#ifdef __cplusplus
// The std430 layout of each struct (every member a 4-byte scalar: offset = 4 x member index).
static_assert(sizeof(GlintFlareLight) == 48, "GlintFlareLight is 48 bytes");
static_assert(offsetof(GlintFlareLight, intensity) == 12 && offsetof(GlintFlareLight, size_px) == 28 &&
                  offsetof(GlintFlareLight, element) == 32 && offsetof(GlintFlareLight, enabled) == 36,
              "GlintFlareLight std430 offsets");
static_assert(sizeof(GlintFlareInstance) == 48, "GlintFlareInstance is 48 bytes");
static_assert(offsetof(GlintFlareInstance, visible_fraction) == 12 && offsetof(GlintFlareInstance, intensity) == 28 &&
                  offsetof(GlintFlareInstance, light_index) == 32 && offsetof(GlintFlareInstance, ndc_depth) == 40,
              "GlintFlareInstance std430 offsets");
static_assert(sizeof(GlintFlareIndirect) == 32, "GlintFlareIndirect is 32 bytes");
static_assert(offsetof(GlintFlareIndirect, instance_count) == 4 && offsetof(GlintFlareIndirect, group_count_x) == 16,
              "GlintFlareIndirect: VkDrawIndirectCommand at 0, VkDispatchIndirectCommand at 16");
static_assert(sizeof(GlintFlareStats) == 32, "GlintFlareStats is 32 bytes");
static_assert(offsetof(GlintFlareStats, visible) == 12 && offsetof(GlintFlareStats, disabled) == 20,
              "GlintFlareStats std430 offsets");
static_assert(sizeof(GlintFlareLightResult) == 8 && offsetof(GlintFlareLightResult, culled) == 4,
              "GlintFlareLightResult std430 layout");
#endif

#endif
