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

#include "bench_support.h"
#include "bloom/bloom_internal.h"
#include "core/half.h"
#include "reference/bloom_reference.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

constexpr int kFramesPerIteration = 16;

void BM_Bloom(benchmark::State& state) {
  const auto width = static_cast<uint32_t>(state.range(0));
  const auto height = static_cast<uint32_t>(state.range(1));
  const auto filter = static_cast<BloomFilter>(state.range(2));
  const auto precision = static_cast<Precision>(state.range(3));
  const auto guard = static_cast<FireflyGuard>(state.range(4));
  const auto level0_height = static_cast<uint32_t>(state.range(5));
  // fused: bit 0 the small levels in one dispatch, bit 1 the last upsample in the composite, bit 2
  // the tiled composite instead of the 2:1 one, bit 3 the tiled upsample steps instead of the 2:1
  // ones (src/bloom/bloom_internal.h, docs/BLOOM.md "Dispatches"); 0 is the default.
  const auto fused = static_cast<uint32_t>(state.range(6));
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
  detail::BloomAccess::set_path(bloom, {(fused & 1u) != 0, (fused & 2u) != 0, (fused & 4u) == 0, (fused & 8u) == 0});
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
                 firefly_guard_name(guard) + (level0_height ? "/l0h" + std::to_string(level0_height) : "") + "/fused" +
                 std::to_string(fused) + " on " + ctx.info().name);
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

}  // namespace
}  // namespace glint::bench
