// LodBatch throughput: queries per second (GPU timestamps, manual time), with the largest
// deviation from the C++ twin as the error counter.
#include <benchmark/benchmark.h>
#include <glint/lod.h>

#include <cmath>
#include <cstring>
#include <random>

#include "bench_support.h"
#include "core/barriers.h"
#include "core/resources.h"

namespace glint::bench {
namespace {

void BM_LodBatch(benchmark::State& state) {
  const auto count = static_cast<uint32_t>(state.range(0));
  const bool aniso = state.range(1) != 0;
  const Context& ctx = context();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<LodQuery> queries(count);
  for (auto& q : queries) {
    q.tex_w = float(1 << int(unit(rng) * 11));
    q.tex_h = float(1 << int(unit(rng) * 11));
    q.off_x = std::floor(unit(rng) * (4096.0f - q.tex_w));
    q.off_y = std::floor(unit(rng) * (4096.0f - q.tex_h));
    const float rho = std::exp2(-2.0f + 15.0f * unit(rng));
    q.dudx = rho / q.tex_w;
    q.dvdy = rho * unit(rng) / q.tex_h;
    q.dvdx = 0.3f * rho / q.tex_h;
  }
  // Device-local buffers (what an engine would use), filled and read back through staging.
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  detail::OwnedBuffer qbuf(ctx, count * sizeof(LodQuery), usage, false);
  detail::OwnedBuffer lbuf(ctx, count * sizeof(float), usage, false);
  detail::OwnedBuffer upload(ctx, count * sizeof(LodQuery), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  detail::OwnedBuffer readback(ctx, count * sizeof(float), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  std::memcpy(upload.mapped(), queries.data(), count * sizeof(LodQuery));
  upload.flush();
  Buffer q{qbuf.buffer(), 0, qbuf.size(), usage, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  Buffer l{lbuf.buffer(), 0, lbuf.size(), usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  ctx.run_once([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, qbuf.size()};
    vkCmdCopyBuffer(cmd, upload.buffer(), qbuf.buffer(), 1, &region);
  });
  LodAtlasConfig atlas;
  atlas.anisotropic = aniso;
  atlas.padding_texels = 16.0f;
  LodBatch batch(ctx);
  Profiler profiler(ctx, 17);
  std::vector<double> all;
  for (auto _ : state) {
    const double ms =
        median_frame_ms(ctx, profiler, 16, [&](VkCommandBuffer cmd) { batch.record(cmd, q, l, count, atlas); });
    all.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
  }
  ctx.run_once([&](VkCommandBuffer cmd) {
    detail::Barriers b;
    b.use(l, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    VkBufferCopy region{0, 0, lbuf.size()};
    vkCmdCopyBuffer(cmd, lbuf.buffer(), readback.buffer(), 1, &region);
    Buffer r{readback.buffer(), 0, readback.size(), 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
    b.use(r, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
  });
  readback.invalidate();
  const float* levels = static_cast<const float*>(readback.mapped());
  double worst = 0.0;
  for (uint32_t i = 0; i < count; ++i)
    worst = std::max(worst, std::fabs(double(levels[i]) - lod_level(queries[i], atlas)));
  state.counters["queries_per_second"] = benchmark::Counter(count, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bytes_per_second"] = benchmark::Counter(count * 36.0, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["max_dev_vs_cpp_twin"] = worst;
  state.SetLabel(std::string(aniso ? "anisotropic" : "isotropic") + " on " + ctx.info().name);
}

BENCHMARK(BM_LodBatch)
    ->Args({1 << 16, 0})
    ->Args({1 << 20, 0})
    ->Args({1 << 20, 1})
    ->Args({4'000'000, 0})
    ->ArgNames({"n", "aniso"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
