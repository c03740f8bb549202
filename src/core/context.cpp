// Context: standalone (own instance and device) or adopted (the engine's), device selection,
// validation messages, run_once for tools, and the timestamp profiler.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"

namespace glint {
namespace detail {

const char* vk_result_name(VkResult r) {
  switch (r) {
    case VK_SUCCESS:
      return "VK_SUCCESS";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_FORMAT_NOT_SUPPORTED:
      return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_OUT_OF_POOL_MEMORY:
      return "VK_ERROR_OUT_OF_POOL_MEMORY";
    default:
      return "VkResult error";
  }
}

uint32_t ContextState::memory_type(uint32_t type_bits, VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
  }
  throw Error(ErrorCode::vulkan_failure, concat("no memory type with flags 0x", std::hex, flags));
}

VkDeviceMemory ContextState::allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags flags,
                                      const std::string& what, uint32_t* type_index) {
  const uint32_t type = memory_type(req.memoryTypeBits, flags);
  const uint32_t heap = memory.memoryTypes[type].heapIndex;
  VkDeviceSize available = memory.memoryHeaps[heap].size;
  const char* source = "the heap's size";
  if (memory_budget) {
    // VK_EXT_memory_budget: heapBudget is what this process may use in all, heapUsage what it uses.
    VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
    VkPhysicalDeviceMemoryProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2};
    props.pNext = &budget;
    vkGetPhysicalDeviceMemoryProperties2(physical_device, &props);
    available = budget.heapBudget[heap] > budget.heapUsage[heap] ? budget.heapBudget[heap] - budget.heapUsage[heap] : 0;
    source = "the budget left (VK_EXT_memory_budget)";
  }
  auto refuse = [&](const char* why) {
    return Error(ErrorCode::unsupported_size, concat(what, " needs ", req.size, " bytes of memory heap ", heap, "; ",
                                                     why, " ", available, " bytes: make it smaller or free memory"));
  };
  if (req.size > available) throw refuse(concat(source, " is").c_str());
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = type;
  VkDeviceMemory out = VK_NULL_HANDLE;
  const VkResult r = vkAllocateMemory(device, &alloc, nullptr, &out);
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY) {
    throw refuse("vkAllocateMemory ran out of memory; the heap reported");
  }
  vk_check(r, "vkAllocateMemory");
  count_object();
  if (type_index) *type_index = type;
  return out;
}

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

