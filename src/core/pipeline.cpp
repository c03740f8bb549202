#include "core/pipeline.h"

#include <algorithm>
#include <array>
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

bool copy_order_by_default(const DeviceInfo& info) { return info.type != VK_PHYSICAL_DEVICE_TYPE_CPU; }

CompiledPipeline::~CompiledPipeline() {
  if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
  if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
}

namespace {

std::shared_ptr<CompiledPipeline> compile(const Context& context, const PipelineDesc& desc, const KernelBinary& bin) {
  ContextState& s = context.state();
  auto c = std::make_shared<CompiledPipeline>();  // destroys whatever was made if a step throws
  c->device = s.device;
  c->push_descriptor_set = s.cmd_push_descriptor_set;
  c->set_layout = make_push_set_layout(context, desc.bindings, VK_SHADER_STAGE_COMPUTE_BIT);
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
  if (s.kernel_statistics) cp.flags |= VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
  const VkResult r = vkCreateComputePipelines(s.device, VK_NULL_HANDLE, 1, &cp, nullptr, &c->pipeline);
  vkDestroyShaderModule(s.device, module, nullptr);
  vk_check(r, "vkCreateComputePipelines");
  s.count_object();
  return c;
}

}  // namespace

VkDescriptorSetLayout make_push_set_layout(const Context& context, const std::vector<VkDescriptorType>& types,
                                           VkShaderStageFlags stages) {
  const ContextState& s = context.state();
  const uint32_t limit = std::min(kMaxBindings, s.max_push_descriptors);
  if (types.size() > limit) {
    throw Error(ErrorCode::no_device,
                concat("a kernel pushes ", types.size(), " descriptors; device '", s.info.name, "' allows ",
                       s.max_push_descriptors, " (VkPhysicalDevicePushDescriptorPropertiesKHR::maxPushDescriptors)"));
  }
  std::array<VkDescriptorSetLayoutBinding, kMaxBindings> b{};
  for (uint32_t i = 0; i < types.size(); ++i) b[i] = {i, types[i], 1, stages, nullptr};
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  sl.bindingCount = static_cast<uint32_t>(types.size());
  sl.pBindings = b.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  vk_check(vkCreateDescriptorSetLayout(s.device, &sl, nullptr, &layout), "vkCreateDescriptorSetLayout");
  return layout;
}

void check_bindings(const std::vector<VkDescriptorType>& types, const Bindings& bindings, const std::string& who) {
  const uint32_t n = bindings.size();
  if (n != types.size()) {
    throw Error(ErrorCode::invalid_argument,
                concat("internal: ", who, " has ", types.size(), " bindings; ", n, " descriptors were given"));
  }
  for (uint32_t i = 0; i < n; ++i) {
    const Binding& b = bindings[i];
    if (types[i] == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || types[i] == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
      if (!b.buffer.buffer || b.buffer.size == 0) {
        throw Error(ErrorCode::invalid_argument,
                    concat("internal: ", who, " binding ", i, " needs a buffer and a size"));
      }
    } else {
      const bool sampler = types[i] == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
      if (!b.view || (sampler && !b.sampler)) {
        throw Error(ErrorCode::invalid_argument, concat("internal: ", who, " binding ", i,
                                                        sampler ? " needs a view and a sampler" : " needs a view"));
      }
    }
  }
}

void push_descriptors(PFN_vkCmdPushDescriptorSetKHR push, VkCommandBuffer cmd, VkPipelineBindPoint bind_point,
                      VkPipelineLayout layout, const std::vector<VkDescriptorType>& types, const Bindings& bindings,
                      const std::string& who) {
  check_bindings(types, bindings, who);
  const uint32_t n = bindings.size();
  // Everything lives on this stack frame until vkCmdPushDescriptorSetKHR has copied it (the
  // command records the descriptors themselves, Vulkan spec "Push Descriptor Updates").
  std::array<VkWriteDescriptorSet, kMaxBindings> writes;
  std::array<VkDescriptorImageInfo, kMaxBindings> images;
  std::array<VkDescriptorBufferInfo, kMaxBindings> buffers;
  for (uint32_t i = 0; i < n; ++i) {
    const Binding& b = bindings[i];
    VkWriteDescriptorSet& w = writes[i];
    w = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstBinding = i;
    w.descriptorCount = 1;
    w.descriptorType = types[i];
    if (types[i] == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || types[i] == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
      buffers[i] = {b.buffer.buffer, b.buffer.offset, b.buffer.size};
      w.pBufferInfo = &buffers[i];
    } else {
      images[i] = {b.sampler, b.view, b.layout};
      w.pImageInfo = &images[i];
    }
  }
  push(cmd, bind_point, layout, 0, n, writes.data());
}

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
  if (!slot) slot = compile(context, desc, *bin);
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

