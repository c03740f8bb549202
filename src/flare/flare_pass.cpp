// LensFlarePass: HiZPyramid + LightCuller + LensFlare and the buffers between them
// (include/glint/flare_pass.h). Nothing here is new GPU work: the cull is told the draw's
// vertices_per_instance() and groups_per_instance() (docs/FLARE.md, "Interface with the visibility
// stage"), and each part writes its own barriers from the buffers' state fields, so the frame is
// Hi-Z -> cull (one dispatch for few lights, else cull, scan, scatter) -> draw on one command
// buffer with no readback; no Hi-Z where the cull reads the depth image itself (few lights, a
// shallow pyramid: LightCuller::needs_pyramid).
#include <glint/flare_pass.h>
#include <glint/gpu/flare_types.h>

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/context_state.h"
#include "core/resources.h"

namespace glint {

using detail::concat;

void FlarePassConfig::validate() const {
  if (extent.width < 1 || extent.width > 16384 || extent.height < 1 || extent.height > 16384) {
    throw Error(ErrorCode::unsupported_size, concat("FlarePassConfig::extent = ", extent.width, "x", extent.height,
                                                    " is out of range: accepted 1 to 16384 on a side"));
  }
  if (color_format != VK_FORMAT_R16G16B16A16_SFLOAT && color_format != VK_FORMAT_R32G32B32A32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("FlarePassConfig::color_format = ", detail::format_name(color_format),
                       " is not accepted: RGBA16F or RGBA32F"));
  }
  if (depth_format != VK_FORMAT_D32_SFLOAT && depth_format != VK_FORMAT_R32_SFLOAT) {
    throw Error(ErrorCode::unsupported_format,
                concat("FlarePassConfig::depth_format = ", detail::format_name(depth_format),
                       " is not accepted: VK_FORMAT_D32_SFLOAT or VK_FORMAT_R32_SFLOAT"));
  }
  if (max_size_px != 0.0f) detail::check_range("FlarePassConfig::max_size_px", max_size_px, 1.0, 65536.0);
  detail::check_enum("FlarePassConfig::draw", draw, 2, "FlareDrawPath", "raster, compute");
  cull.validate();
}

namespace {

constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

// The config, validated, and the raster path's needs checked against the context before any part
// is made: LensFlare::record_raster would refuse them only after record() had recorded the Hi-Z
// and the cull.
FlarePassConfig validated(const Context& ctx, const FlarePassConfig& c) {
  c.validate();
  if (c.draw != FlareDrawPath::raster) return c;
  const detail::ContextState& s = ctx.state();
  if (!s.dynamic_rendering) {
    throw Error(ErrorCode::no_device,
                "FlarePassConfig::draw = raster needs VkPhysicalDeviceVulkan13Features::dynamicRendering, which is not "
                "enabled on the device; enable it or use FlareDrawPath::compute");
  }
  if (!s.graphics_queue) {
    throw Error(ErrorCode::no_device, concat("FlarePassConfig::draw = raster needs a graphics queue; queue family ",
                                             ctx.queue_family_index(), " has none; use FlareDrawPath::compute"));
  }
  return c;
}

HiZConfig hiz_config(const FlarePassConfig& c) {
  HiZConfig h;
  h.extent = c.extent;
  h.format = c.depth_format;
  h.reversed_z = c.reversed_z;
  if (c.max_size_px > 0.0f) {
    const double cell = std::ceil(double(c.max_size_px) / c.cull.grid);
    h.max_cell_px = static_cast<uint32_t>(std::clamp(cell, 1.0, 16384.0));
  }
  return h;
}

struct OwnedView {
  detail::OwnedBuffer owned;
  Buffer view;
  OwnedView() = default;
  OwnedView(const Context& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage)
      : owned(ctx, bytes, usage, false), view{owned.buffer(),  0, bytes, usage, VK_PIPELINE_STAGE_2_NONE,
                                              VK_ACCESS_2_NONE} {}
};

}  // namespace

// The cull settings with the compute path's capacity limit applied (or refused).
LightCullConfig cull_config(const FlarePassConfig& c, const LensFlare& flare) {
  LightCullConfig cull = c.cull;
  if (c.draw != FlareDrawPath::compute) return cull;
  const uint32_t limit = flare.max_compute_instances();
  if (c.clamp_capacity) cull.capacity = std::min(cull.capacity, limit);
  if (cull.capacity > limit) {
    throw Error(ErrorCode::invalid_argument,
                concat("FlarePassConfig::cull.capacity = ", cull.capacity,
                       " is out of range for the compute path on this device: accepted 1 to ", limit,
                       " (LensFlare::max_compute_instances())"));
  }
  return cull;
}

struct LensFlarePass::Impl {
  FlarePassConfig config;
  LensFlare flare;  // first: the cull's capacity depends on it
  HiZPyramid hiz;
  LightCuller culler;
  OwnedView instances, indirect, stats, results;
  Buffer no_results;

