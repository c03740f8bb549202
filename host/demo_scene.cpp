#include "demo_scene.h"

#include <cmath>
#include <map>
#include <memory>

#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/pipeline.h"
#include "demo_params.h"

namespace glint::demo {

static_assert(sizeof(StarfieldPush) == 48);

namespace {

struct DemoPipelines {
  detail::ComputePipeline pipeline;
  detail::DescriptorArena arena;
  std::map<VkImageView, VkDescriptorSet> sets;
};

// One per (context, format), owned by the context.
DemoPipelines& pipelines_for(const Context& context, VkFormat format) {
  const bool fp32 = format == VK_FORMAT_R32G32B32A32_SFLOAT;
  return context.state().cached<DemoPipelines>(fp32 ? "demo_starfield_rgba32f" : "demo_starfield_rgba16f", [&] {
    auto dp = std::make_shared<DemoPipelines>();
    detail::PipelineDesc d;
    d.kernel_id = fp32 ? "demo_starfield_rgba32f" : "demo_starfield_rgba16f";
    d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
    d.push_constant_bytes = sizeof(StarfieldPush);
    d.workgroup = detail::choose_workgroup_2d(context.info());
    dp->pipeline = detail::ComputePipeline(context, d);
    dp->arena = detail::DescriptorArena(context, 16);
    return dp;
  });
}

}  // namespace

void record_starfield(const Context& context, VkCommandBuffer cmd, Image& target, const StarfieldParams& params,
                      Profiler* profiler) {
  detail::check_range("StarfieldParams::stars", params.stars, 1, 1e6);
  detail::check_range("StarfieldParams::min_brightness", params.min_brightness, 1e-6, 1e4);
  detail::check_range("StarfieldParams::max_brightness", params.max_brightness, params.min_brightness, 1e4);
  detail::check_range("StarfieldParams::sun_brightness", params.sun_brightness, 10, 100);
  if (target.format != VK_FORMAT_R16G16B16A16_SFLOAT && target.format != VK_FORMAT_R32G32B32A32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format, detail::concat("record_starfield: target format is ",
                                                              detail::format_name(target.format),
                                                              "; accepted RGBA16F or RGBA32F"));
  }
  if (!(target.usage & VK_IMAGE_USAGE_STORAGE_BIT)) {
    throw Error(ErrorCode::missing_usage, "record_starfield: target lacks VK_IMAGE_USAGE_STORAGE_BIT usage");
  }
  DemoPipelines& dp = pipelines_for(context, target.format);
  auto it = dp.sets.find(target.view);
  if (it == dp.sets.end()) {
    it = dp.sets.emplace(target.view, dp.arena.make_set(dp.pipeline, {{target.view, VK_IMAGE_LAYOUT_GENERAL}})).first;
  }
  StarfieldPush p{};
  p.width = static_cast<int32_t>(target.extent.width);
  p.height = static_cast<int32_t>(target.extent.height);
  // Cells sized so that about `stars` of them hold a star at probability 0.8.
  const double area = double(target.extent.width) * target.extent.height;
  p.star_probability = 0.8f;
  p.cell_px = std::max(3, static_cast<int32_t>(std::lround(std::sqrt(area * 0.8 / params.stars))));
  p.seed = params.seed;
  p.min_brightness = params.min_brightness;
  p.max_brightness = params.max_brightness;
  p.sun_brightness = params.sun_brightness;
  p.sun_radius_px = std::max(1.0f, 0.025f * static_cast<float>(std::min(target.extent.width, target.extent.height)));
  p.sun_x = 0.68f * static_cast<float>(target.extent.width);
  p.sun_y = 0.32f * static_cast<float>(target.extent.height);
  detail::Barriers b;
  b.use(target, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.flush(cmd);
  dp.pipeline.dispatch(cmd, it->second, p, target.extent.width, target.extent.height);
  if (profiler) profiler->mark(cmd, "demo starfield");
}

}  // namespace glint::demo
