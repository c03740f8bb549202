// Instance creation (validation layer and messenger) and device selection for standalone
// contexts (Context::create), and list_devices().
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/check.h"
#include "core/context_state.h"
#include "core/device_setup.h"

namespace glint {
namespace detail {

namespace {
std::atomic<uint64_t> g_validation_messages{0};
}

uint64_t validation_messages_all_contexts() { return g_validation_messages.load(); }

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* state = static_cast<ContextState*>(user);
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) return VK_FALSE;
  std::string text = data && data->pMessage ? data->pMessage : "(no message)";
  {
    std::lock_guard<std::mutex> lock(state->log_mutex);
    state->validation_log.push_back(text);
  }
  state->validation_count++;
  g_validation_messages++;
  std::fprintf(stderr, "glint: validation: %s\n", text.c_str());
  return VK_FALSE;
}

bool layer_available(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

}  // namespace

VkInstance make_instance(bool validation, bool gpu_assisted, ContextState* state, VkDebugUtilsMessengerEXT* messenger) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "glint";
  app.pEngineName = "glint";
  app.apiVersion = VK_API_VERSION_1_3;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  const char* kValidation = "VK_LAYER_KHRONOS_validation";
  if (validation) {
    if (!layer_available(kValidation)) {
      throw Error(ErrorCode::no_device,
                  "ContextOptions::validation is set but "
                  "VK_LAYER_KHRONOS_validation is not installed (Debian: vulkan-validationlayers)");
    }
    layers.push_back(kValidation);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  // Synchronization validation on; best practices off (it warns about choices, not errors).
  // ContextOptions::gpu_assisted_validation adds GPU-assisted validation (instrumented shaders
  // check descriptor indexing and buffer bounds on the device); slow.
  VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT,
                                            VK_VALIDATION_FEATURE_ENABLE_GPU_ASSISTED_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = gpu_assisted ? 2 : 1;
  features.pEnabledValidationFeatures = enables;

  VkDebugUtilsMessengerCreateInfoEXT messenger_info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger_info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger_info.pfnUserCallback = on_validation_message;
  messenger_info.pUserData = state;
  if (validation) features.pNext = &messenger_info;

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pNext = validation ? &features : nullptr;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  vk_check(vkCreateInstance(&info, nullptr, &instance), "vkCreateInstance");
  if (validation && messenger) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create) vk_check(create(instance, &messenger_info, nullptr, messenger), "vkCreateDebugUtilsMessengerEXT");
  }
  return instance;
}

std::vector<VkPhysicalDevice> physical_devices(VkInstance instance) {
  uint32_t n = 0;
  vk_check(vkEnumeratePhysicalDevices(instance, &n, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(n);
  vk_check(vkEnumeratePhysicalDevices(instance, &n, devices.data()), "vkEnumeratePhysicalDevices");
  return devices;
}

namespace {

int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

}  // namespace

VkPhysicalDevice choose_device(VkInstance instance, std::string wanted) {
  auto devices = physical_devices(instance);
  if (devices.empty())
    throw Error(ErrorCode::no_device, "no Vulkan device found (Debian: mesa-vulkan-drivers gives lavapipe)");
  std::vector<VkPhysicalDeviceProperties> props(devices.size());
  for (size_t i = 0; i < devices.size(); ++i) vkGetPhysicalDeviceProperties(devices[i], &props[i]);
  if (!wanted.empty()) {
    bool numeric = std::all_of(wanted.begin(), wanted.end(), [](unsigned char c) { return std::isdigit(c); });
    if (numeric) {
      unsigned long idx = std::strtoul(wanted.c_str(), nullptr, 10);
      if (idx >= devices.size()) {
        throw Error(ErrorCode::no_device,
                    concat("device index ", wanted, " is out of range: accepted 0 to ", devices.size() - 1));
      }
      return devices[idx];
    }
    for (size_t i = 0; i < devices.size(); ++i) {
      if (lower(props[i].deviceName).find(lower(wanted)) != std::string::npos) return devices[i];
    }
    std::string names;
    for (auto& p : props) names += concat(names.empty() ? "" : ", ", "'", p.deviceName, "'");
    throw Error(ErrorCode::no_device, concat("no Vulkan device matches '", wanted, "'; devices: ", names));
  }
  size_t best = 0;
  for (size_t i = 1; i < devices.size(); ++i) {
    if (type_rank(props[i].deviceType) < type_rank(props[best].deviceType)) best = i;
  }
  return devices[best];
}

uint32_t compute_queue_family(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, families.data());
  // Prefer graphics+compute: effects that draw (flares) need graphics; bloom needs compute.
  for (uint32_t i = 0; i < n; ++i) {
    if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) return i;
  }
  for (uint32_t i = 0; i < n; ++i) {
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return i;
  }
  throw Error(ErrorCode::no_device, "the device has no queue family with compute");
}

}  // namespace detail

std::vector<DeviceDescription> list_devices() {
  VkInstance instance = detail::make_instance(false, false, nullptr, nullptr);
  std::vector<DeviceDescription> out;
  try {
    auto devices = detail::physical_devices(instance);
    for (uint32_t i = 0; i < devices.size(); ++i) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(devices[i], &p);
      out.push_back({i, p.deviceName, p.deviceType, p.apiVersion});
    }
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return out;
}

}  // namespace glint
