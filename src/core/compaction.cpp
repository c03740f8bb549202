// The ordered compaction's host side (core/compaction.h).
#include "core/compaction.h"

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/check.h"
#include "core/context_state.h"

namespace glint::detail {

static_assert(sizeof(GlintCompactPush) == 32);
static_assert(offsetof(GlintCompactPush, step) == 16);
static_assert(GLINT_COMPACT_GROUP == 64, "compact.glsl keeps a group's mask in two 32-bit words");

namespace {
constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kRead = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
constexpr VkAccessFlags2 kWrite = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
constexpr uint32_t kGroup = GLINT_COMPACT_GROUP;
}  // namespace

Compaction::Compaction(const Context& context, const Desc& desc) {
  if (desc.scan_outputs > kMaxBuffers || desc.scatter_inputs + desc.scatter_outputs > kMaxBuffers) {
    throw Error(ErrorCode::invalid_argument, concat("Compaction: at most ", kMaxBuffers, " buffers per kernel"));
  }
  if (desc.scatter_groups < 1) throw Error(ErrorCode::invalid_argument, "Compaction: scatter_groups must be >= 1");
  scatter_groups_ = desc.scatter_groups;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context.physical_device(), &props);
  max_groups_x_ = props.limits.maxComputeWorkGroupCount[0];
  // The scan's workgroup size, from the device (CONTRIBUTING.md, "Device limits"). CPU devices
  // (lavapipe) run a workgroup's invocations a few at a time and pay for every barrier per
  // invocation: 64 there, where longer serial runs per invocation cost little.
  const uint32_t cap = context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 64u : GLINT_COMPACT_SCAN_MAX_THREADS;
  scan_threads_ = std::min({cap, props.limits.maxComputeWorkGroupInvocations, props.limits.maxComputeWorkGroupSize[0]});
  const auto B = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  PipelineDesc d;
  d.kernel_id = "compact_scan_tiles_main";
  d.bindings = {B};
  d.push_constant_bytes = sizeof(GlintCompactPush);
  d.workgroup = {scan_threads_, 1};
  if (!desc.scan_kernel.empty()) {
    scan_tiles_ = ComputePipeline(context, d);
    d.kernel_id = desc.scan_kernel;
    d.bindings.assign(1 + desc.scan_outputs, B);
    scan_ = ComputePipeline(context, d);
  }
  d.kernel_id = desc.scatter_kernel;
  d.bindings.assign(1 + desc.scatter_inputs + desc.scatter_outputs, B);
  d.workgroup = {kGroup, 1};
  scatter_ = ComputePipeline(context, d);
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize group_count = (VkDeviceSize(desc.max_items) + kGroup - 1) / kGroup;
  groups_ = OwnedBuffer(context, GLINT_COMPACT_HEADER_WORDS * 4 + group_count * 16, usage, false);
  groups_state_.buffer = groups_.buffer();
  groups_state_.size = groups_.size();
  groups_state_.usage = usage;
}

void Compaction::record_clear_once(VkCommandBuffer cmd, Barriers& b) {
  if (counters_cleared_) return;
  record_zero_fill(cmd, b, groups_state_, GLINT_COMPACT_HEADER_WORDS * 4);
  counters_cleared_ = true;
}

void Compaction::record_scan(VkCommandBuffer cmd, Barriers& b, GlintCompactPush push,
                             std::initializer_list<Buffer*> outputs) {
  // The top-level scan's descriptors: the group buffer, then the user's outputs.
  Bindings top{groups_state_};
  for (Buffer* o : outputs) top.push_back(*o);
  push.tile_groups = scan_threads_;
  const uint32_t group_count = (push.count + kGroup - 1) / kGroup;
  const uint32_t tiles = (group_count + scan_threads_ - 1) / scan_threads_;
  if (!scan_) throw Error(ErrorCode::invalid_argument, "Compaction::record_scan: no scan kernel was given");
  // 1. Tiles of scan_threads groups in parallel: slots within each tile, tile totals.
  if (group_count > 0) {
    b.use(groups_state_, kCompute, kRead | kWrite);
    b.flush(cmd);
    scan_tiles_.dispatch(cmd, {groups_state_}, push, tiles * scan_threads_, 1);
  }
  // 2. One workgroup: the tiles' first slots, then the user's outputs.
  b.use(groups_state_, kCompute, kRead | kWrite);
  for (Buffer* o : outputs) b.use(*o, kCompute, kWrite);
  b.flush(cmd);
  scan_.dispatch(cmd, top, push, scan_threads_, 1);
}

void Compaction::record_scatter(VkCommandBuffer cmd, Barriers& b, GlintCompactPush push,
                                std::initializer_list<Buffer*> inputs, std::initializer_list<Buffer*> outputs) {
  // The scatter's descriptors: the group buffer, the user's inputs, then its outputs.
  Bindings set{groups_state_};
  for (Buffer* in : inputs) set.push_back(*in);
  for (Buffer* o : outputs) set.push_back(*o);
  // Workgroups of scatter_groups groups each, as a 2D grid of at most maxComputeWorkGroupCount[0] per row.
  const uint32_t workgroups =
      std::max(1u, ((push.count + kGroup - 1) / kGroup + scatter_groups_ - 1) / scatter_groups_);
  const uint32_t gx = std::min(workgroups, max_groups_x_);
  const uint32_t gy = (workgroups + gx - 1) / gx;
  push.tile_groups = scan_threads_;
  push.groups_x = gx;
  b.use(groups_state_, kCompute, kRead);
  for (Buffer* in : inputs) b.use(*in, kCompute, kRead);
  for (Buffer* o : outputs) b.use(*o, kCompute, kWrite);
  b.flush(cmd);
  scatter_.dispatch(cmd, set, push, gx * kGroup, gy);
}

}  // namespace glint::detail
