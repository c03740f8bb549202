// The steps of making a Context shared by Context::create (context.cpp) and Context::adopt
// (adopt.cpp). Internal to src/core.
#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <vector>

namespace glint::detail {

struct ContextState;

/// A Vulkan 1.3 instance; with `validation`, the Khronos validation layer with synchronization
/// validation (and GPU-assisted validation with `gpu_assisted`), its messages counted in `state`
/// through the messenger made into `messenger`. Throws Error(no_device) if the layer is missing.
VkInstance make_instance(bool validation, bool gpu_assisted, ContextState* state, VkDebugUtilsMessengerEXT* messenger);

/// The instance's physical devices, in enumeration order.
std::vector<VkPhysicalDevice> physical_devices(VkInstance instance);

/// ContextOptions::device: an index, else the first device whose name contains `wanted`
/// (case-insensitive), else (empty) the first discrete, integrated, virtual, CPU device in that
/// order. Throws Error(no_device) naming the devices when none matches.
VkPhysicalDevice choose_device(VkInstance instance, std::string wanted);

/// A queue family with graphics and compute, else one with compute. Throws Error(no_device).
uint32_t compute_queue_family(VkPhysicalDevice pd);

/// Fills what `s` reads from its physical device once (s.physical_device and s.queue_family set):
/// DeviceInfo, memory properties, the extensions glint uses and the format-feature table
/// (core/formats.h, format_features()).
void fill_info(ContextState& s);

/// Loads vkCmdPushDescriptorSetKHR from s.device, which has VK_KHR_push_descriptor enabled.
void load_push_descriptor(ContextState& s);

}  // namespace glint::detail
