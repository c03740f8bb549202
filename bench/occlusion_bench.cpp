// Lens-flare visibility benchmarks (speed targets in docs/PERF.md): the Hi-Z build of a D32 depth buffer,
// and the cull + occlusion grid + compaction of a light list, on device-local resources. GPU time
// from timestamps as manual time (median of the frames of one command buffer), bytes/s over the
// bytes each stage must move, and error counters against the float64 references:
// - BM_HiZBuild: texels that differ from the reference pyramid (must be 0); BM_HiZStreamPass
//   times the same build with either stream pass forced (detail::HiZAccess);
// - BM_LightCull: mean |grid fraction - brute force| over the first 2000 tested lights of the
//   fixed scene (the occlusion error of docs/charts/occlusion_pareto.svg), and how often the
//   documented bound or the conservative rule is broken (must be 0).
#include <benchmark/benchmark.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "bench_support.h"
#include "core/barriers.h"
#include "core/resources.h"
#include "reference/occlusion_reference.h"
#include "support/transfer.h"
#include "visibility/hiz_internal.h"
#include "visibility/light_cull_internal.h"

namespace glint::bench {
namespace {

// Frames per timed command buffer: fewer on CPU devices (lavapipe), where 1M lights take seconds.
int frames_for(const Context& ctx, uint64_t work) {
  if (ctx.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU && work > 100000) return 2;
  return 16;
}

// A depth buffer of sloped boxes over the far plane (the same generator as the tests).
reference::Scene scene_for(uint32_t w, uint32_t h, uint32_t lights, double max_size) {
  return reference::random_scene(w, h, lights, 2024, false, max_size);
}

// The Hi-Z build of a w x h D32 depth buffer with stream pass `stream`.
void run_hiz_build(benchmark::State& state, uint32_t w, uint32_t h, detail::HiZStream stream) {
  const Context& ctx = context();
  const auto scene = scene_for(w, h, 0, 1);
  auto depth = depth_image(ctx, scene.depth);
  HiZConfig config;
  config.extent = {w, h};
  HiZPyramid hiz(ctx, config);
  if (stream != detail::HiZStream::device) detail::HiZAccess::select_stream(hiz, stream);
  const int frames = frames_for(ctx, uint64_t(w) * h / 64);
  Profiler profiler(ctx, frames + 1);
  std::vector<double> all;
  for (auto _ : state) {
    const double ms =
        median_frame_ms(ctx, profiler, frames, [&](VkCommandBuffer cmd) { hiz.record(cmd, depth.state); });
    all.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
  }
  // Exactness of the benchmarked pyramid.
  const auto ref = reference::hiz_pyramid(scene.depth, false, hiz.levels());
  uint64_t mismatches = 0;
  for (uint32_t k = 1; k <= hiz.levels(); ++k) {
    const auto& r = ref[k - 1];
    const auto gpu = detail::download_r32(ctx, hiz.image(), k - 1, {r.width, r.height}, hiz.levels());
    for (size_t i = 0; i < gpu.size(); ++i) mismatches += std::memcmp(&gpu[i], &r.depth[i], 4) != 0;
  }
  const double bytes = double(hiz.min_bytes_moved());
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["floor_bytes"] = bytes;
  state.counters["levels"] = hiz.levels();
  state.counters["mismatches_vs_f64"] = double(mismatches);
  const bool blocks = detail::HiZAccess::stream(hiz) == detail::HiZStream::blocks;
  state.SetLabel(std::string("D32, ") + (blocks ? "block" : "texel") + " stream pass on " + ctx.info().name);
}

// Args: width, height. The device's stream pass (blocks on GPUs, texels on CPU devices).
void BM_HiZBuild(benchmark::State& state) {
  run_hiz_build(state, static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)),
                detail::HiZStream::device);
}

