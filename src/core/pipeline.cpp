#include "core/pipeline.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>

#include "core/barriers.h"
#include "core/context_state.h"
#include "core/kernel_table.h"

namespace glint::detail {

Workgroup2D choose_workgroup_2d(const Context& context) {
  const DeviceInfo& info = context.info();
  // ContextOptions::workgroup_2d overrides the choice (checked when the context was made).
  const VkExtent2D forced = context.state().workgroup_2d;
  if (forced.width != 0) return {forced.width, forced.height};
  // CPU devices (lavapipe) run a workgroup per thread with 8-wide SIMD: 8x8 keeps groups small
  // enough to spread over cores. GPUs with 32/64-wide subgroups get 16x8: on an H100 it beat 8x8,
  // 16x16 and 32x8 for the bloom chain (docs/PERF.md), as a compromise between the shared-memory
  // apron (smaller groups re-read more) and occupancy (larger tiles hold more shared memory).
  if (info.type != VK_PHYSICAL_DEVICE_TYPE_CPU && info.max_workgroup_invocations >= 128 && info.subgroup_size >= 32) {
    return {16, 8};
  }
  return {8, 8};
}

CompiledPipeline::~CompiledPipeline() {
  if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
  if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
}

namespace {

std::shared_ptr<CompiledPipeline> compile(ContextState& s, const PipelineDesc& desc, const KernelBinary& bin) {
  auto c = std::make_shared<CompiledPipeline>();  // destroys whatever was made if a step throws
  c->device = s.device;
  std::vector<VkDescriptorSetLayoutBinding> b(desc.bindings.size());
  for (uint32_t i = 0; i < b.size(); ++i) b[i] = {i, desc.bindings[i], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.bindingCount = static_cast<uint32_t>(b.size());
  sl.pBindings = b.data();
  vk_check(vkCreateDescriptorSetLayout(s.device, &sl, nullptr, &c->set_layout), "vkCreateDescriptorSetLayout");
  s.count_object();

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc.push_constant_bytes};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &c->set_layout;
  pl.pushConstantRangeCount = desc.push_constant_bytes ? 1 : 0;
  pl.pPushConstantRanges = &range;
  vk_check(vkCreatePipelineLayout(s.device, &pl, nullptr, &c->layout), "vkCreatePipelineLayout");
  s.count_object();

  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = bin.size_bytes;
  sm.pCode = bin.code;
  VkShaderModule module = VK_NULL_HANDLE;
  vk_check(vkCreateShaderModule(s.device, &sm, nullptr, &module), "vkCreateShaderModule");

  std::vector<uint32_t> values = {desc.workgroup.x, desc.workgroup.y};
  values.insert(values.end(), desc.specialization.begin(), desc.specialization.end());
  std::vector<VkSpecializationMapEntry> entries(values.size());
  for (uint32_t i = 0; i < values.size(); ++i) entries[i] = {i, i * 4u, 4u};
  VkSpecializationInfo spec{static_cast<uint32_t>(entries.size()), entries.data(), values.size() * 4, values.data()};

  VkComputePipelineCreateInfo cp{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  cp.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  cp.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cp.stage.module = module;
  cp.stage.pName = "main";
  cp.stage.pSpecializationInfo = &spec;
  cp.layout = c->layout;
  const VkResult r = vkCreateComputePipelines(s.device, VK_NULL_HANDLE, 1, &cp, nullptr, &c->pipeline);
  vkDestroyShaderModule(s.device, module, nullptr);
  vk_check(r, "vkCreateComputePipelines");
  s.count_object();
  return c;
}

}  // namespace

ComputePipeline::ComputePipeline(const Context& context, const PipelineDesc& desc) {
  id_ = desc.kernel_id;
  push_bytes_ = desc.push_constant_bytes;
  workgroup_ = desc.workgroup;
  bindings_ = desc.bindings;
  const KernelBinary* bin = desc.binary ? desc.binary : find_kernel(desc.kernel_id.c_str());
  if (!bin)
    throw Error(ErrorCode::vulkan_failure, concat("kernel '", desc.kernel_id, "' is not embedded in this build"));
  // Everything that makes the compiled objects differ is in the key.
  std::string key = concat("pipeline|", desc.kernel_id, "|", desc.workgroup.x, "x", desc.workgroup.y, "|",
                           desc.push_constant_bytes, "|");
  for (uint32_t v : desc.specialization) key += concat(v, ",");
  key += "|";
  for (VkDescriptorType t : desc.bindings) key += concat(static_cast<int>(t), ",");
  auto& s = context.state();
  std::lock_guard<std::mutex> lock(s.pipeline_mutex);
  auto& slot = s.pipelines[key];
  if (!slot) slot = compile(s, desc, *bin);
  compiled_ = static_cast<const CompiledPipeline*>(slot.get());
}

ComputePipeline& ComputePipeline::operator=(ComputePipeline&& o) noexcept {
  if (this != &o) {
    compiled_ = std::exchange(o.compiled_, nullptr);
    id_ = std::move(o.id_);
    push_bytes_ = o.push_bytes_;
    workgroup_ = o.workgroup_;
    bindings_ = std::move(o.bindings_);
  }
  return *this;
}

void ComputePipeline::bind_and_push(VkCommandBuffer cmd, VkDescriptorSet set, const void* push, uint32_t bytes) const {
  if (bytes != push_bytes_) {
    throw Error(ErrorCode::invalid_argument,
                concat("kernel ", id_, ": push constants are ", bytes, " bytes, pipeline expects ", push_bytes_));
  }
  count_recorded_command();
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, compiled_->pipeline);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, compiled_->layout, 0, 1, &set, 0, nullptr);
  if (bytes) vkCmdPushConstants(cmd, compiled_->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, push);
}

