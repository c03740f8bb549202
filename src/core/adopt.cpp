// Context::adopt: the checks that an engine's instance and device have what glint needs, and the
// context made on them.
#include <cstring>

#include "core/check.h"
#include "core/context_state.h"
#include "core/device_setup.h"

namespace glint {
namespace detail {
namespace {

// The device features glint relies on, as an adopted device has them enabled. From the engine's
// vkCreateDevice feature chain when it gives one (a feature is off unless a struct in the chain
// turns it on: VkPhysicalDeviceVulkan13Features or the extension structs it absorbed), else from
// what the physical device supports, which the AdoptInfo contract asks the engine to have enabled
// (Vulkan cannot be asked which features a device was created with).
struct AdoptedFeatures {
  bool synchronization2 = false;   // vkCmdPipelineBarrier2, vkCmdWriteTimestamp2: every barrier glint records
  bool maintenance4 = false;       // LocalSizeId: every kernel takes its workgroup size from specialization
  bool dynamic_rendering = false;  // vkCmdBeginRendering: LensFlare's raster path only
};

AdoptedFeatures adopted_features(const AdoptInfo& a) {
  AdoptedFeatures f;
  if (a.enabled_features) {
    for (auto* p = static_cast<const VkBaseInStructure*>(a.enabled_features); p; p = p->pNext) {
      switch (p->sType) {
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES: {
          const auto* v = reinterpret_cast<const VkPhysicalDeviceVulkan13Features*>(p);
          f.synchronization2 = f.synchronization2 || v->synchronization2 == VK_TRUE;
          f.maintenance4 = f.maintenance4 || v->maintenance4 == VK_TRUE;
          f.dynamic_rendering = f.dynamic_rendering || v->dynamicRendering == VK_TRUE;
          break;
        }
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES:
          f.synchronization2 =
              f.synchronization2 ||
              reinterpret_cast<const VkPhysicalDeviceSynchronization2Features*>(p)->synchronization2 == VK_TRUE;
          break;
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_FEATURES:
          f.maintenance4 = f.maintenance4 ||
                           reinterpret_cast<const VkPhysicalDeviceMaintenance4Features*>(p)->maintenance4 == VK_TRUE;
          break;
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES:
          f.dynamic_rendering =
              f.dynamic_rendering ||
              reinterpret_cast<const VkPhysicalDeviceDynamicRenderingFeatures*>(p)->dynamicRendering == VK_TRUE;
          break;
        default:
          break;
      }
    }
    return f;
  }
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  supported.pNext = &f13;
  vkGetPhysicalDeviceFeatures2(a.physical_device, &supported);
  f.synchronization2 = f13.synchronization2 == VK_TRUE;
  f.maintenance4 = f13.maintenance4 == VK_TRUE;
  f.dynamic_rendering = f13.dynamicRendering == VK_TRUE;
  return f;
}

std::string version_string(uint32_t v) {
  return concat(VK_API_VERSION_MAJOR(v), ".", VK_API_VERSION_MINOR(v), ".", VK_API_VERSION_PATCH(v));
}

}  // namespace
}  // namespace detail

using detail::concat;

Context Context::adopt(const AdoptInfo& a) {
  if (!a.instance || !a.physical_device || !a.device) {
    throw Error(ErrorCode::invalid_argument,
                concat("AdoptInfo: instance, physical_device and device must all be non-null (got ",
                       a.instance ? "instance" : "null instance", ", ",
                       a.physical_device ? "physical_device" : "null physical_device", ", ",
                       a.device ? "device" : "null device", ")"));
  }
  detail::check_frames_in_flight("AdoptInfo::frames_in_flight", a.frames_in_flight);
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(a.physical_device, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(a.physical_device, &n, families.data());
  if (a.queue_family_index >= n) {
    throw Error(ErrorCode::invalid_argument, concat("AdoptInfo::queue_family_index = ", a.queue_family_index,
                                                    " is out of range: accepted 0 to ", n - 1));
  }
  if (!(families[a.queue_family_index].queueFlags & VK_QUEUE_COMPUTE_BIT)) {
    throw Error(ErrorCode::invalid_argument,
                concat("AdoptInfo::queue_family_index = ", a.queue_family_index, " has no compute capability"));
  }
  // The instance's version bounds what the device may use (Vulkan spec, "Version Numbers": a
  // physical device's apiVersion above the instance's is not available to the application).
  if (a.api_version < VK_API_VERSION_1_3) {
    throw Error(ErrorCode::invalid_argument,
                concat("AdoptInfo::api_version = ",
                       a.api_version == 0 ? std::string("0 (not set)") : detail::version_string(a.api_version),
                       " is out of range: glint needs the instance created with VkApplicationInfo::apiVersion >= 1.3 "
                       "(VK_API_VERSION_1_3), and api_version must say what it was created with"));
  }
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(a.physical_device, &props);
  if (props.apiVersion < VK_API_VERSION_1_3) {
    throw Error(ErrorCode::no_device, concat("AdoptInfo::physical_device '", props.deviceName, "' supports Vulkan ",
                                             detail::version_string(props.apiVersion), "; glint needs 1.3"));
  }
  const detail::AdoptedFeatures features = detail::adopted_features(a);
  const char* source =
      a.enabled_features ? " is not enabled (AdoptInfo::enabled_features)" : " is not supported by the physical device";
  const ErrorCode code = a.enabled_features ? ErrorCode::invalid_argument : ErrorCode::no_device;
  if (!features.synchronization2) {
    throw Error(code, concat("VkPhysicalDeviceVulkan13Features::synchronization2", source,
                             "; glint records every barrier with vkCmdPipelineBarrier2"));
  }
  if (!features.maintenance4) {
    throw Error(code, concat("VkPhysicalDeviceVulkan13Features::maintenance4", source,
                             "; glint's kernels take their workgroup size from specialization (LocalSizeId)"));
  }
  // Vulkan cannot be asked which extensions a device was created with: the engine says.
  if (a.enabled_extension_count != 0 && !a.enabled_extensions) {
    throw Error(ErrorCode::invalid_argument,
                concat("AdoptInfo::enabled_extension_count = ", a.enabled_extension_count,
                       " with a null AdoptInfo::enabled_extensions: give the list or a count of 0"));
  }
  bool push_descriptor = false;
  for (uint32_t i = 0; i < a.enabled_extension_count; ++i) {
    const char* name = a.enabled_extensions[i];
    if (name && std::strcmp(name, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0) push_descriptor = true;
  }
  if (!push_descriptor) {
    throw Error(ErrorCode::invalid_argument,
                concat(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, " is not in AdoptInfo::enabled_extensions (",
                       a.enabled_extension_count,
                       " names given); glint pushes every kernel's descriptors with vkCmdPushDescriptorSetKHR, so "
                       "the device must be created with it (VkDeviceCreateInfo::ppEnabledExtensionNames)"));
  }
  auto state = std::make_unique<detail::ContextState>();
  state->instance = a.instance;
  state->physical_device = a.physical_device;
  state->device = a.device;
  state->queue_family = a.queue_family_index;
  state->adopted = true;
  state->frames_in_flight = a.frames_in_flight;
  detail::fill_info(*state);
  if (!state->push_descriptor_supported) {
    throw Error(ErrorCode::invalid_argument,
                concat("AdoptInfo::enabled_extensions names ", VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME,
                       " but physical device '", state->info.name, "' does not support it"));
  }
  detail::load_push_descriptor(*state);
  state->dynamic_rendering = features.dynamic_rendering;
  return Context(std::move(state));
}

}  // namespace glint
