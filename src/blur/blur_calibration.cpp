// measure_blur_cost_model() (docs/BLUR.md "Cost model"): the per-device constants of the cost model
// `auto` ranks GaussianBlur's methods by. A fixed cost model cannot serve every device: on an H100
// a dispatch (about 3 us with its barrier) outweighs a 401-tap separable blur of 512x512, while on
// lavapipe that blur takes 6 s and the pyramid 36 ms. So each standalone Context measures its
// device once: a few small blurs of each method, at two sizes (one where the dispatches dominate,
// one where the taps do), timed with timestamps, and the linear model fitted to them.
#include <glint/blur.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#include "blur/blur_plan.h"
#include "core/barriers.h"
#include "core/check.h"
#include "core/context_state.h"
#include "core/resources.h"

namespace glint {
namespace {

struct Case {
  BlurMethod method;
  float sigma_px;
  uint32_t small, large;  // square sizes: dispatch-bound, work-bound on a CPU device (x8 on a GPU)
};

// Each method at a sigma where it is a plausible choice, so the fit weighs the kernels as auto
// uses them: the fused separable (radius 6), the line separable (radius 32), the pyramid (two
// levels and its blur), the dual (three levels down and up), and the pyramid and the separable
// blur at sigma 4, where the two are closest. Without the last two the fit ranked the one-level
// pyramid ahead of the separable blur at sigma 4 on the H100, 1.41 to 1.83 times slower
// (docs/PERF.md, "GaussianBlur auto against the fastest method").
constexpr Case kCases[] = {{BlurMethod::separable, 1.5f, 32, 128}, {BlurMethod::separable, 8.0f, 32, 96},
                           {BlurMethod::pyramid, 8.0f, 32, 128},   {BlurMethod::dual, 8.0f, 32, 128},
                           {BlurMethod::pyramid, 4.0f, 32, 128},   {BlurMethod::separable, 4.0f, 32, 128}};
constexpr int kRepeats = 3;  // the fastest of these counts (the first may start cold)

blur_plan::Method plan_method_of(BlurMethod m) {
  return m == BlurMethod::pyramid ? blur_plan::Method::pyramid
         : m == BlurMethod::dual  ? blur_plan::Method::dual
                                  : blur_plan::Method::separable;
}

// Records a clear of `image` to `value` (the inputs must hold defined values; the library's own
// barrier tracking, as every glint recording).
void record_clear(VkCommandBuffer cmd, Image& image, float value) {
  detail::Barriers b;
  b.use(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  b.flush(cmd);
  VkClearColorValue color{};
  for (float& c : color.float32) c = value;
  const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, image.base_array_layer, 1};
  vkCmdClearColorImage(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &color, 1, &range);
}

// The fastest of kRepeats runs of `blur` on `size`, in microseconds.
double time_blur(const Context& context, GaussianBlur& blur, VkExtent2D size) {
  detail::OwnedImage in(context, size, VK_FORMAT_R16G16B16A16_SFLOAT,
                        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  detail::OwnedImage out(context, size, VK_FORMAT_R16G16B16A16_SFLOAT,
                         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  double best = std::numeric_limits<double>::infinity();
  if (context.info().timestamps_supported) {
    Profiler profiler(context, kRepeats + 1);
    context.run_once([&](VkCommandBuffer cmd) {
      profiler.reset(cmd);
      record_clear(cmd, in.state, 0.5f);
      record_clear(cmd, out.state, 0.0f);
      profiler.mark(cmd, "start");
      for (int r = 0; r < kRepeats; ++r) {
        blur.record(cmd, in.state, out.state);
        profiler.mark(cmd, "blur");
      }
    });
    for (const Profiler::Stage& s : profiler.results()) best = std::min(best, s.ms * 1e3);
  }
  if (!std::isfinite(best) || best <= 0.0) {  // no timestamps: the wall clock of a submission
    context.run_once([&](VkCommandBuffer cmd) {
      record_clear(cmd, in.state, 0.5f);
      record_clear(cmd, out.state, 0.0f);
    });
    for (int r = 0; r < kRepeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      context.run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
      best = std::min(best, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  return std::max(best, 1e-3);
}

}  // namespace

BlurCostModel measure_blur_cost_model(const Context& context) {
  if (context.is_adopted()) {
    throw Error(ErrorCode::invalid_argument,
                "measure_blur_cost_model: an adopted context never submits; measure on a standalone Context of "
                "the same device and pass the result in GaussianBlurConfig::cost_model");
  }
  detail::ContextState& state = context.state();
  {
    std::lock_guard<std::mutex> lock(state.blur_cost_mutex);
    if (state.blur_cost_measured)
      return {state.blur_cost[0], state.blur_cost[1], state.blur_cost[2], state.blur_cost[3]};
  }
  // Measured without the lock (it submits, and a thread inside run_once() may plan a blur): two
  // threads may both measure; the first result is kept.
  blur_plan::Storage storage;  // what the blurs below store: RGBA16F levels and output
  storage.level_unit = storage.output_unit = blur_plan::store_unit(10);
  storage.level_half = storage.output_half = true;
  storage.sub_texel_bits = context.info().sub_texel_precision_bits;
  std::vector<blur_plan::Work> work;
  std::vector<double> measured;
  // A GPU needs larger images than a CPU device before the work outweighs a dispatch (at 128x128
  // an H100 is still dispatch-bound, and the per-tap constants would be guesses).
  const uint32_t scale = context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 1 : 8;
  for (const Case& c : kCases) {
    GaussianBlurConfig config;
    config.method = c.method;
    config.sigma_px = c.sigma_px;
    GaussianBlur blur(context, config);
    for (uint32_t n : {c.small, c.large * scale}) {
      const VkExtent2D size{n, n};
      blur.prepare(size);
      work.push_back(
          blur_plan::plan_method(plan_method_of(c.method), c.sigma_px, n, n, config.max_relative_error, storage).work);
      measured.push_back(time_blur(context, blur, size));
    }
  }
  const blur_plan::CostModel fit = blur_plan::fit_cost_model(work, measured);
  std::lock_guard<std::mutex> lock(state.blur_cost_mutex);
  if (!state.blur_cost_measured) {
    state.blur_cost[0] = fit.us_per_dispatch;
    state.blur_cost[1] = fit.us_per_byte;
    state.blur_cost[2] = fit.us_per_shared_tap;
    state.blur_cost[3] = fit.us_per_fetch_tap;
    state.blur_cost_measured = true;
  }
  return {state.blur_cost[0], state.blur_cost[1], state.blur_cost[2], state.blur_cost[3]};
}

}  // namespace glint
