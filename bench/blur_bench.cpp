// Blur benchmarks: GPU time from timestamp queries as manual time (CONTRIBUTING.md, "Benchmarks"),
// bytes/s over the bytes-moved floor, and accuracy counters, for the chart of error against time
// (bench/plot.py blur -> docs/charts/blur_pareto.svg).
//
// Accuracy is measured on an n x n RGBA32F pair of inputs (n = 512, or more so that an interior
// remains beyond the border margin), with the method the timed run chose (errors of a Gaussian
// blur do not depend on the image size once the image is a few sigmas wide):
//   rel_l2          relative L2 against the exact Gaussian of the requested sigma, random HDR input,
//                   over the interior (docs/BLUR.md: the modelled bound is for the interior)
//   rel_l2_full     the same over the whole image (each method clamps at borders its own way)
//   max_abs         max absolute error against it, same input
//   rel_l2_impulse  relative L2 against the exact Gaussian's impulse response (the modelled case)
//   rel_l2_vs_f64   relative L2 against the float64 reference of the method itself (correctness)
//   expected_rel_l2 the planner's model, which `auto` uses
#include <benchmark/benchmark.h>
#include <glint/blur.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "bench_support.h"
#include "core/half.h"
#include "core/resources.h"
#include "reference/blur_reference.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

constexpr uint32_t kErrorSize = 512;

int frames_per_iteration() { return context().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 3 : 16; }

// Random HDR input and a centred impulse, n x n, made once per size.
const std::pair<CpuImage, CpuImage>& error_inputs(uint32_t n) {
  static std::map<uint32_t, std::pair<CpuImage, CpuImage>> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    it = cache.emplace(n, std::make_pair(random_hdr(n, n, 777), reference::impulse_image(n, n, n / 2, n / 2))).first;
  }
  return it->second;
}
// The exact Gaussian of the error inputs, once per (sigma, size) (float64; the expensive part).
const std::pair<reference::DoubleImage, reference::DoubleImage>& exact_of(double sigma, uint32_t n) {
  static std::map<std::pair<double, uint32_t>, std::pair<reference::DoubleImage, reference::DoubleImage>> cache;
  auto it = cache.find({sigma, n});
  if (it == cache.end()) {
    const auto& in = error_inputs(n);
    it = cache
             .emplace(std::make_pair(sigma, n), std::make_pair(reference::exact_gaussian(in.first, sigma),
                                                               reference::exact_gaussian(in.second, sigma)))
             .first;
  }
  return it->second;
}

CpuImage run_once_on(GaussianBlur& blur, const CpuImage& input) {
  const Context& ctx = context();
  const VkFormat f = VK_FORMAT_R32G32B32A32_SFLOAT;
  detail::OwnedImage in(ctx, {input.width, input.height}, f, detail::kToolImageUsage);
  detail::OwnedImage out(ctx, {input.width, input.height}, f, detail::kToolImageUsage);
  detail::upload(ctx, in.state, input);
  ctx.run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
  blur.forget_caller_resources();  // `in` and `out` die here; their handles may be reused
  return detail::download(ctx, out.state);
}

reference::DoubleImage own_reference(const GaussianBlur& blur, const CpuImage& input) {
  const BlurChoice& c = blur.choice();
  blur_plan::Plan p;
  p.levels = c.levels;
  p.level_sigma = c.level_sigma;
  p.dual_offset = c.dual_offset;
  p.radius = c.radius;
  p.sigma_px = blur.config().sigma_px;
  switch (c.method) {
    case BlurMethod::pyramid:
      p.method = blur_plan::Method::pyramid;
      return reference::gaussian_pyramid(input, p);
    case BlurMethod::dual:
      p.method = blur_plan::Method::dual;
      return reference::gaussian_dual(input, p);
    default:
      return c.linear_sampling ? reference::gaussian_separable_linear(input, p.sigma_px)
                               : reference::gaussian_separable(input, p.sigma_px);
  }
}

void run_gauss_benchmark(benchmark::State& state, BlurMethod method, bool linear) {
  const double sigma = state.range(0) / 10.0;
  const auto width = static_cast<uint32_t>(state.range(1));
  const auto height = static_cast<uint32_t>(state.range(2));
  const Context& ctx = context();
  const VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
  GaussianBlurConfig config;
  config.sigma_px = static_cast<float>(sigma);
  config.method = method;
  config.linear_sampling = linear;

  // Timing at the requested size, RGBA16F in and out, fp16 intermediates (the default).
  detail::OwnedImage in(ctx, {width, height}, format, detail::kToolImageUsage);
  detail::OwnedImage dst(ctx, {width, height}, format, detail::kToolImageUsage);
  detail::upload(ctx, in.state, random_hdr(width, height, 99));
  GaussianBlur blur(ctx, config);
  blur.prepare({width, height});
  const int frames = frames_per_iteration();
  Profiler profiler(ctx, frames + 1);
  std::vector<double> frame_ms;
  for (auto _ : state) {
    const double median =
        median_frame_ms(ctx, profiler, frames, [&](VkCommandBuffer cmd) { blur.record(cmd, in.state, dst.state); });
    frame_ms.push_back(median);
    state.SetIterationTime(median * 1e-3);
  }

  // Accuracy of the method the timed run chose (auto resolved), fp32 storage so that the method's
  // own error shows, on inputs large enough to keep an interior beyond the border margin.
  GaussianBlurConfig accurate = config;
  accurate.precision = Precision::fp32;
  accurate.method = blur.choice().method;
  accurate.linear_sampling = blur.choice().linear_sampling;
  GaussianBlur probe(ctx, accurate);
  const uint32_t margin = static_cast<uint32_t>(std::ceil(4 * sigma)) + (2u << blur.choice().levels);
  const uint32_t n = std::max(kErrorSize, (2 * margin + 256 + 1) & ~1u);
  const auto& inputs = error_inputs(n);
  const CpuImage out = run_once_on(probe, inputs.first);
  const CpuImage response = run_once_on(probe, inputs.second);
  const auto& exact = exact_of(sigma, n);
  state.counters["rel_l2"] = reference::rgba_relative_l2_interior(out, exact.first, margin);
  state.counters["rel_l2_full"] = reference::rgba_relative_l2(out, exact.first);
  state.counters["max_abs"] = reference::rgba_max_abs(out, exact.first);
  state.counters["rel_l2_impulse"] = reference::rgba_relative_l2(response, exact.second);
  state.counters["rel_l2_vs_f64"] = reference::rgba_relative_l2(out, own_reference(probe, inputs.first));
  state.counters["error_size"] = n;

  const BlurChoice& c = blur.choice();
  const double bytes = static_cast<double>(blur.min_bytes_moved(format, format));
  state.counters["floor_bytes"] = bytes;
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(frame_ms) * 1e3;
  state.counters["sigma"] = sigma;
  state.counters["expected_rel_l2"] = c.expected_relative_error;
  state.counters["levels"] = c.levels;
  state.counters["taps"] = c.method == BlurMethod::separable ? 2.0 * c.radius + 1.0 : 0.0;
  state.counters["dispatches"] = c.dispatches;
  state.SetLabel(std::string(blur_method_name(c.method)) + (c.linear_sampling ? "+linear" : "") + " on " +
                 ctx.info().name);
}

