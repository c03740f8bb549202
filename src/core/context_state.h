// What a Context holds. Internal: effects and tools include it, users never need to.
#pragma once

#include <glint/glint.h>

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/formats.h"

namespace glint::detail {

struct ContextState {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  VkQueue queue = VK_NULL_HANDLE;  // standalone only
  bool adopted = false;
  DeviceInfo info;
  // Whether the device was created with dynamicRendering (standalone: enabled when supported;
  // adopted: read from AdoptInfo::enabled_features, else the physical device's support), and
  // whether the queue family can draw. LensFlare's raster path needs both.
  bool dynamic_rendering = false;
  bool graphics_queue = false;
  // ContextOptions::workgroup_2d (0x0: each kernel's device-specific choice).
  VkExtent2D workgroup_2d{0, 0};
  VkPhysicalDeviceMemoryProperties memory{};
  // Whether the physical device supports VK_EXT_memory_budget (a physical-device query, usable
  // whether or not the engine enabled the extension on its device).
  bool memory_budget = false;
  // VK_KHR_push_descriptor: every kernel's descriptors are pushed with the dispatch
  // (core/pipeline.h). The physical device's support and maxPushDescriptors (fill_info()), and the
  // command, loaded with vkGetDeviceProcAddr once the device is known to have it enabled.
  bool push_descriptor_supported = false;
  uint32_t max_push_descriptors = 0;
  PFN_vkCmdPushDescriptorSetKHR cmd_push_descriptor_set = nullptr;
  // VK_KHR_pipeline_executable_properties (ContextOptions::kernel_statistics): whether the
  // physical device has it (fill_info()), and whether it was enabled with pipelineExecutableInfo;
  // then pipelines are made with VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR
  // (Context::kernel_statistics(), core/pipeline.cpp).
  bool executable_properties_supported = false;
  bool kernel_statistics = false;
  // The subgroup sizes a compute dispatch may get (VkPhysicalDeviceVulkan13Properties; the one
  // subgroupSize where those are 0) and the subgroup operations compute shaders have (0 where the
  // compute stage has none), read once by fill_info() for kernels with subgroup variants.
  uint32_t min_subgroup_size = 0;
  uint32_t max_subgroup_size = 0;
  VkSubgroupFeatureFlags compute_subgroup_operations = 0;

  // Standalone helpers for run_once(). The pool, the fence and the queue need external
  // synchronization (Vulkan, "Threading Behavior"): run_once() holds submit_mutex from allocating
  // its command buffer to the fence wait. Recursive, because a recording callback may make an
  // effect whose constructor submits through run_once() on the same thread.
  VkCommandPool command_pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  std::recursive_mutex submit_mutex;

  // Frames (Context::begin_frame()): the current frame number and the caller's frames in flight.
  std::atomic<uint64_t> frame{0};
  uint32_t frames_in_flight = 3;

  // Command buffers of run_once() calls that are recording or executing, with a serial number
  // each (run_once() may nest on one thread). Work recorded into one of them is complete once its
  // serial leaves this list, which lets effects retire a size used only there (core/size_cache.h).
  std::atomic<uint32_t> once_count{0};
  mutable std::mutex once_mutex;
  std::vector<std::pair<VkCommandBuffer, uint64_t>> once_active;
  uint64_t once_next = 1;
  /// The serial of the run_once() command buffer `cmd`, or 0 if `cmd` is not one.
  uint64_t once_serial(VkCommandBuffer cmd) const;
  /// Whether the run_once() call of `serial` (non-zero) is still recording or executing.
  bool once_pending(uint64_t serial) const;

  // GaussianBlur's measured cost model (measure_blur_cost_model(), docs/BLUR.md "Cost model"):
  // us per dispatch, byte, shared tap, fetch tap; measured once, under blur_cost_mutex.
  std::mutex blur_cost_mutex;
  bool blur_cost_measured = false;
  double blur_cost[4] = {0, 0, 0, 0};

  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  mutable std::mutex log_mutex;
  std::vector<std::string> validation_log;
  std::atomic<uint32_t> validation_count{0};
  std::atomic<uint64_t> objects_created{0};

  /// Index of a memory type allowed by `type_bits` with all `flags`; throws if none.
  uint32_t memory_type(uint32_t type_bits, VkMemoryPropertyFlags flags) const;
  void count_object(uint64_t n = 1) { objects_created += n; }

  /// Allocates `req` from a memory type with `flags` for `what` ("a 16384x16384 image"): refuses
  /// with Error(unsupported_size), before allocating, a request larger than the heap's budget
  /// (VK_EXT_memory_budget: what this process may still allocate) or, without the extension, than
  /// the heap; turns VK_ERROR_OUT_OF_DEVICE_MEMORY / _HOST_MEMORY into the same error, naming the
  /// bytes asked for and the heap. Returns the memory and the type index chosen.
  VkDeviceMemory allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags flags, const std::string& what,
                          uint32_t* type_index = nullptr);

  /// Objects owned by the context for helpers without an owner of their own (the demo scene's
  /// pipeline): made on first use, destroyed with the context, before the device.
  template <typename T>
  T& cached(const std::string& key, const std::function<std::shared_ptr<T>()>& make) {
    std::lock_guard<std::mutex> lock(cache_mutex);
    auto& slot = cache[key];
    if (!slot) slot = make();
    return *static_cast<T*>(slot.get());
  }
  std::mutex cache_mutex;
  std::map<std::string, std::shared_ptr<void>> cache;

  /// Compiled kernels, shared by every ComputePipeline of the context (core/pipeline.cpp). Apart
  /// from `cache` because a cached helper's make() may itself make a ComputePipeline.
  std::mutex pipeline_mutex;
  std::map<std::string, std::shared_ptr<void>> pipelines;

  /// Clamp-to-edge samplers by (filter, mipmap mode, max lod), shared like the kernels
  /// (core/resources.h, clamp_sampler()); destroyed with the context.
  std::mutex sampler_mutex;
  std::map<std::tuple<int, int, float>, VkSampler> samplers;

  /// optimalTilingFeatures of each format of kCheckedFormats (core/formats.h, format_features()),
  /// read by fill_info() when the context is made and never written afterwards: effects look them
  /// up on every record(), from any thread, without a lock.
  FormatFeatureTable format_features{};
};

/// Validation messages seen by every context of the process, including those that arrive while a
/// context is being destroyed (the object tracker reports leaked objects in vkDestroyDevice, after
/// which the context's own count is gone). Tests of leaks compare it before and after.
uint64_t validation_messages_all_contexts();

/// Throws Error(invalid_argument) "<name> = N is out of range: accepted 1 to 16".
void check_frames_in_flight(const char* name, uint32_t frames);

}  // namespace glint::detail
