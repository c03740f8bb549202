// What a context reads from its physical device once, standalone or adopted: the DeviceInfo
// limits, the extensions glint uses, the format features of every format glint accepts, and the
// push-descriptor command.
#include <cstring>

#include "core/check.h"
#include "core/context_state.h"
#include "core/device_setup.h"
#include "core/formats.h"

namespace glint::detail {

void fill_info(ContextState& s) {
  VkPhysicalDevicePushDescriptorPropertiesKHR push{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
  p13.pNext = &push;  // filled only if the device has the extension (checked below)
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  subgroup.pNext = &p13;
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(s.physical_device, &props);
  const auto& p = props.properties;
  s.info.name = p.deviceName;
  s.info.type = p.deviceType;
  s.info.subgroup_size = subgroup.subgroupSize;
  s.min_subgroup_size = p13.minSubgroupSize != 0 ? p13.minSubgroupSize : subgroup.subgroupSize;
  s.max_subgroup_size = p13.maxSubgroupSize != 0 ? p13.maxSubgroupSize : subgroup.subgroupSize;
  s.compute_subgroup_operations =
      (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 ? subgroup.supportedOperations : 0;
  s.info.max_shared_memory_bytes = p.limits.maxComputeSharedMemorySize;
  s.info.sub_texel_precision_bits = p.limits.subTexelPrecisionBits;
  s.info.max_workgroup_invocations = p.limits.maxComputeWorkGroupInvocations;
  s.info.max_image_dimension_2d = p.limits.maxImageDimension2D;
  s.info.timestamp_period_ns = p.limits.timestampPeriod;
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(s.physical_device, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(s.physical_device, &n, families.data());
  s.info.timestamps_supported = s.queue_family < n && families[s.queue_family].timestampValidBits > 0;
  s.graphics_queue = s.queue_family < n && (families[s.queue_family].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0;
  vkGetPhysicalDeviceMemoryProperties(s.physical_device, &s.memory);
  uint32_t extension_count = 0;
  vkEnumerateDeviceExtensionProperties(s.physical_device, nullptr, &extension_count, nullptr);
  std::vector<VkExtensionProperties> extensions(extension_count);
  vkEnumerateDeviceExtensionProperties(s.physical_device, nullptr, &extension_count, extensions.data());
  for (const VkExtensionProperties& e : extensions) {
    if (std::strcmp(e.extensionName, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) == 0) s.memory_budget = true;
    if (std::strcmp(e.extensionName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0) s.push_descriptor_supported = true;
    if (std::strcmp(e.extensionName, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME) == 0)
      s.executable_properties_supported = true;
  }
  s.max_push_descriptors = s.push_descriptor_supported ? push.maxPushDescriptors : 0;
  s.format_features = fill_format_features(s.physical_device);
}

// Loads vkCmdPushDescriptorSetKHR from the device, which has VK_KHR_push_descriptor enabled.
void load_push_descriptor(ContextState& s) {
  s.cmd_push_descriptor_set =
      reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(vkGetDeviceProcAddr(s.device, "vkCmdPushDescriptorSetKHR"));
  if (!s.cmd_push_descriptor_set) {
    throw Error(ErrorCode::no_device, concat("device '", s.info.name,
                                             "' gives no vkCmdPushDescriptorSetKHR although VK_KHR_push_descriptor "
                                             "is enabled"));
  }
}

}  // namespace glint::detail