void fill_info(ContextState& s) {
  VkPhysicalDevicePushDescriptorPropertiesKHR push{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR};
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  subgroup.pNext = &push;  // filled only if the device has the extension (checked below)
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(s.physical_device, &props);
  const auto& p = props.properties;
  s.info.name = p.deviceName;
  s.info.type = p.deviceType;
  s.info.subgroup_size = subgroup.subgroupSize;
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
using detail::vk_check;

Context::Context(std::unique_ptr<detail::ContextState> state) : state_(std::move(state)) {}
Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;

Context::~Context() {
  if (!state_) return;
  auto& s = *state_;
  s.cache.clear();      // helper objects first: they hold handles of the device
  s.pipelines.clear();  // then the compiled kernels, before the device goes
  for (auto& [key, sampler] : s.samplers) vkDestroySampler(s.device, sampler, nullptr);
  s.samplers.clear();
  if (s.adopted) return;
  if (s.device) {
    vkDeviceWaitIdle(s.device);
    if (s.fence) vkDestroyFence(s.device, s.fence, nullptr);
    if (s.command_pool) vkDestroyCommandPool(s.device, s.command_pool, nullptr);
    vkDestroyDevice(s.device, nullptr);
  }
  if (s.messenger) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(s.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(s.instance, s.messenger, nullptr);
  }
  if (s.instance) vkDestroyInstance(s.instance, nullptr);
}

Context Context::create(const ContextOptions& options) {
  auto state = std::make_unique<detail::ContextState>();
  auto& s = *state;
  // The context is returned only when complete; a throw below must not leak what was made.
  struct Guard {
    detail::ContextState* s;
    bool done = false;
    ~Guard() {
      if (done) return;
      if (s->device) vkDestroyDevice(s->device, nullptr);
      if (s->messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(s->instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(s->instance, s->messenger, nullptr);
      }
      if (s->instance) vkDestroyInstance(s->instance, nullptr);
    }
  } guard{&s};

  detail::check_frames_in_flight("ContextOptions::frames_in_flight", options.frames_in_flight);
  if (options.gpu_assisted_validation && !options.validation) {
    throw Error(ErrorCode::invalid_argument,
                "ContextOptions::gpu_assisted_validation needs ContextOptions::validation = true");
  }
  s.instance = detail::make_instance(options.validation, options.gpu_assisted_validation, &s, &s.messenger);
  s.physical_device = detail::choose_device(s.instance, options.device);
  s.queue_family = detail::compute_queue_family(s.physical_device);

  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(s.physical_device, &props);
  if (props.apiVersion < VK_API_VERSION_1_3) {
    throw Error(ErrorCode::no_device,
                concat("device '", props.deviceName, "' supports Vulkan ", VK_API_VERSION_MAJOR(props.apiVersion), ".",
                       VK_API_VERSION_MINOR(props.apiVersion), "; glint needs 1.3"));
  }

  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.pNext = &f13;
  VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  supported.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(s.physical_device, &supported);
  for (auto [name, supported_feature] :
       {std::pair{"synchronization2", f13.synchronization2}, std::pair{"maintenance4", f13.maintenance4}}) {
    if (!supported_feature) {
      throw Error(ErrorCode::no_device,
                  concat("device '", props.deviceName, "' does not support VkPhysicalDeviceVulkan13Features::", name,
                         ", which glint needs"));
    }
  }

  detail::fill_info(s);
  if (!s.push_descriptor_supported) {
    throw Error(ErrorCode::no_device,
                concat("device '", props.deviceName, "' does not support ", VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME,
                       ", which glint needs (every kernel's descriptors are pushed)"));
  }
  const char* device_extensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME,
                                     VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME};
  // Kernel statistics (ContextOptions::kernel_statistics): the extension and its feature only where
  // the device has both; otherwise the device is made as without the option.
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR exec_supported{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  if (options.kernel_statistics && s.executable_properties_supported) {
    VkPhysicalDeviceFeatures2 query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    query.pNext = &exec_supported;
    vkGetPhysicalDeviceFeatures2(s.physical_device, &query);
  }
  s.kernel_statistics = exec_supported.pipelineExecutableInfo == VK_TRUE;
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR exec_enabled{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  exec_enabled.pipelineExecutableInfo = VK_TRUE;

  VkPhysicalDeviceVulkan13Features e13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  e13.synchronization2 = VK_TRUE;
  e13.dynamicRendering = f13.dynamicRendering;  // a Vulkan 1.3 requirement; LensFlare draws with it
  e13.subgroupSizeControl = f13.subgroupSizeControl;
  e13.computeFullSubgroups = f13.computeFullSubgroups;
  e13.maintenance4 = VK_TRUE;
  VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  e12.pNext = &e13;
  if (s.kernel_statistics) e13.pNext = &exec_enabled;
  e12.hostQueryReset = f12.hostQueryReset;
  e12.timelineSemaphore = f12.timelineSemaphore;
  e12.shaderFloat16 = f12.shaderFloat16;
  VkPhysicalDeviceFeatures2 enabled{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  enabled.pNext = &e12;
  enabled.features.shaderStorageImageWriteWithoutFormat = supported.features.shaderStorageImageWriteWithoutFormat;
  enabled.features.samplerAnisotropy = supported.features.samplerAnisotropy;

  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = s.queue_family;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &enabled;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  info.enabledExtensionCount = s.kernel_statistics ? 2 : 1;
  info.ppEnabledExtensionNames = device_extensions;
  vk_check(vkCreateDevice(s.physical_device, &info, nullptr, &s.device), "vkCreateDevice");
  detail::load_push_descriptor(s);
  vkGetDeviceQueue(s.device, s.queue_family, 0, &s.queue);

  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = s.queue_family;
  vk_check(vkCreateCommandPool(s.device, &pool, nullptr, &s.command_pool), "vkCreateCommandPool");
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  vk_check(vkCreateFence(s.device, &fence, nullptr, &s.fence), "vkCreateFence");
  s.dynamic_rendering = f13.dynamicRendering == VK_TRUE;
  const VkExtent2D wg = options.workgroup_2d;
  if (wg.width != 0 || wg.height != 0) {
    const uint64_t n = uint64_t(wg.width) * wg.height;
    if (wg.width == 0 || wg.height == 0 || n > s.info.max_workgroup_invocations) {
      throw Error(ErrorCode::invalid_argument,
                  concat("ContextOptions::workgroup_2d = ", wg.width, "x", wg.height,
                         " is out of range: accepted 0x0 (the device's choice) or WxH with W, H >= 1 and W * H <= ",
                         s.info.max_workgroup_invocations, " (maxComputeWorkGroupInvocations)"));
    }
    s.workgroup_2d = wg;
  }
  s.frames_in_flight = options.frames_in_flight;
  guard.done = true;
  return Context(std::move(state));
}

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

VkInstance Context::instance() const { return state_->instance; }
VkPhysicalDevice Context::physical_device() const { return state_->physical_device; }
VkDevice Context::device() const { return state_->device; }
uint32_t Context::queue_family_index() const { return state_->queue_family; }
const DeviceInfo& Context::info() const { return state_->info; }
bool Context::is_adopted() const { return state_->adopted; }
uint32_t Context::validation_messages() const { return state_->validation_count.load(); }
std::vector<std::string> Context::validation_log() const {
  std::lock_guard<std::mutex> lock(state_->log_mutex);
  return state_->validation_log;
}
uint64_t Context::objects_created() const { return state_->objects_created.load(); }

void Context::run_once(const std::function<void(VkCommandBuffer)>& record) const {
  auto& s = *state_;
  if (s.adopted) {
    throw Error(ErrorCode::invalid_argument, "run_once() is for standalone contexts; an adopted context never submits");
  }
  std::lock_guard<std::recursive_mutex> lock(s.submit_mutex);
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = s.command_pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  vk_check(vkAllocateCommandBuffers(s.device, &alloc, &cmd), "vkAllocateCommandBuffers");
  struct Free {
    const detail::ContextState& s;
    VkCommandBuffer cmd;
    ~Free() { vkFreeCommandBuffers(s.device, s.command_pool, 1, &cmd); }
  } free_cmd{s, cmd};
  // Effects recording into `cmd` note its serial; it is pending until the fence wait below is over
  // (or recording failed and nothing was submitted), the guard's destructor.
  struct Once {
    detail::ContextState& s;
    VkCommandBuffer cmd;
    Once(detail::ContextState& state, VkCommandBuffer c) : s(state), cmd(c) {
      std::lock_guard<std::mutex> lock(s.once_mutex);
      s.once_active.emplace_back(cmd, s.once_next++);
      ++s.once_count;
    }
    ~Once() {
      std::lock_guard<std::mutex> lock(s.once_mutex);
      for (auto it = s.once_active.begin(); it != s.once_active.end(); ++it) {
        if (it->first == cmd) {
          s.once_active.erase(it);
          break;
        }
      }
      --s.once_count;
    }
  } once{s, cmd};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vk_check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  record(cmd);
  vk_check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  vk_check(vkResetFences(s.device, 1, &s.fence), "vkResetFences");
  vk_check(vkQueueSubmit(s.queue, 1, &submit, s.fence), "vkQueueSubmit");
  vk_check(vkWaitForFences(s.device, 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

uint64_t Context::begin_frame() const { return ++state_->frame; }
uint64_t Context::frame() const { return state_->frame.load(); }
uint32_t Context::frames_in_flight() const { return state_->frames_in_flight; }
void Context::mark_idle() const { state_->frame += state_->frames_in_flight; }

void Context::wait_idle() const {
  auto& s = *state_;
  if (s.adopted) {
    throw Error(ErrorCode::invalid_argument,
                "Context::wait_idle() is for standalone contexts; with an adopted context wait for the engine's "
                "queues, then call mark_idle()");
  }
  {
    std::lock_guard<std::recursive_mutex> lock(s.submit_mutex);
    vk_check(vkQueueWaitIdle(s.queue), "vkQueueWaitIdle");
  }
  mark_idle();
}

namespace detail {

uint64_t ContextState::once_serial(VkCommandBuffer cmd) const {
  if (once_count.load() == 0) return 0;
  std::lock_guard<std::mutex> lock(once_mutex);
  for (const auto& [c, serial] : once_active) {
    if (c == cmd) return serial;
  }
  return 0;
}

bool ContextState::once_pending(uint64_t serial) const {
  if (serial == 0 || once_count.load() == 0) return false;
  std::lock_guard<std::mutex> lock(once_mutex);
  for (const auto& entry : once_active) {
    if (entry.second == serial) return true;
  }
  return false;
}

void check_frames_in_flight(const char* name, uint32_t frames) {
  if (frames < 1 || frames > 16) {
    throw Error(ErrorCode::invalid_argument, concat(name, " = ", frames, " is out of range: accepted 1 to 16"));
  }
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

// ---- Profiler ---------------------------------------------------------------------------------

Profiler::Profiler(const Context& context, uint32_t capacity) : context_(&context), capacity_(capacity) {
  detail::check_range("Profiler capacity", capacity, 1, 4096);
  if (!context.info().timestamps_supported) return;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = capacity;
  vk_check(vkCreateQueryPool(context.device(), &info, nullptr, &pool_), "vkCreateQueryPool");
  context.state().count_object();
  // Every label's storage is made here, so that mark() in the frame path never allocates.
  labels_.resize(capacity);
  for (std::string& l : labels_) l.reserve(kLabelBytes);
}

Profiler::~Profiler() {
  if (pool_) vkDestroyQueryPool(context_->device(), pool_, nullptr);
}

void Profiler::reset(VkCommandBuffer cmd) {
  marks_ = 0;
  if (!pool_) return;
  detail::count_recorded_command();
  vkCmdResetQueryPool(cmd, pool_, 0, capacity_);
}

void Profiler::mark(VkCommandBuffer cmd, std::string_view label) {
  if (!pool_) return;
  if (marks_ >= capacity_) {
    throw Error(ErrorCode::invalid_argument, concat("Profiler: more than ", capacity_, " marks in one frame"));
  }
  detail::count_recorded_command();
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_, marks_);
  labels_[marks_++].assign(label.data(), label.size());
}

std::vector<Profiler::Stage> Profiler::results() const {
  std::vector<Stage> out;
  if (!pool_ || marks_ < 2) return out;
  std::vector<uint64_t> ticks(marks_);
  vk_check(vkGetQueryPoolResults(context_->device(), pool_, 0, static_cast<uint32_t>(ticks.size()),
                                 ticks.size() * sizeof(uint64_t), ticks.data(), sizeof(uint64_t),
                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
           "vkGetQueryPoolResults");
  const double ns = context_->info().timestamp_period_ns;
  for (size_t i = 1; i < ticks.size(); ++i) {
    out.push_back({labels_[i], static_cast<double>(ticks[i] - ticks[i - 1]) * ns * 1e-6});
  }
  return out;
}

double Profiler::total_ms() const {
  double total = 0.0;
  for (const auto& s : results()) total += s.ms;
  return total;
}

}  // namespace glint
