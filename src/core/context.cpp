// Context: the standalone context's device (Context::create), its accessors, run_once for tools,
// frames and the context's memory allocation. Instance creation and device selection are in
// device_selection.cpp, what is read from the device in device_info.cpp, adoption in adopt.cpp.
#include "core/check.h"
#include "core/context_state.h"
#include "core/device_setup.h"

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

}  // namespace glint
