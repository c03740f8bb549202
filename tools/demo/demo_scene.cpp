#include "demo/demo_scene.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/pipeline.h"
#include "demo/shaders/demo_params.h"
#include "support/tool_kernels.h"

namespace glint::demo {

static_assert(sizeof(StarfieldPush) == 48);

namespace {

struct DemoPipelines {
  detail::ComputePipeline pipeline;
};

// One per (context, format), owned by the context.
DemoPipelines& pipelines_for(const Context& context, VkFormat format) {
  const bool fp32 = format == VK_FORMAT_R32G32B32A32_SFLOAT;
  return context.state().cached<DemoPipelines>(fp32 ? "demo_starfield_rgba32f" : "demo_starfield_rgba16f", [&] {
    auto dp = std::make_shared<DemoPipelines>();
    detail::PipelineDesc d;
    d.kernel_id = fp32 ? "demo_starfield_rgba32f" : "demo_starfield_rgba16f";
    d.binary = tools::find_kernel(d.kernel_id.c_str());
    if (!d.binary) {
      throw Error(ErrorCode::vulkan_failure, detail::concat("kernel '", d.kernel_id, "' is not embedded in the tools"));
    }
    d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
    d.push_constant_bytes = sizeof(StarfieldPush);
    d.workgroup = detail::choose_workgroup_2d(context);
    dp->pipeline = detail::ComputePipeline(context, d);
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
    throw Error(ErrorCode::unsupported_format,
                detail::concat("record_starfield: target format is ", detail::format_name(target.format),
                               "; accepted RGBA16F or RGBA32F"));
  }
  if (!(target.usage & VK_IMAGE_USAGE_STORAGE_BIT)) {
    throw Error(ErrorCode::missing_usage, "record_starfield: target lacks VK_IMAGE_USAGE_STORAGE_BIT usage");
  }
  DemoPipelines& dp = pipelines_for(context, target.format);
  StarfieldPush p{};
  p.width = static_cast<int32_t>(target.extent.width);
  p.height = static_cast<int32_t>(target.extent.height);
  // Cells sized so that about `stars` of them hold a star at probability 0.8.
  const double area = double(target.extent.width) * target.extent.height;
  p.star_probability = 0.8f;
  p.cell_px = std::max(3, static_cast<int32_t>(std::lround(std::sqrt(area * 0.8 / params.stars))));
  p.variant = params.variant;
  p.min_brightness = params.min_brightness;
  p.max_brightness = params.max_brightness;
  p.sun_brightness = params.sun_brightness;
  p.sun_radius_px = std::max(1.0f, 0.025f * static_cast<float>(std::min(target.extent.width, target.extent.height)));
  p.sun_x = 0.68f * static_cast<float>(target.extent.width);
  p.sun_y = 0.32f * static_cast<float>(target.extent.height);
  detail::Barriers b;
  b.use(target, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.flush(cmd);
  dp.pipeline.dispatch(cmd, {{target.view, VK_IMAGE_LAYOUT_GENERAL}}, p, target.extent.width, target.extent.height);
  if (profiler) profiler->mark(cmd, "demo starfield");
}

namespace {

// Camera of the flare scene (a perspective with Vulkan's depth range [0, 1] and y down in NDC, so
// that world up is the top row: pixel = (ndc * 0.5 + 0.5) * size).
constexpr double kFovY = 1.0471975511965976;  // 60 degrees
constexpr double kNear = 0.1, kFar = 100.0;

struct Camera {
  double f, aspect, a, b;  // clip_z = a * z_view + b, clip_w = -z_view
  explicit Camera(VkExtent2D e)
      : f(1.0 / std::tan(kFovY / 2)),
        aspect(double(e.width) / e.height),
        a(kFar / (kNear - kFar)),
        b(kNear * kFar / (kNear - kFar)) {}
  // NDC depth of a point `distance` in front of the camera.
  double depth_at(double distance) const { return (a * -distance + b) / distance; }
  // World position of the point at pixel fraction (fx, fy) of the image, `distance` away.
  void unproject(double fx, double fy, double distance, float out[3]) const {
    const double nx = fx * 2 - 1, ny = fy * 2 - 1;
    out[0] = static_cast<float>(nx * distance * aspect / f);
    out[1] = static_cast<float>(-ny * distance / f);
    out[2] = static_cast<float>(-distance);
  }
};

}  // namespace

FlareScene make_flare_scene(VkExtent2D extent) {
  const Camera cam(extent);
  FlareScene s;
  s.view_proj = {};
  s.view_proj[0] = static_cast<float>(cam.f / cam.aspect);
  s.view_proj[5] = static_cast<float>(-cam.f);  // Vulkan: ndc.y = -1 is the top row
  s.view_proj[10] = static_cast<float>(cam.a);
  s.view_proj[11] = -1.0f;  // clip_w = -z_view
  s.view_proj[14] = static_cast<float>(cam.b);

  // Occluders: screen rectangles (fractions of the image) at a view distance.
  struct Box {
    double x0, y0, x1, y1, distance;
  };
  const Box boxes[] = {
      {0.10, 0.35, 0.30, 1.00, 8.0},   // left tower
      {0.55, 0.55, 0.80, 1.00, 12.0},  // right tower
      {0.38, 0.20, 0.48, 0.62, 5.0},   // pillar
  };
  const uint32_t w = extent.width, h = extent.height;
  s.depth.assign(size_t(w) * h, 1.0f);
  for (const Box& box : boxes) {
    const auto x0 = static_cast<uint32_t>(std::floor(box.x0 * w)), x1 = static_cast<uint32_t>(std::ceil(box.x1 * w));
    const auto y0 = static_cast<uint32_t>(std::floor(box.y0 * h)), y1 = static_cast<uint32_t>(std::ceil(box.y1 * h));
    const auto d = static_cast<float>(cam.depth_at(box.distance));
    if (std::min(x1, w) > x0 && std::min(y1, h) > y0) {
      s.occluders.push_back({{int32_t(x0), int32_t(y0)}, {std::min(x1, w) - x0, std::min(y1, h) - y0}});
    }
    for (uint32_t y = y0; y < std::min(y1, h); ++y) {
      for (uint32_t x = x0; x < std::min(x1, w); ++x) {
        float& v = s.depth[size_t(y) * w + x];
        v = std::min(v, d);
      }
    }
  }

  // Lights: pixel fraction, distance, colour, intensity, size at 1080 lines, element, enabled.
  struct Light {
    double fx, fy, distance;
    float r, g, b, intensity, size;
    uint32_t element;
    bool enabled;
  };
  const Light lights[] = {
      {0.68, 0.32, 90.0, 1.0f, 0.85f, 0.6f, 3.0f, 180.0f, GLINT_FLARE_ELEMENT_GLOW, true},     // on the sun
      {0.90, 0.15, 50.0, 0.6f, 0.8f, 1.0f, 2.5f, 90.0f, GLINT_FLARE_ELEMENT_STARBURST, true},  // sky
      {0.32, 0.12, 60.0, 1.0f, 0.7f, 0.9f, 2.0f, 70.0f, GLINT_FLARE_ELEMENT_HALO, true},       // sky
      {0.85, 0.45, 25.0, 0.7f, 1.0f, 0.8f, 2.0f, 60.0f, GLINT_FLARE_ELEMENT_GHOST, true},      // sky
      {0.22, 0.50, 4.0, 1.0f, 0.6f, 0.3f, 3.0f, 80.0f, GLINT_FLARE_ELEMENT_GLOW, true},        // before the left tower
      {0.70, 0.78, 6.0, 0.4f, 0.7f, 1.0f, 3.0f, 70.0f, GLINT_FLARE_ELEMENT_STREAK, true},      // before the right tower
      {0.20, 0.60, 30.0, 1.0f, 0.2f, 0.2f, 4.0f, 80.0f, GLINT_FLARE_ELEMENT_GLOW, true},       // behind the left tower
      {0.43, 0.40, 20.0, 0.2f, 1.0f, 0.2f, 4.0f, 60.0f, GLINT_FLARE_ELEMENT_GLOW, true},       // behind the pillar
      {0.62, 0.80, 40.0, 0.2f, 0.2f, 1.0f, 4.0f, 80.0f, GLINT_FLARE_ELEMENT_GLOW, true},       // behind the right tower
      {0.465, 0.30, 20.0, 1.0f, 1.0f, 0.6f, 2.5f, 100.0f, GLINT_FLARE_ELEMENT_GLOW, true},     // half behind the pillar
      {0.25, 0.35, 30.0, 1.0f, 0.5f, 0.8f, 2.5f, 90.0f, GLINT_FLARE_ELEMENT_HALO, true},       // on the tower's roof
      {1.25, 0.50, 20.0, 1.0f, 1.0f, 1.0f, 2.0f, 80.0f, GLINT_FLARE_ELEMENT_GLOW, true},       // off screen (culled)
      {0.05, 0.10, 30.0, 1.0f, 1.0f, 1.0f, 2.0f, 80.0f, GLINT_FLARE_ELEMENT_GLOW, false},      // disabled
  };
  const float scale = static_cast<float>(h) / 1080.0f;
  for (const Light& l : lights) {
    GlintFlareLight g{};
    cam.unproject(l.fx, l.fy, l.distance, &g.position_x);
    g.color_r = l.r;
    g.color_g = l.g;
    g.color_b = l.b;
    g.intensity = l.intensity;
    g.size_px = std::max(1.0f, l.size * scale);
    g.element = l.element;
    g.enabled = l.enabled ? 1u : 0u;
    s.lights.push_back(g);
  }
  GlintFlareLight behind{};  // behind the camera (w < 0): culled
  behind.position_z = 5.0f;
  behind.color_r = behind.color_g = behind.color_b = 1.0f;
  behind.intensity = 2.0f;
  behind.size_px = std::max(1.0f, 80.0f * scale);
  behind.enabled = 1;
  s.lights.push_back(behind);
  return s;
}

}  // namespace glint::demo
