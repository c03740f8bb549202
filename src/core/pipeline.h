// Compute pipelines made from embedded kernels, and the descriptor sets that feed them.
#pragma once

#include <glint/glint.h>

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

  VkDescriptorSetLayout set_layout() const { return compiled_ ? compiled_->set_layout : VK_NULL_HANDLE; }
  const std::vector<VkDescriptorType>& bindings() const { return bindings_; }

  /// Binds the pipeline and `set`, pushes `push` and dispatches enough groups to cover
  /// width x height invocations. The push-constant size is checked on every dispatch.
  template <typename Push>
  void dispatch(VkCommandBuffer cmd, VkDescriptorSet set, const Push& push, uint32_t width, uint32_t height) const {
    dispatch_raw(cmd, set, &push, sizeof(Push), width, height);
  }

  /// Binds the pipeline and `set`, pushes `push` and records vkCmdDispatchIndirect reading a
  /// VkDispatchIndirectCommand at `offset` in `args` (which needs INDIRECT_BUFFER usage and a
  /// barrier to DRAW_INDIRECT / INDIRECT_COMMAND_READ after whatever wrote it).
  template <typename Push>
  void dispatch_indirect(VkCommandBuffer cmd, VkDescriptorSet set, const Push& push, VkBuffer args,
                         VkDeviceSize offset) const {
    bind_and_push(cmd, set, &push, sizeof(Push));
    vkCmdDispatchIndirect(cmd, args, offset);
  }

 private:
  void bind_and_push(VkCommandBuffer cmd, VkDescriptorSet set, const void* push, uint32_t bytes) const;
  void dispatch_raw(VkCommandBuffer cmd, VkDescriptorSet set, const void* push, uint32_t bytes, uint32_t width,
                    uint32_t height) const;
  const CompiledPipeline* compiled_ = nullptr;  // owned by the context
  std::string id_;
  uint32_t push_bytes_ = 0;
  Workgroup2D workgroup_;
  std::vector<VkDescriptorType> bindings_;
};

/// Descriptor pools and the sets allocated from them, owned by one effect. Pools are made on
/// demand, each for `sets_per_pool` sets of up to `per_type` descriptors of each type, so an arena
/// never runs out (effects that make sets for each new caller image keep one arena for them).
class DescriptorArena {
 public:
  DescriptorArena() = default;
  DescriptorArena(const Context& context, uint32_t sets_per_pool, uint32_t per_type = 4);
  DescriptorArena(DescriptorArena&& o) noexcept { *this = std::move(o); }
  DescriptorArena& operator=(DescriptorArena&& o) noexcept;
  DescriptorArena(const DescriptorArena&) = delete;
  DescriptorArena& operator=(const DescriptorArena&) = delete;
  ~DescriptorArena() { reset(); }
  /// Frees every set and pool (the arena stays usable).
  void reset();

  struct ImageBinding {
    VkImageView view;
    VkImageLayout layout;
  };
  /// One binding of a set that mixes images and buffers: `buffer.buffer` set means a buffer;
  /// `sampler` goes with the image of a combined image sampler binding.
  struct AnyBinding {
    ImageBinding image{VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED};
    Buffer buffer{};
    VkSampler sampler = VK_NULL_HANDLE;
  };
  /// Allocates a set for `pipeline` and writes one image per binding, in binding order.
  VkDescriptorSet make_set(const ComputePipeline& pipeline, const std::vector<ImageBinding>& images);
  /// The same for pipelines whose bindings are all storage buffers.
  VkDescriptorSet make_buffer_set(const ComputePipeline& pipeline, const std::vector<Buffer>& buffers);
  /// Allocates a set for `pipeline` and writes one image or buffer per binding, in binding order.
  VkDescriptorSet make_mixed_set(const ComputePipeline& pipeline, const std::vector<AnyBinding>& bindings) {
    return make_mixed_set(pipeline.set_layout(), pipeline.bindings(), bindings);
  }
  /// The same for any set layout (a graphics pipeline's) whose binding i has type types[i].
  VkDescriptorSet make_mixed_set(VkDescriptorSetLayout layout, const std::vector<VkDescriptorType>& types,
                                 const std::vector<AnyBinding>& bindings);

 private:
  const Context* context_ = nullptr;
  uint32_t sets_per_pool_ = 0;
  uint32_t per_type_ = 4;
  uint32_t left_ = 0;  // sets the last pool can still give
  std::vector<VkDescriptorPool> pools_;
};

}  // namespace glint::detail