  Impl(const Context& ctx, const FlarePassConfig& c)
      : config(validated(ctx, c)),
        flare(ctx, c.color_format, c.extent),
        hiz(ctx, hiz_config(c)),
        culler(ctx, cull_config(c, flare)) {
    config.cull = culler.config();
    // Every limit a frame could hit is checked here, not in record().
    if (flare.groups_per_instance() > culler.max_groups_per_instance()) {
      throw Error(ErrorCode::invalid_argument,
                  concat("FlarePassConfig::cull.capacity = ", config.cull.capacity,
                         " is out of range on this device: its flare dispatch needs ", flare.groups_per_instance(),
                         " workgroups per instance and the device allows ", culler.max_groups_per_instance()));
    }
    instances = OwnedView(ctx, VkDeviceSize(config.cull.capacity) * sizeof(GlintFlareInstance), kStorage);
    indirect = OwnedView(ctx, sizeof(GlintFlareIndirect), kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    stats = OwnedView(ctx, sizeof(GlintFlareStats), kStorage);
    if (c.per_light_results) {
      results = OwnedView(ctx, VkDeviceSize(config.cull.max_lights) * sizeof(GlintFlareLightResult), kStorage);
    }
  }
};

LensFlarePass::LensFlarePass(const Context& context, const FlarePassConfig& config)
    : impl_(std::make_unique<Impl>(context, config)) {}
LensFlarePass::LensFlarePass(LensFlarePass&&) noexcept = default;
LensFlarePass& LensFlarePass::operator=(LensFlarePass&&) noexcept = default;
LensFlarePass::~LensFlarePass() = default;

void LensFlarePass::record(VkCommandBuffer cmd, Image& color, Image& depth, Buffer& lights, uint32_t count,
                           const float view_proj[16], const FlareConfig& look, Profiler* profiler) {
  detail::check_command_buffer("LensFlarePass::record", cmd);
  Impl& m = *impl_;
  // Everything the parts would reject later is checked first, so a throw records nothing.
  if (view_proj == nullptr) throw Error(ErrorCode::invalid_argument, "LensFlarePass::record: view_proj is null");
  look.validate();
  if (color.format != m.config.color_format || color.extent.width != m.config.extent.width ||
      color.extent.height != m.config.extent.height) {
    throw Error(ErrorCode::invalid_argument,
                concat("LensFlarePass::record: color is ", detail::format_name(color.format), " ", color.extent.width,
                       "x", color.extent.height, "; the pass was made for ", detail::format_name(m.config.color_format),
                       " ", m.config.extent.width, "x", m.config.extent.height));
  }
  const VkImageUsageFlags needed =
      m.config.draw == FlareDrawPath::raster ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT : VK_IMAGE_USAGE_STORAGE_BIT;
  if (!(color.usage & needed)) {
    throw Error(ErrorCode::missing_usage,
                concat("LensFlarePass::record: color lacks ",
                       m.config.draw == FlareDrawPath::raster ? "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT (raster path)"
                                                              : "VK_IMAGE_USAGE_STORAGE_BIT (compute path)",
                       " usage"));
  }
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(view_proj[i])) {
      throw Error(ErrorCode::invalid_argument,
                  concat("LensFlarePass::record: view_proj[", i, "] = ", view_proj[i], " is not finite"));
    }
  }
  if (depth.format != m.config.depth_format || depth.extent.width != m.config.extent.width ||
      depth.extent.height != m.config.extent.height) {
    throw Error(ErrorCode::invalid_argument,
                concat("LensFlarePass::record: depth is ", detail::format_name(depth.format), " ", depth.extent.width,
                       "x", depth.extent.height, "; the pass was made for ", detail::format_name(m.config.depth_format),
                       " ", m.config.extent.width, "x", m.config.extent.height));
  }
  if (!(depth.usage & VK_IMAGE_USAGE_SAMPLED_BIT)) {
    throw Error(ErrorCode::missing_usage, "LensFlarePass::record: depth lacks VK_IMAGE_USAGE_SAMPLED_BIT usage");
  }
  if (count > m.config.cull.max_lights) {
    throw Error(ErrorCode::invalid_argument,
                concat("LensFlarePass::record: count = ", count,
                       " is out of range: accepted 0 to cull.max_lights = ", m.config.cull.max_lights));
  }
  detail::check_buffer("LensFlarePass::record", "lights", lights,
                       std::max<VkDeviceSize>(1, VkDeviceSize(count) * sizeof(GlintFlareLight)),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  LightCullFrame frame;
  std::copy(view_proj, view_proj + 16, frame.view_proj);
  frame.vertex_count = LensFlare::vertices_per_instance();
  frame.groups_per_instance = m.flare.groups_per_instance();
  LightCullOutputs out{m.instances.view, m.indirect.view, m.stats.view,
                       m.config.per_light_results ? m.results.view : Buffer{}};
  // Few lights read their samples' windows from the depth image itself (the same answers):
  // building the pyramid would cost more than the cull reads (LightCuller::needs_pyramid).
  if (m.culler.needs_pyramid(m.hiz, count)) m.hiz.record(cmd, depth, profiler);
  m.culler.record(cmd, m.hiz, depth, lights, count, frame, out, profiler);
  m.instances.view = out.instances;
  m.indirect.view = out.indirect;
  m.stats.view = out.stats;
  if (m.config.per_light_results) m.results.view = out.results;
  if (m.config.draw == FlareDrawPath::raster) {
    m.flare.record_raster(cmd, color, m.instances.view, m.indirect.view, look, profiler);
  } else {
    m.flare.record_compute(cmd, color, m.instances.view, m.indirect.view, look, profiler);
  }
}

Buffer& LensFlarePass::stats() { return impl_->stats.view; }
Buffer& LensFlarePass::results() { return impl_->config.per_light_results ? impl_->results.view : impl_->no_results; }
Buffer& LensFlarePass::instances() { return impl_->instances.view; }
Buffer& LensFlarePass::indirect() { return impl_->indirect.view; }
HiZPyramid& LensFlarePass::hiz() { return impl_->hiz; }
LightCuller& LensFlarePass::culler() { return impl_->culler; }
LensFlare& LensFlarePass::flare() { return impl_->flare; }
const FlarePassConfig& LensFlarePass::config() const { return impl_->config; }

}  // namespace glint
