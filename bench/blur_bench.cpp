// Blur benchmarks: GPU time from timestamp queries as manual time (CONTRIBUTING.md, "Benchmarks"),
// bytes/s over the bytes-moved floor, and accuracy counters, for the chart of error against time
// (bench/plot.py blur -> docs/charts/blur_pareto.svg).
//
// Accuracy is measured on a 512x512 RGBA32F pair of inputs, with the method the timed run chose
// (errors of a Gaussian blur do not depend on the image size once the image is a few sigmas wide):
//   rel_l2          relative L2 against the exact Gaussian of the requested sigma, random HDR input,
//                   over the whole image (docs/BLUR.md "Borders": the bound covers the borders)
//   max_abs         max absolute error against it, same input
//   rel_l2_impulse  relative L2 against the exact Gaussian's impulse response (the modelled case)
//   rel_l2_vs_f64   relative L2 against the float64 reference of the method itself (correctness)
//   expected_rel_l2 the planner's model, which `auto` uses
#include <benchmark/benchmark.h>
#include <glint/blur.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "bench_support.h"
#include "blur/blur_steps.h"
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

// The counter of a stage mark: "us_" and the step's label, "gauss " dropped, every run of other
// characters than letters and digits one '_' ("gauss pyramid level 1 (down)" ->
// "us_pyramid_level_1_down").
std::string stage_key(const std::string& label) {
  const std::string name = label.rfind("gauss ", 0) == 0 ? label.substr(6) : label;
  std::string key = "us_";
  for (char ch : name) {
    if (std::isalnum(static_cast<unsigned char>(ch)))
      key += ch;
    else if (key.back() != '_')
      key += '_';
  }
  while (key.back() == '_') key.pop_back();
  return key;
}