void ComputePipeline::bind_and_push(VkCommandBuffer cmd, const Bindings& bindings, const void* push,
                                    uint32_t bytes) const {
  if (bytes != push_bytes_) {
    throw Error(ErrorCode::invalid_argument,
                concat("kernel ", id_, ": push constants are ", bytes, " bytes, pipeline expects ", push_bytes_));
  }
  check_bindings(bindings_, bindings, id_);  // before anything is recorded
  count_recorded_command();
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, compiled_->pipeline);
  push_descriptors(compiled_->push_descriptor_set, cmd, VK_PIPELINE_BIND_POINT_COMPUTE, compiled_->layout, bindings_,
                   bindings, id_);
  if (bytes) vkCmdPushConstants(cmd, compiled_->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, push);
}

void ComputePipeline::dispatch_raw(VkCommandBuffer cmd, const Bindings& bindings, const void* push, uint32_t bytes,
                                   uint32_t width, uint32_t height) const {
  bind_and_push(cmd, bindings, push, bytes);
  vkCmdDispatch(cmd, (width + workgroup_.x - 1) / workgroup_.x, (height + workgroup_.y - 1) / workgroup_.y, 1);
}

}  // namespace glint::detail

namespace glint {

bool Context::kernel_statistics_enabled() const { return state().kernel_statistics; }

std::vector<KernelStatistics> Context::kernel_statistics() const {
  std::vector<KernelStatistics> out;
  detail::ContextState& s = state();
  if (!s.kernel_statistics) return out;
  const auto get_properties = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
      vkGetDeviceProcAddr(s.device, "vkGetPipelineExecutablePropertiesKHR"));
  const auto get_statistics = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(s.device, "vkGetPipelineExecutableStatisticsKHR"));
  if (!get_properties || !get_statistics) {
    throw Error(ErrorCode::vulkan_failure,
                "VK_KHR_pipeline_executable_properties is enabled but its commands are not loadable");
  }
  std::lock_guard<std::mutex> lock(s.pipeline_mutex);
  for (const auto& [key, slot] : s.pipelines) {
    // key: "pipeline|<kernel>|<workgroup>|<push bytes>|<specialization>|<bindings>" (ComputePipeline).
    const auto* c = static_cast<const detail::CompiledPipeline*>(slot.get());
    if (!c || !c->pipeline) continue;
    const size_t k0 = key.find('|') + 1, k1 = key.find('|', k0);
    VkPipelineInfoKHR info{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
    info.pipeline = c->pipeline;
    uint32_t n = 0;
    detail::vk_check(get_properties(s.device, &info, &n, nullptr), "vkGetPipelineExecutablePropertiesKHR");
    std::vector<VkPipelineExecutablePropertiesKHR> props(n, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR});
    detail::vk_check(get_properties(s.device, &info, &n, props.data()), "vkGetPipelineExecutablePropertiesKHR");
    for (uint32_t e = 0; e < n; ++e) {
      KernelStatistics ks;
      ks.kernel = key.substr(k0, k1 - k0);
      ks.variant = key.substr(k1 + 1);
      ks.executable = props[e].name;
      ks.subgroup_size = props[e].subgroupSize;
      VkPipelineExecutableInfoKHR ei{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
      ei.pipeline = c->pipeline;
      ei.executableIndex = e;
      uint32_t m = 0;
      detail::vk_check(get_statistics(s.device, &ei, &m, nullptr), "vkGetPipelineExecutableStatisticsKHR");
      std::vector<VkPipelineExecutableStatisticKHR> stats(m, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
      detail::vk_check(get_statistics(s.device, &ei, &m, stats.data()), "vkGetPipelineExecutableStatisticsKHR");
      for (uint32_t i = 0; i < m; ++i) {
        KernelStatistic st;
        st.name = stats[i].name;
        st.description = stats[i].description;
        switch (stats[i].format) {
          case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
            st.value = stats[i].value.b32 ? "true" : "false";
            break;
          case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
            st.value = std::to_string(stats[i].value.i64);
            break;
          case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
            st.value = std::to_string(stats[i].value.u64);
            break;
          default:
            st.value = detail::concat(stats[i].value.f64);
            break;
        }
        ks.statistics.push_back(std::move(st));
      }
      out.push_back(std::move(ks));
    }
  }
  return out;
}

}  // namespace glint
