// Bloom benchmarks: GPU time from timestamp queries as manual time (CONTRIBUTING.md, "Benchmarks"), bytes/s over
// the bytes-moved floor, and the error against the float64 reference as a counter.
//
// Each iteration records kFramesPerIteration blooms back to back in one command buffer with a
// timestamp between them and reports their median; Google Benchmark then aggregates iterations
// (run with --benchmark_repetitions=N --benchmark_report_aggregates_only for medians).
#include <benchmark/benchmark.h>
#include <glint/bloom.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>

#include "bench_support.h"
#include "bloom/bloom_internal.h"
#include "core/half.h"
#include "reference/bloom_reference.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

constexpr int kFramesPerIteration = 16;

// One bloom configuration at width x height with the dispatch structure `path`; `variant` names
// the path in the label.
void run_bloom(benchmark::State& state, uint32_t width, uint32_t height, BloomFilter filter, Precision precision,
               FireflyGuard guard, uint32_t level0_height, const detail::BloomPath& path, const std::string& variant) {
  const Context& ctx = context();
  const VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;

  const CpuImage input = random_hdr(width, height, 1234);
  detail::OwnedImage in(ctx, {width, height}, format, detail::kToolImageUsage);
  detail::OwnedImage out(ctx, {width, height}, format, detail::kToolImageUsage);
  detail::upload(ctx, in.state, input);
  BloomConfig config;
  config.filter = filter;
  config.precision = precision;
  config.firefly_guard = guard;
  config.level0_height = level0_height;
  Bloom bloom(ctx, config);
  try {
    detail::BloomAccess::set_path(bloom, path);
  } catch (const Error& e) {  // a shape the device cannot run (BM_BloomShapes)
    state.SkipWithError(e.what());
    return;
  }
  bloom.prepare({width, height});
  Profiler profiler(ctx, kFramesPerIteration + 1);

  // Error against the float64 reference (not timed); skipped above 1080p to keep runs short.
  double error = -1.0;
  if (uint64_t(width) * height <= 1920ull * 1080ull) {
    ctx.run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
    CpuImage stored = input;
    for (float& v : stored.rgba) v = detail::round_to_half(v);
    error = reference::relative_l2(detail::download(ctx, out.state), reference::bloom(stored, config));
  }

  std::vector<double> frame_ms;
  for (auto _ : state) {
    const double median = median_frame_ms(ctx, profiler, kFramesPerIteration,
                                          [&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
    frame_ms.push_back(median);
    state.SetIterationTime(median * 1e-3);
  }
  // Stage breakdown of one more frame (bloom's own profiler marks), for docs/PERF.md.
  const std::vector<Profiler::Stage> stages =
      stage_marks(ctx, 8, [&](VkCommandBuffer cmd, Profiler* p) { bloom.record(cmd, in.state, out.state, p); });
  // Every stage's key is reported (0 when the path has no such stage), so rows of different paths compare.
  for (const char* key : {"us_prefilter_down0", "us_down", "us_small_levels", "us_up", "us_composite"})
    state.counters[key] = 0.0;
  for (const auto& s : stages) {
    const std::string& l = s.label;
    const char* key = l.find("bright") != std::string::npos         ? "us_prefilter_down0"
                      : l.find("downsample") != std::string::npos   ? "us_down"
                      : l.find("small levels") != std::string::npos ? "us_small_levels"
                      : l.find("upsample") != std::string::npos     ? "us_up"
                                                                    : "us_composite";
    state.counters[key] = s.ms * 1e3;
  }
  state.counters["small_levels_top"] = detail::BloomAccess::small_levels_top(bloom);
  const double bytes = static_cast<double>(bloom.min_bytes_moved(format, format));
  state.counters["floor_bytes"] = bytes;
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(frame_ms) * 1e3;
  state.counters["rel_l2_vs_f64"] = error;
  state.counters["levels"] = bloom.levels();
  state.SetLabel(std::string(bloom_filter_name(filter)) + (precision == Precision::fp16 ? "/fp16/" : "/fp32/") +
                 firefly_guard_name(guard) + (level0_height ? "/l0h" + std::to_string(level0_height) : "") + "/" +
                 variant + " on " + ctx.info().name);
}

void BM_Bloom(benchmark::State& state) {
  // fused: bit 0 the small levels in one dispatch, bit 1 the last upsample in the composite, bit 2
  // the tiled composite instead of the 2:1 one, bit 3 the tiled upsample steps instead of the 2:1
  // ones (src/bloom/bloom_internal.h, docs/BLOOM.md "Dispatches"); 0 is the default.
  const auto fused = static_cast<uint32_t>(state.range(6));
  detail::BloomPath path;
  path.fuse_small_levels = (fused & 1u) != 0;
  path.fuse_last_up = (fused & 2u) != 0;
  path.composite_2x = (fused & 4u) == 0;
  path.up_2x = (fused & 8u) == 0;
  run_bloom(state, static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)),
            static_cast<BloomFilter>(state.range(2)), static_cast<Precision>(state.range(3)),
            static_cast<FireflyGuard>(state.range(4)), static_cast<uint32_t>(state.range(5)), path,
            "fused" + std::to_string(fused));
}