// Stage breakdown of one more frame (a timestamp after each dispatch, which serialises them, so
// the stages add up to more than the frame), for docs/PERF.md: one counter per step.
void add_stage_counters(benchmark::State& state, const std::function<void(VkCommandBuffer, Profiler*)>& record) {
  for (const auto& st : stage_marks(context(), 16, record)) state.counters[stage_key(st.label)] += st.ms * 1e3;
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
  auto [in, dst] = rgba16f_pair(ctx, {width, height}, 99);
  GaussianBlur blur(ctx, config);
  blur.prepare({width, height});
  const std::vector<double> frame_ms =
      time_frames(state, frames_per_iteration(), [&](VkCommandBuffer cmd) { blur.record(cmd, in.state, dst.state); });
  add_stage_counters(state, [&](VkCommandBuffer cmd, Profiler* p) { blur.record(cmd, in.state, dst.state, p); });

  // Accuracy of the method the timed run chose (auto resolved), fp32 storage so that the method's
  // own error shows.
  GaussianBlurConfig accurate = config;
  accurate.precision = Precision::fp32;
  accurate.method = blur.choice().method;
  accurate.linear_sampling = blur.choice().linear_sampling;
  GaussianBlur probe(ctx, accurate);
  const uint32_t n = kErrorSize;
  const auto& inputs = error_inputs(n);
  const CpuImage out = run_once_on(probe, inputs.first);
  const CpuImage response = run_once_on(probe, inputs.second);
  const auto& exact = exact_of(sigma, n);
  state.counters["rel_l2"] = reference::rgba_relative_l2(out, exact.first);
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

// The two kernels of a level-blur step (docs/BLUR.md "Streamed separable"), forced through
// detail::BlurAccess: the tiled one (kernel 1), the streamed one (kernel 2, wherever a strip
// fits; four fetches for a 2:1 mean) and the streamed one with the GPUs' load orders on any
// device (kernel 3, SeparableKernel::gpu_order: column means, gathered downsample taps); a
// GaussianBlur pyramid's downsamples take the same choice (blur_down.comp or
// blur_down_stream.comp), and its rows report each step's time (us_<step> counters). Method 1:
// GaussianBlur separable (sigma 1.2, radius 5; sigma 3, radius 12, the largest); method 2:
// GaussianBlur pyramid, one level (sigma 4: its level blur reads at the same size); method 3:
// BlurPyramid, every level sigma_texels = sigma (1.2: the default), whose levels read the exact
// 2:1 mean where the sizes halve exactly. RGBA16F. 3840x2160 and 1920x1080 for GPUs, 960x540 for
// CPU devices. Args: kernel, method, sigma x 10, width, height. Counters: median_us, streamed (the
// steps that ran a streamed kernel), gpu_ordered (those that loaded in the GPUs' orders), taps
// (GaussianBlur).
void BM_BlurLevelKernel(benchmark::State& state) {
  const auto kernel = state.range(0) == 1   ? blur_steps::SeparableKernel::tiles
                      : state.range(0) == 3 ? blur_steps::SeparableKernel::gpu_order
                                            : blur_steps::SeparableKernel::stream;
  const auto sigma = static_cast<float>(state.range(2) / 10.0);
  const auto width = static_cast<uint32_t>(state.range(3));
  const auto height = static_cast<uint32_t>(state.range(4));
  const Context& ctx = context();
  auto [in, dst] = rgba16f_pair(ctx, {width, height}, 99);
  std::vector<double> frame_ms;
  uint32_t streamed = 0;
  std::string label;
  if (state.range(1) == 3) {
    BlurPyramidConfig config;
    config.sigma_texels = {sigma, sigma, sigma};
    BlurPyramid pyramid(ctx, config);
    detail::BlurAccess::select_separable(pyramid, kernel);
    pyramid.prepare({width, height});
    frame_ms = time_frames(state, frames_per_iteration(), [&](VkCommandBuffer cmd) { pyramid.record(cmd, in.state); });
    streamed = detail::BlurAccess::streamed(pyramid);
    state.counters["gpu_ordered"] = detail::BlurAccess::gpu_ordered(pyramid);
    label = "BlurPyramid";
  } else {
    GaussianBlurConfig config;
    config.method = state.range(1) == 1 ? BlurMethod::separable : BlurMethod::pyramid;
    config.sigma_px = sigma;
    GaussianBlur blur(ctx, config);
    detail::BlurAccess::select_separable(blur, kernel);
    blur.prepare({width, height});
    frame_ms =
        time_frames(state, frames_per_iteration(), [&](VkCommandBuffer cmd) { blur.record(cmd, in.state, dst.state); });
    add_stage_counters(state, [&](VkCommandBuffer cmd, Profiler* p) { blur.record(cmd, in.state, dst.state, p); });
    streamed = detail::BlurAccess::streamed(blur);
    state.counters["gpu_ordered"] = detail::BlurAccess::gpu_ordered(blur);
    state.counters["taps"] = 2.0 * blur.choice().radius + 1.0;
    label = blur_method_name(blur.choice().method);
  }
  state.counters["median_us"] = median_of(frame_ms) * 1e3;
  state.counters["streamed"] = streamed;
  state.SetLabel(label + ", " + std::to_string(streamed) + " streamed steps on " + ctx.info().name);
}
BENCHMARK(BM_BlurLevelKernel)
    ->ArgsProduct({{1, 2}, {1}, {12, 30}, {3840}, {2160}})
    ->ArgsProduct({{1, 2}, {1}, {12}, {1920}, {1080}})
    ->ArgsProduct({{1, 2}, {2}, {40}, {3840}, {2160}})
    ->ArgsProduct({{1, 2, 3}, {3}, {12}, {3840}, {2160}})
    ->ArgsProduct({{1, 2, 3}, {3}, {12}, {1920}, {1080}})
    ->ArgsProduct({{1, 2}, {1}, {12, 30}, {960}, {540}})
    ->ArgsProduct({{1, 2, 3}, {2, 3}, {40}, {960}, {540}})
    ->ArgNames({"kernel", "method", "sigma10", "w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// auto against the fastest method that meets the same bound, on the device it runs on (docs/BLUR.md
// "Cost model"): every method whose expected error meets the bound is timed at the size, and
// auto's time is reported next to the fastest one's. Counters: auto_us, best_us, ratio (auto /
// best, 1 when auto picked the fastest), auto_method and best_method (BlurMethod values: 1
// separable, 2 pyramid, 3 dual); the label names both. A candidate whose first frame already takes
// more than 3x the best so far is not timed further (one frame of a 401-tap blur on a CPU device
// takes seconds). Args: sigma x 10, width, height, bound x 1000.
void BM_BlurAutoVsBest(benchmark::State& state) {
  const double sigma = state.range(0) / 10.0;
  const auto width = static_cast<uint32_t>(state.range(1));
  const auto height = static_cast<uint32_t>(state.range(2));
  const float bound = static_cast<float>(state.range(3)) / 1000.0f;
  const Context& ctx = context();
  auto [in, dst] = rgba16f_pair(ctx, {width, height}, 99);
  const int frames = frames_per_iteration();
  Profiler profiler(ctx, frames + 1);
  // Median frame time of `blur` in microseconds; one frame only when that one is beyond `cutoff`.
  auto time_us = [&](GaussianBlur& blur, double cutoff_us) {
    const auto record = [&](VkCommandBuffer cmd) { blur.record(cmd, in.state, dst.state); };
    const double first = median_frame_ms(ctx, profiler, 1, record) * 1e3;
    if (first > cutoff_us) return first;
    return median_frame_ms(ctx, profiler, frames, record) * 1e3;
  };
  GaussianBlurConfig config;
  config.sigma_px = static_cast<float>(sigma);
  config.max_relative_error = bound;
  GaussianBlur automatic(ctx, config);
  automatic.prepare({width, height});  // the first automatic plan measures the cost model
  double auto_us = 0, best_us = 0;
  BlurMethod best = BlurMethod::automatic;
  for (auto _ : state) {
    auto_us = time_us(automatic, std::numeric_limits<double>::infinity());
    best_us = std::numeric_limits<double>::infinity();
    for (BlurMethod m : {BlurMethod::separable, BlurMethod::pyramid, BlurMethod::dual}) {
      GaussianBlurConfig c = config;
      c.method = m;
      GaussianBlur blur(ctx, c);
      blur.prepare({width, height});
      if (blur.choice().expected_relative_error > bound) continue;
      const double us = m == automatic.choice().method ? auto_us : time_us(blur, 3.0 * std::min(best_us, 1e300));
      if (us < best_us) {
        best_us = us;
        best = m;
      }
    }
    state.SetIterationTime(auto_us * 1e-6);
  }
  state.counters["auto_us"] = auto_us;
  state.counters["best_us"] = best_us;
  state.counters["ratio"] = auto_us / best_us;
  state.counters["auto_method"] = static_cast<double>(automatic.choice().method);
  state.counters["best_method"] = static_cast<double>(best);
  state.counters["auto_expected_rel_l2"] = automatic.choice().expected_relative_error;
  state.counters["auto_estimated_us"] = automatic.choice().estimated_us;
  state.SetLabel(std::string("auto=") + blur_method_name(automatic.choice().method) +
                 " best=" + blur_method_name(best) + " on " + ctx.info().name);
}

// sigma x 10, width, height, bound x 1000 (0.02 and 0.1): 1920x1080 and 3840x2160 for GPUs,
// 256x256 and 512x512 for lavapipe (select with --benchmark_filter).
void auto_vs_best_args(benchmark::internal::Benchmark* b) {
  for (auto size : {std::pair{3840, 2160}, std::pair{1920, 1080}, std::pair{512, 512}, std::pair{256, 256}})
    for (int bound : {20, 100})  // 0.1 lets the dual in (its error is 0.07 to 0.3)
      for (int s : {20, 40, 80, 200, 500}) b->Args({s, size.first, size.second, bound});
  b->ArgNames({"sigma10", "w", "h", "bound1000"});
  b->UseManualTime();
  b->Iterations(1);
  b->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_BlurAutoVsBest)->Apply(auto_vs_best_args);

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
