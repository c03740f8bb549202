// Compile-time checks that GlintFlareIndirect (include/glint/gpu/flare_types.h, which checks its own
// std430 layout) puts the indirect arguments where Vulkan reads them.
#include <glint/gpu/flare_types.h>
#include <vulkan/vulkan.h>

#include <cstddef>

static_assert(offsetof(GlintFlareIndirect, vertex_count) == offsetof(VkDrawIndirectCommand, vertexCount));
static_assert(offsetof(GlintFlareIndirect, instance_count) == offsetof(VkDrawIndirectCommand, instanceCount));
static_assert(offsetof(GlintFlareIndirect, first_instance) == offsetof(VkDrawIndirectCommand, firstInstance));
static_assert(sizeof(VkDrawIndirectCommand) == 16 && sizeof(VkDispatchIndirectCommand) == 12);
static_assert(offsetof(GlintFlareIndirect, group_count_x) == 16 + offsetof(VkDispatchIndirectCommand, x));
static_assert(offsetof(GlintFlareIndirect, group_count_z) == 16 + offsetof(VkDispatchIndirectCommand, z));