BENCHMARK(BM_HiZBuild)
    ->Args({1920, 1080})
    ->Args({3840, 2160})
    ->ArgNames({"w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// Args: stream pass (detail::HiZStream: 1 blocks, levels 1-6 by 64x64 blocks; 2 texels, levels
// 1-2), width, height: both passes on any device (docs/OCCLUSION.md "Speed").
void BM_HiZStreamPass(benchmark::State& state) {
  run_hiz_build(state, static_cast<uint32_t>(state.range(1)), static_cast<uint32_t>(state.range(2)),
                static_cast<detail::HiZStream>(state.range(0)));
}

BENCHMARK(BM_HiZStreamPass)
    ->ArgsProduct({{1, 2}, {1920}, {1080}})
    ->ArgsProduct({{1, 2}, {3840}, {2160}})
    ->ArgNames({"stream", "w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The light cull of `n` lights with an N = `grid` grid, timed; `path` forces the cull's path
// (detail::LightCullPath; `device` lets the count choose). With `measure_error`, the error against
// brute force as BM_LightCull reports it.
void light_cull(benchmark::State& state, uint32_t n, uint32_t grid, bool with_results, bool with_hiz,
                OcclusionPattern pattern, detail::LightCullPath path, bool measure_error) {
  const Context& ctx = context();
  const uint32_t w = 1920, h = 1080;
  // Flares of 8 to 128 pixels (the default flare size is 100).
  const auto scene = scene_for(w, h, n, 128.0);
  auto depth = depth_image(ctx, scene.depth);
  HiZConfig hc;
  hc.extent = {w, h};
  HiZPyramid hiz(ctx, hc);
  LightCullConfig cc;
  cc.capacity = std::max(n, 1u);
  cc.grid = grid;
  cc.pattern = pattern;
  cc.max_lights = std::max(n, 1u);
  LightCuller culler(ctx, cc);
  detail::LightCullAccess::select_path(culler, path);
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  auto lights = device_buffer(ctx, scene.lights.data(), VkDeviceSize(n) * sizeof(GlintFlareLight), storage);
  auto instances = device_buffer(ctx, nullptr, VkDeviceSize(cc.capacity) * sizeof(GlintFlareInstance), storage);
  auto indirect =
      device_buffer(ctx, nullptr, sizeof(GlintFlareIndirect), storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  auto stats = device_buffer(ctx, nullptr, sizeof(GlintFlareStats), storage);
  auto results = device_buffer(ctx, nullptr, VkDeviceSize(n) * sizeof(GlintFlareLightResult), storage);
  Buffer lv = buffer_view(lights, storage, true);
  LightCullOutputs out{buffer_view(instances, storage, false),
                       buffer_view(indirect, storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, false),
                       buffer_view(stats, storage, false),
                       with_results ? buffer_view(results, storage, false) : Buffer{}};
  LightCullFrame frame;
  for (int i = 0; i < 16; ++i) frame.view_proj[i] = static_cast<float>(scene.view_proj[i]);
  ctx.run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, depth.state); });

  const int frames = frames_for(ctx, uint64_t(n) * grid * grid);
  Profiler profiler(ctx, frames + 1);
  std::vector<double> all;
  for (auto _ : state) {
    const double ms = median_frame_ms(ctx, profiler, frames, [&](VkCommandBuffer cmd) {
      if (with_hiz) hiz.record(cmd, depth.state);
      culler.record(cmd, hiz, depth.state, lv, n, frame, out);
    });
    all.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
  }

  // Read the per-light results and statistics back (results are written in a separate frame when
  // the timed one had none).
  Buffer rv = buffer_view(results, storage, false);
  LightCullOutputs check{out.instances, out.indirect, out.stats, rv};
  detail::OwnedBuffer readback(ctx, VkDeviceSize(n) * 8 + sizeof(GlintFlareStats) + 16,
                               VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  ctx.run_once([&](VkCommandBuffer cmd) {
    culler.record(cmd, hiz, depth.state, lv, n, frame, check);
    detail::Barriers b;
    b.use(check.results, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.use(check.stats, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    VkBufferCopy r1{0, 0, VkDeviceSize(n) * 8};
    if (n) vkCmdCopyBuffer(cmd, results.buffer(), readback.buffer(), 1, &r1);
    VkBufferCopy r2{0, VkDeviceSize(n) * 8, sizeof(GlintFlareStats)};
    vkCmdCopyBuffer(cmd, stats.buffer(), readback.buffer(), 1, &r2);
    Buffer rb{readback.buffer(), 0, readback.size(), 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
    b.use(rb, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
  });
  readback.invalidate();
  const auto* res = static_cast<const GlintFlareLightResult*>(readback.mapped());
  GlintFlareStats st;
  std::memcpy(&st, static_cast<const char*>(readback.mapped()) + VkDeviceSize(n) * 8, sizeof(st));

  // Occlusion error against brute force on the first 2000 lights that reach the grid test.
  reference::CullSettings s;
  std::copy(scene.view_proj, scene.view_proj + 16, s.view_proj);
  s.grid = grid;
  s.levels = hiz.levels();
  s.regular_grid = pattern == OcclusionPattern::regular;
  const auto pyramid =
      measure_error ? reference::hiz_pyramid(scene.depth, false, hiz.levels()) : std::vector<reference::DepthImage>{};
  double error_sum = 0.0;
  uint32_t tested = 0, broken = 0;
  for (uint32_t i = 0; measure_error && i < n && tested < 2000; ++i) {
    const auto ref = reference::cull_light(scene.lights[i], s, scene.depth, pyramid);
    if (ref.ambiguous || (ref.culled != GLINT_FLARE_VISIBLE && ref.culled != GLINT_FLARE_OCCLUDED)) continue;
    const double gpu = res[i].culled == GLINT_FLARE_VISIBLE ? res[i].visible_fraction : 0.0;
    const double err = gpu - ref.brute_force;
    // docs/OCCLUSION.md: |grid - brute force| <= mixed samples / N^2, and any visible pixel keeps
    // the light visible.
    if (std::fabs(err) > ref.mixed_cells / double(grid * grid) + 1e-6 || (ref.brute_force > 0.0 && gpu <= 0.0) ||
        std::fabs(gpu - ref.grid_fraction) > 1e-6) {
      ++broken;
    }
    error_sum += std::fabs(err);
    ++tested;
  }
  const double bytes = double(n) * (sizeof(GlintFlareLight) + (with_results ? 8 : 0)) +
                       double(std::min(st.visible, cc.capacity)) * sizeof(GlintFlareInstance);
  state.counters["lights_per_second"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["visible"] = st.visible;
  state.counters["occluded"] = st.occluded;
  state.counters["frustum_culled"] = st.frustum_culled;
  if (measure_error) {
    state.counters["mean_abs_error_vs_brute_force"] = tested ? error_sum / tested : 0.0;
    state.counters["bound_or_exactness_violations"] = broken;
  }
  const bool one_group = path == detail::LightCullPath::one_group ||
                         (path == detail::LightCullPath::device && n <= culler.one_group_lights());
  state.counters["one_group"] = one_group ? 1 : 0;
  state.SetLabel(std::string(one_group ? "one workgroup" : "ordered compaction") + (with_hiz ? " + Hi-Z" : "") +
                 (pattern == OcclusionPattern::regular ? ", regular grid" : ", multi-jittered") + " on " +
                 ctx.info().name);
}

// Args: lights, grid N, per-light results (0/1), whether the Hi-Z build is timed with the cull
// (0/1), and the sampling pattern (OcclusionPattern: 0 multi-jittered, the default; 1 regular).
// The path is the one the count chooses.
void BM_LightCull(benchmark::State& state) {
  light_cull(state, static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)), state.range(2) != 0,
             state.range(3) != 0, static_cast<OcclusionPattern>(state.range(4)), detail::LightCullPath::device, true);
}

BENCHMARK(BM_LightCull)
    ->Args({10, 4, 0, 0, 0})
    ->Args({1000, 4, 0, 0, 0})
    ->Args({1000000, 4, 0, 0, 0})
    ->Args({1000000, 4, 1, 0, 0})
    ->Args({1000000, 1, 0, 0, 0})
    ->Args({1000000, 8, 0, 0, 0})
    ->Args({1000000, 16, 0, 0, 0})
    ->Args({10, 4, 0, 1, 0})
    ->Args({1000, 1, 0, 0, 0})
    ->Args({1000, 8, 0, 0, 0})
    ->Args({1000, 16, 0, 0, 0})
    // The regular grid for comparison (docs/OCCLUSION.md).
    ->Args({1000000, 4, 0, 0, 1})
    ->Args({1000, 4, 0, 0, 1})
    ->ArgNames({"n", "grid", "results", "hiz", "pattern"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The two paths of the light cull on the same lights (detail::LightCullPath: 1 the four
// dispatches, 2 one workgroup), to place LightCuller::one_group_lights() (docs/OCCLUSION.md).
void BM_LightCullPath(benchmark::State& state) {
  light_cull(state, static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)), false, false,
             OcclusionPattern::multi_jittered, static_cast<detail::LightCullPath>(state.range(2)), false);
}

BENCHMARK(BM_LightCullPath)
    ->ArgsProduct({{64, 128, 256, 512, 1024}, {4, 8, 16}, {1, 2}})
    ->ArgNames({"n", "grid", "path"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
