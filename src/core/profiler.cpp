// Profiler: timestamps around the stages of a frame.
#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"

namespace glint {

using detail::concat;
using detail::vk_check;

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