void ComputePipeline::dispatch_raw(VkCommandBuffer cmd, VkDescriptorSet set, const void* push, uint32_t bytes,
                                   uint32_t width, uint32_t height) const {
  bind_and_push(cmd, set, push, bytes);
  vkCmdDispatch(cmd, (width + workgroup_.x - 1) / workgroup_.x, (height + workgroup_.y - 1) / workgroup_.y, 1);
}

DescriptorArena::DescriptorArena(const Context& context, uint32_t sets_per_pool, uint32_t per_type)
    : context_(&context), sets_per_pool_(std::max(1u, sets_per_pool)), per_type_(std::max(1u, per_type)) {}

DescriptorArena& DescriptorArena::operator=(DescriptorArena&& o) noexcept {
  if (this != &o) {
    reset();
    context_ = std::exchange(o.context_, nullptr);
    sets_per_pool_ = o.sets_per_pool_;
    per_type_ = o.per_type_;
    left_ = std::exchange(o.left_, 0);
    pools_ = std::move(o.pools_);
    o.pools_.clear();
  }
  return *this;
}

void DescriptorArena::reset() {
  if (context_)
    for (VkDescriptorPool p : pools_) vkDestroyDescriptorPool(context_->device(), p, nullptr);
  pools_.clear();
  left_ = 0;
}

VkDescriptorSet DescriptorArena::make_set(const ComputePipeline& pipeline, const std::vector<ImageBinding>& images) {
  std::vector<AnyBinding> bindings(images.size());
  for (size_t i = 0; i < images.size(); ++i) bindings[i].image = images[i];
  return make_mixed_set(pipeline, bindings);
}

VkDescriptorSet DescriptorArena::make_buffer_set(const ComputePipeline& pipeline, const std::vector<Buffer>& buffers) {
  std::vector<AnyBinding> bindings(buffers.size());
  for (size_t i = 0; i < buffers.size(); ++i) bindings[i].buffer = buffers[i];
  return make_mixed_set(pipeline, bindings);
}

VkDescriptorSet DescriptorArena::make_mixed_set(VkDescriptorSetLayout layout,
                                                const std::vector<VkDescriptorType>& types,
                                                const std::vector<AnyBinding>& bindings) {
  if (bindings.size() != types.size()) {
    throw Error(ErrorCode::invalid_argument,
                concat("descriptor set: ", bindings.size(), " bindings for ", types.size()));
  }
  for (VkDescriptorType t : types) {
    if (uint32_t(std::count(types.begin(), types.end(), t)) > per_type_) {
      throw Error(ErrorCode::invalid_argument,
                  concat("descriptor set: more descriptors of one type than the arena's ", per_type_, " per set"));
    }
  }
  const VkDevice device = context_->device();
  if (left_ == 0) {
    const uint32_t n = sets_per_pool_;
    VkDescriptorPoolSize sizes[] = {
        {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, n * per_type_},
        {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, n * per_type_},
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, n * per_type_},
        {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, n * per_type_},
    };
    VkDescriptorPoolCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    info.maxSets = n;
    info.poolSizeCount = 4;
    info.pPoolSizes = sizes;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    vk_check(vkCreateDescriptorPool(device, &info, nullptr, &pool), "vkCreateDescriptorPool");
    context_->state().count_object();
    pools_.push_back(pool);
    left_ = n;
  }
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = pools_.back();
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  vk_check(vkAllocateDescriptorSets(device, &alloc, &set), "vkAllocateDescriptorSets");
  context_->state().count_object();
  --left_;

  std::vector<VkDescriptorImageInfo> images(bindings.size());
  std::vector<VkDescriptorBufferInfo> buffers(bindings.size());
  std::vector<VkWriteDescriptorSet> writes(bindings.size());
  for (uint32_t i = 0; i < bindings.size(); ++i) {
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = types[i];
    if (bindings[i].buffer.buffer) {
      buffers[i] = {bindings[i].buffer.buffer, bindings[i].buffer.offset, bindings[i].buffer.size};
      writes[i].pBufferInfo = &buffers[i];
    } else {
      images[i] = {bindings[i].sampler, bindings[i].image.view, bindings[i].image.layout};
      writes[i].pImageInfo = &images[i];
    }
  }
  vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  return set;
}

}  // namespace glint::detail