void bloom_args(benchmark::internal::Benchmark* b) {
  // Defaults (karis_smooth, level0_height 0) per filter and cod13 with fp32 levels; then cod13 with
  // the per-box guard and none (what the smooth guard costs), and with level0_height 540. Each with
  // the fused dispatches (fused:3) and one dispatch per level (fused:0, the default); the default
  // configuration also with each fusion alone (fused:1 small levels, fused:2 the last upsample)
  // and with the tiled kernels where the 2:1 ones run (fused:4 the composite, 8 the upsample
  // steps, 12 both).
  for (auto size : {std::pair{640, 480}, std::pair{1920, 1080}, std::pair{3840, 2160}}) {
    for (int fused : {3, 0, 1, 2, 4, 8, 12}) b->Args({size.first, size.second, 0, 0, 2, 0, fused});
    for (int fused : {3, 0}) {
      for (int filter = 1; filter < 3; ++filter) b->Args({size.first, size.second, filter, 0, 2, 0, fused});
      b->Args({size.first, size.second, 0, 1, 2, 0, fused});
      b->Args({size.first, size.second, 0, 0, 1, 0, fused});
      b->Args({size.first, size.second, 0, 0, 0, 0, fused});
      if (size.second >= 1080) b->Args({size.first, size.second, 0, 0, 2, 540, fused});
    }
  }
  b->ArgNames({"w", "h", "filter", "fp32", "guard", "l0h", "fused"});
  b->UseManualTime();
  b->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Bloom)->Apply(bloom_args);

// The default bloom (cod13, fp16 levels, karis_smooth) with the kernels after the first stage in
// other workgroup shapes than the bloom's own (BloomPath's down_workgroup, up_workgroup and
// composite_workgroup): shape 0 the default; 1 / 2 the downsamples in 32x8 / 64x4; 3 / 4 the
// upsamples; 5 / 6 the composite; 7 / 8 all three. A shape the device cannot run is skipped.
void BM_BloomShapes(benchmark::State& state) {
  const auto shape = static_cast<int>(state.range(2));
  const detail::Workgroup2D wide = shape % 2 == 1 ? detail::Workgroup2D{32, 8} : detail::Workgroup2D{64, 4};
  detail::BloomPath path;
  if (shape == 1 || shape == 2 || shape >= 7) path.down_workgroup = wide;
  if (shape == 3 || shape == 4 || shape >= 7) path.up_workgroup = wide;
  if (shape == 5 || shape == 6 || shape >= 7) path.composite_workgroup = wide;
  const std::string name = shape == 0 ? "default shapes"
                                      : std::string(shape >= 7   ? "all"
                                                    : shape >= 5 ? "composite"
                                                    : shape >= 3 ? "up"
                                                                 : "down") +
                                            " " + std::to_string(wide.x) + "x" + std::to_string(wide.y);
  run_bloom(state, static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)), BloomFilter::cod13,
            Precision::fp16, FireflyGuard::karis_smooth, 0, path, name);
}

BENCHMARK(BM_BloomShapes)
    ->ArgsProduct({{1920}, {1080}, {0, 1, 2, 3, 4, 5, 6, 7, 8}})
    ->ArgsProduct({{3840}, {2160}, {0, 1, 2, 3, 4, 5, 6, 7, 8}})
    ->ArgNames({"w", "h", "shape"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