void BM_BlurSeparable(benchmark::State& s) { run_gauss_benchmark(s, BlurMethod::separable, false); }
void BM_BlurSeparableLinear(benchmark::State& s) { run_gauss_benchmark(s, BlurMethod::separable, true); }
void BM_BlurPyramid(benchmark::State& s) { run_gauss_benchmark(s, BlurMethod::pyramid, false); }
void BM_BlurDual(benchmark::State& s) { run_gauss_benchmark(s, BlurMethod::dual, false); }
void BM_BlurAuto(benchmark::State& s) { run_gauss_benchmark(s, BlurMethod::automatic, false); }

// sigma * 10 (1.2 is the 9-tap default), width, height. 3840x2160 for GPUs, 960x540 for lavapipe
// (select with --benchmark_filter).
void gauss_args(benchmark::internal::Benchmark* b, std::initializer_list<int> sigmas10) {
  for (auto size : {std::pair{3840, 2160}, std::pair{960, 540}})
    for (int s : sigmas10) b->Args({s, size.first, size.second});
  b->ArgNames({"sigma10", "w", "h"});
  b->UseManualTime();
  b->Unit(benchmark::kMicrosecond);
}

void all_sigmas(benchmark::internal::Benchmark* b) { gauss_args(b, {12, 20, 40, 80, 160, 320, 640}); }
void small_sigmas(benchmark::internal::Benchmark* b) { gauss_args(b, {12, 20, 40}); }

BENCHMARK(BM_BlurSeparable)->Apply(all_sigmas);
BENCHMARK(BM_BlurSeparableLinear)->Apply(small_sigmas);
BENCHMARK(BM_BlurPyramid)->Apply(all_sigmas);
BENCHMARK(BM_BlurDual)->Apply(all_sigmas);
BENCHMARK(BM_BlurAuto)->Apply(all_sigmas);

// The three-level BlurPyramid (docs/BLUR.md, default sigmas 1.2, 2.4, 4.8), RGBA16F input, fp16 levels.
void BM_PyramidLevels3(benchmark::State& state) {
  const auto width = static_cast<uint32_t>(state.range(0));
  const auto height = static_cast<uint32_t>(state.range(1));
  const Context& ctx = context();
  const VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
  const CpuImage input = random_hdr(width, height, 4321);
  detail::OwnedImage in(ctx, {width, height}, format, detail::kToolImageUsage);
  detail::upload(ctx, in.state, input);
  BlurPyramid pyramid(ctx);
  pyramid.prepare({width, height});
  // Correctness against the float64 reference (levels in fp16; below 4K to keep runs short).
  double error = -1;
  if (uint64_t(width) * height <= 1920ull * 1080ull) {
    ctx.run_once([&](VkCommandBuffer cmd) { pyramid.record(cmd, in.state); });
    CpuImage stored = input;
    for (float& v : stored.rgba) v = detail::round_to_half(v);
    const auto ref = reference::blur_pyramid(stored, {1.2, 1.2, 1.2});
    error = 0;
    for (uint32_t k = 1; k <= 3; ++k)
      error = std::max(error, reference::rgba_relative_l2(detail::download(ctx, pyramid.level(k)), ref[k - 1]));
  }
  const int frames = frames_per_iteration();
  Profiler profiler(ctx, frames + 1);
  std::vector<double> frame_ms;
  for (auto _ : state) {
    const double median =
        median_frame_ms(ctx, profiler, frames, [&](VkCommandBuffer cmd) { pyramid.record(cmd, in.state); });
    frame_ms.push_back(median);
    state.SetIterationTime(median * 1e-3);
  }
  const double bytes = static_cast<double>(pyramid.min_bytes_moved(format));
  state.counters["floor_bytes"] = bytes;
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(frame_ms) * 1e3;
  state.counters["rel_l2_vs_f64"] = error;
  state.SetLabel("blur pyramid (3 levels, sigma 1.2) on " + ctx.info().name);
}
BENCHMARK(BM_PyramidLevels3)
    ->Args({1920, 1080})
    ->Args({3840, 2160})
    ->Args({960, 540})
    ->ArgNames({"w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
