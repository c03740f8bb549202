// Compute pipelines made from embedded kernels, and the descriptors that feed them: pushed with
// every dispatch (VK_KHR_push_descriptor), so no effect keeps a descriptor set, and a caller's
// view or buffer is named only by the command buffer it was recorded into.
#pragma once

#include <glint/glint.h>

#include <array>
#include <initializer_list>
#include <string>
#include <vector>

#include "core/check.h"
#include "core/kernel_table.h"

namespace glint::detail {

/// Workgroup shape for 2D image kernels, chosen from the device's limits (CONTRIBUTING.md, "Device limits").
struct Workgroup2D {
  uint32_t x = 8;
  uint32_t y = 8;
};
Workgroup2D choose_workgroup_2d(const Context& context);

/// Whether kernels that can order their image loads or stores as a copy does (consecutive
/// invocations at consecutive texels) do so by default on this device: on GPUs, where the other
/// orders measured slower, and not on CPU devices, where the copy orders did (lavapipe: bloom's 2:1
/// upsample and composite, docs/BLOOM.md "Upsample and accumulate"; the blur's 2:1 means and downsample taps,
/// docs/BLUR.md "Streamed separable"). Each kernel also has a way to force either order for tests.
bool copy_order_by_default(const DeviceInfo& info);

/// The most descriptors one dispatch pushes. VkPhysicalDevicePushDescriptorPropertiesKHR::
/// maxPushDescriptors is at least 32 on every device with VK_KHR_push_descriptor (Vulkan spec,
/// "Limits"); pipelines are checked against the device's own limit when they are made.
constexpr uint32_t kMaxBindings = 32;

/// One descriptor of a dispatch: an image view in `layout` (with `sampler` for a combined image
/// sampler binding), or a range of a buffer. Which one is read from the binding's type.
struct Binding {
  Binding() = default;
  Binding(VkImageView v, VkImageLayout l, VkSampler s = VK_NULL_HANDLE) : view(v), layout(l), sampler(s) {}
  Binding(const Buffer& b) : buffer(b) {}  // NOLINT(google-explicit-constructor): {buffer} in a list
  VkImageView view = VK_NULL_HANDLE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkSampler sampler = VK_NULL_HANDLE;
  Buffer buffer{};
};

/// The descriptors of one dispatch, binding i at index i: a fixed-capacity array that lives on the
/// recording thread's stack, so recording allocates nothing (tests/allocation_test.cpp).
class Bindings {
 public:
  Bindings() = default;
  Bindings(std::initializer_list<Binding> list) {
    for (const Binding& b : list) push_back(b);
  }
  void push_back(const Binding& b) {
    if (count_ == kMaxBindings) {
      throw Error(ErrorCode::invalid_argument,
                  concat("internal: more than kMaxBindings = ", kMaxBindings, " bindings"));
    }
    items_[count_++] = b;
  }
  uint32_t size() const { return count_; }
  const Binding& operator[](uint32_t i) const { return items_[i]; }
  Binding& operator[](uint32_t i) { return items_[i]; }

