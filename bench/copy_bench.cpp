// The copy-bandwidth floor, measured in the same run as the effects: a compute kernel that reads
// one RGBA16F image and writes another (src/bloom/shaders/image_copy.comp), timed with timestamps. Effects
// quote their time as a ratio to this (docs/PERF.md).
#include <benchmark/benchmark.h>

#include "bench_support.h"
#include "bloom/shaders/bloom_params.h"
#include "core/barriers.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

void BM_CopyFloor(benchmark::State& state) {
  const auto width = static_cast<uint32_t>(state.range(0));
  const auto height = static_cast<uint32_t>(state.range(1));
  const Context& ctx = context();
  auto [src, dst] = rgba16f_pair(ctx, {width, height}, 7);
  detail::PipelineDesc desc;
  desc.kernel_id = "image_copy_rgba16f";
  desc.bindings = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  desc.push_constant_bytes = sizeof(BloomPush);
  desc.workgroup = detail::choose_workgroup_2d(ctx);
  detail::ComputePipeline copy(ctx, desc);
  BloomPush push{};
  push.dst_width = static_cast<int32_t>(width);
  push.dst_height = static_cast<int32_t>(height);
  constexpr int kCopies = 16;
  Profiler profiler(ctx, kCopies + 1);
  std::vector<double> all;
  for (auto _ : state) {
    const double m = median_frame_ms(ctx, profiler, kCopies, [&](VkCommandBuffer cmd) {
      detail::Barriers b;
      b.use(src.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
      b.use(dst.state, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
      b.flush(cmd);
      copy.dispatch(
          cmd, {{src.state.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}, {dst.state.view, VK_IMAGE_LAYOUT_GENERAL}},
          push, width, height);
    });
    all.push_back(m);
    state.SetIterationTime(m * 1e-3);
  }
  const double bytes = double(width) * height * 16.0;  // 8 bytes read + 8 written per texel
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["floor_bytes"] = bytes;
  state.SetLabel("RGBA16F image copy on " + ctx.info().name);
}

BENCHMARK(BM_CopyFloor)
    ->Args({640, 480})
    ->Args({1920, 1080})
    ->Args({3840, 2160})
    ->Args({7680, 4320})
    ->ArgNames({"w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
