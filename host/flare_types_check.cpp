// Compile-time checks that kernels/common/flare_types.h lays out the same in C++ as in GLSL
// std430 (STYLE rule 2), and that the indirect arguments sit where Vulkan reads them.
#include <cstddef>

#include <vulkan/vulkan.h>

#include "flare_types.h"

static_assert(sizeof(GlintFlareLight) == 48);
static_assert(offsetof(GlintFlareLight, intensity) == 12);
static_assert(offsetof(GlintFlareLight, size_px) == 28);
static_assert(offsetof(GlintFlareLight, element) == 32);
static_assert(sizeof(GlintFlareInstance) == 48);
static_assert(offsetof(GlintFlareInstance, visible_fraction) == 12);
static_assert(offsetof(GlintFlareInstance, light_index) == 32);
static_assert(sizeof(GlintFlareIndirect) == 32);
static_assert(offsetof(GlintFlareIndirect, vertex_count) == 0 && sizeof(VkDrawIndirectCommand) == 16);
static_assert(offsetof(GlintFlareIndirect, instance_count) == offsetof(VkDrawIndirectCommand, instanceCount));
static_assert(offsetof(GlintFlareIndirect, group_count_x) == 16 && sizeof(VkDispatchIndirectCommand) == 12);
static_assert(sizeof(GlintFlareStats) == 32);
static_assert(sizeof(GlintFlareLightResult) == 8);