 private:
  std::array<Binding, kMaxBindings> items_{};
  uint32_t count_ = 0;
};

/// A descriptor set layout for push descriptors (VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR)
/// whose binding i has type types[i], visible to `stages`. Refuses more bindings than the device's
/// maxPushDescriptors (or kMaxBindings). The caller destroys it.
VkDescriptorSetLayout make_push_set_layout(const Context& context, const std::vector<VkDescriptorType>& types,
                                           VkShaderStageFlags stages);

/// Throws Error(invalid_argument) naming `who` unless `bindings` has one descriptor per type of
/// `types`, each with what its type needs (a view, a sampler too, or a buffer with a size).
void check_bindings(const std::vector<VkDescriptorType>& types, const Bindings& bindings, const std::string& who);

/// Records `push` (the context's vkCmdPushDescriptorSetKHR, ContextState::cmd_push_descriptor_set)
/// for set 0 of `layout` at `bind_point`: binding i of type types[i] gets bindings[i]. Checks them
/// first (check_bindings()), so nothing is recorded when they are wrong.
void push_descriptors(PFN_vkCmdPushDescriptorSetKHR push, VkCommandBuffer cmd, VkPipelineBindPoint bind_point,
                      VkPipelineLayout layout, const std::vector<VkDescriptorType>& types, const Bindings& bindings,
                      const std::string& who);

struct PipelineDesc {
  std::string kernel_id;                   //!< e.g. "bloom_down_rgba16f"
  std::vector<VkDescriptorType> bindings;  //!< binding i has type bindings[i]
  uint32_t push_constant_bytes = 0;
  Workgroup2D workgroup;                 //!< constant_id 0 and 1 (local_size_x_id/y_id)
  std::vector<uint32_t> specialization;  //!< constant_id 2, 3, ...
  /// The SPIR-V to compile when it is not the library's: a kernel of another table, such as the
  /// tools' (tools/support/tool_kernels.h); kernel_id still names it in errors and in the
  /// context's pipeline cache, so the ids of all tables are distinct. Null: the library's kernel
  /// named kernel_id.
  const KernelBinary* binary = nullptr;
};

/// The Vulkan objects of one compiled kernel variant. Owned by the context (ContextState::pipelines),
/// shared by every ComputePipeline of the same PipelineDesc, destroyed with the context.
struct CompiledPipeline {
  VkDevice device = VK_NULL_HANDLE;
  PFN_vkCmdPushDescriptorSetKHR push_descriptor_set = nullptr;  // the context's, loaded once
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  CompiledPipeline() = default;
  CompiledPipeline(const CompiledPipeline&) = delete;
  CompiledPipeline& operator=(const CompiledPipeline&) = delete;
  ~CompiledPipeline();
};

/// A kernel variant ready to dispatch. The compiled objects are made once per context and
/// PipelineDesc and live as long as the context: an effect made again (or a second effect of the
/// same shape) compiles nothing. lavapipe kept ~2 MB per compile that destroying the pipeline did
/// not give back, so re-making effects grew the process without bound (tests/api_errors_test.cpp).
class ComputePipeline {
 public:
  ComputePipeline() = default;
  ComputePipeline(const Context& context, const PipelineDesc& desc);
  ComputePipeline(ComputePipeline&& o) noexcept { *this = std::move(o); }
  ComputePipeline& operator=(ComputePipeline&& o) noexcept;
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;
  ~ComputePipeline() = default;
  void reset() { compiled_ = nullptr; }

  explicit operator bool() const { return compiled_ != nullptr; }
  VkDescriptorSetLayout set_layout() const { return compiled_ ? compiled_->set_layout : VK_NULL_HANDLE; }
  const std::vector<VkDescriptorType>& bindings() const { return bindings_; }

  /// Binds the pipeline, pushes `bindings` (binding i of the kernel gets bindings[i]) and `push`,
  /// and dispatches enough groups to cover width x height invocations. The push-constant size
  /// and the binding count are checked on every dispatch.
  template <typename Push>
  void dispatch(VkCommandBuffer cmd, const Bindings& bindings, const Push& push, uint32_t width,
                uint32_t height) const {
    dispatch_raw(cmd, bindings, &push, sizeof(Push), width, height);
  }

  /// Binds the pipeline, pushes `bindings` and `push`, and records vkCmdDispatchIndirect reading a
  /// VkDispatchIndirectCommand at `offset` in `args` (which needs INDIRECT_BUFFER usage and a
  /// barrier to DRAW_INDIRECT / INDIRECT_COMMAND_READ after whatever wrote it).
  template <typename Push>
  void dispatch_indirect(VkCommandBuffer cmd, const Bindings& bindings, const Push& push, VkBuffer args,
                         VkDeviceSize offset) const {
    bind_and_push(cmd, bindings, &push, sizeof(Push));
    vkCmdDispatchIndirect(cmd, args, offset);
  }

 private:
  void bind_and_push(VkCommandBuffer cmd, const Bindings& bindings, const void* push, uint32_t bytes) const;
  void dispatch_raw(VkCommandBuffer cmd, const Bindings& bindings, const void* push, uint32_t bytes, uint32_t width,
                    uint32_t height) const;
  const CompiledPipeline* compiled_ = nullptr;  // owned by the context
  std::string id_;
  uint32_t push_bytes_ = 0;
  Workgroup2D workgroup_;
  std::vector<VkDescriptorType> bindings_;
};

}  // namespace glint::detail
