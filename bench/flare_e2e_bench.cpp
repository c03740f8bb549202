// Lens flares end to end (speed target in docs/PERF.md: 10 lights at 1920x1080, Hi-Z + cull + draw,
// at most 30 us median GPU time on the H100): LensFlarePass::record() on device-local resources, i.e. the
// Hi-Z build of a D32 depth buffer, the cull + 4x4 occlusion grid + compaction, the finalize kernel
// and the indirect draw (raster: vkCmdDrawIndirect; compute: splat + resolve), into an RGBA16F
// image. GPU time from timestamps as manual time (median of the frames of one command buffer).
//
// The scene is the occlusion benchmark's kind (reference::random_scene: sloped depth boxes, lights
// in front of and behind them, at the edges, off screen, behind the camera), with flare sizes of
// 8 to 128 px. Counters: median_us, visible / occluded / frustum_culled lights of the frame, and
// the split into Hi-Z, cull (+ finalize) and draw of one more frame, and each mark's own time
// (us_ and the profiler label).
#include <benchmark/benchmark.h>
#include <glint/flare_pass.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <string>

#include "bench_support.h"
#include "core/barriers.h"
#include "core/resources.h"
#include "reference/occlusion_reference.h"
#include "support/transfer.h"
#include "visibility/light_cull_internal.h"

namespace glint::bench {
namespace {

void BM_FlareEndToEnd(benchmark::State& state) {
  const auto lights = static_cast<uint32_t>(state.range(0));
  const bool compute = state.range(1) != 0;
  const auto visibility = state.range(2);  // 0: as the pass chooses, 1: the pyramid, 2: the depth image
  const Context& ctx = context();
  const uint32_t w = 1920, h = 1080;
  const auto scene = reference::random_scene(w, h, lights, 2024, false, 128.0);

  FlarePassConfig pc;
  pc.extent = {w, h};
  pc.cull.capacity = std::max(lights, 1u);
  pc.cull.max_lights = std::max(lights, 1u);
  pc.max_size_px = 128.0f;
  pc.draw = compute ? FlareDrawPath::compute : FlareDrawPath::raster;
  pc.clamp_capacity = true;
  LensFlarePass pass(ctx, pc);
  if (visibility == 1) detail::LightCullAccess::select_path(pass.culler(), detail::LightCullPath::pyramid);
  if (visibility >= 2) detail::LightCullAccess::select_path(pass.culler(), detail::LightCullPath::depth);
  if (visibility >= 3) {
    try {
      constexpr uint32_t kSizes[] = {64, 128, 512, 1024};
      detail::LightCullAccess::set_depth_workgroup(pass.culler(), kSizes[std::min<int64_t>(visibility - 3, 3)]);
    } catch (const Error& e) {  // CPU devices: the one-workgroup cull has 64 invocations
      state.SkipWithError(e.what());
      return;
    }
  }

  detail::OwnedImage color(ctx, {w, h}, VK_FORMAT_R16G16B16A16_SFLOAT,
                           detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  detail::upload(ctx, color.state, random_hdr(w, h, 7));
  detail::OwnedImage depth(ctx, {w, h}, VK_FORMAT_D32_SFLOAT,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  detail::upload_r32(ctx, depth.state, scene.depth.depth);
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize bytes = std::max<VkDeviceSize>(VkDeviceSize(lights) * sizeof(GlintFlareLight), 16);
  detail::OwnedBuffer light_buffer(ctx, bytes, usage, false);
  {
    detail::OwnedBuffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    std::memcpy(staging.mapped(), scene.lights.data(), size_t(lights) * sizeof(GlintFlareLight));
    staging.flush();
    ctx.run_once([&](VkCommandBuffer cmd) {
      const VkBufferCopy region{0, 0, bytes};
      vkCmdCopyBuffer(cmd, staging.buffer(), light_buffer.buffer(), 1, &region);
    });
  }
  Buffer lv{light_buffer.buffer(), 0, bytes, usage, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  std::array<float, 16> view_proj{};
  for (int i = 0; i < 16; ++i) view_proj[i] = static_cast<float>(scene.view_proj[i]);
  const FlareConfig look = FlareConfig::preset(FlarePreset::cinematic);
  auto frame = [&](VkCommandBuffer cmd, Profiler* p) {
    pass.record(cmd, color.state, depth.state, lv, lights, view_proj.data(), look, p);
  };
  ctx.run_once([&](VkCommandBuffer cmd) { frame(cmd, nullptr); });  // warm-up: descriptor sets, caches

  constexpr int kFrames = 16;
  Profiler profiler(ctx, kFrames + 1);
  std::vector<double> all;
  for (auto _ : state) {
    const double ms = median_frame_ms(ctx, profiler, kFrames, [&](VkCommandBuffer cmd) { frame(cmd, nullptr); });
    all.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
  }

  // One more frame with the parts' marks, and its statistics.
  detail::OwnedBuffer readback(ctx, sizeof(GlintFlareStats), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  const std::vector<Profiler::Stage> stages = stage_marks(ctx, 16, [&](VkCommandBuffer cmd, Profiler* p) {
    frame(cmd, p);
    detail::Barriers b;
    b.use(pass.stats(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    const VkBufferCopy region{0, 0, sizeof(GlintFlareStats)};
    vkCmdCopyBuffer(cmd, pass.stats().buffer, readback.buffer(), 1, &region);
    Buffer rb{readback.buffer(), 0, readback.size(), 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
    b.use(rb, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
  });
  readback.invalidate();
  GlintFlareStats st;
  std::memcpy(&st, readback.mapped(), sizeof st);
  double hiz_us = 0, cull_us = 0, draw_us = 0;
  std::map<std::string, double> by_label;  // us_ + label (spaces as '_'): each dispatch's mark
  for (const auto& s : stages) {
    std::string key = "us_" + s.label;
    std::replace(key.begin(), key.end(), ' ', '_');
    by_label[key] += s.ms * 1e3;
    if (s.label.rfind("hi-z", 0) == 0) {
      hiz_us += s.ms * 1e3;
    } else if (s.label.find("cull") != std::string::npos) {
      cull_us += s.ms * 1e3;
    } else {
      draw_us += s.ms * 1e3;
    }
  }
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["visible"] = st.visible;
  state.counters["occluded"] = st.occluded;
  state.counters["frustum_culled"] = st.frustum_culled;
  state.counters["overflow"] = st.overflow;
  state.counters["us_hiz"] = hiz_us;
  state.counters["us_cull"] = cull_us;
  state.counters["us_draw"] = draw_us;
  for (const auto& [key, us] : by_label) {
    if (key != "us_hiz" && key != "us_cull" && key != "us_draw") state.counters[key] = us;
  }
  const bool pyramid = pass.culler().needs_pyramid(pass.hiz(), lights);
  state.counters["reads_pyramid"] = pyramid ? 1 : 0;
  state.SetLabel(std::string(compute ? "compute" : "raster") + " rgba16f, " +
                 (pyramid ? "hi-z levels " + std::to_string(pass.hiz().levels()) : std::string("depth image")) +
                 " on " + ctx.info().name);
}

// visibility: 0 as LensFlarePass chooses (the speed table's rows), 1 the Hi-Z pyramid, 2 the depth
// image read by the cull (LightCuller::needs_pyramid; docs/OCCLUSION.md): where the choice turns;
// 3 to 6 the depth image in workgroups of 64, 128, 512 and 1024 (the default is 256 on GPUs).
BENCHMARK(BM_FlareEndToEnd)
    ->Args({10, 0, 0})
    ->Args({10, 1, 0})
    ->Args({1000, 0, 0})
    ->Args({1000, 1, 0})
    ->Args({10, 1, 1})
    ->Args({10, 1, 2})
    ->Args({10, 1, 3})
    ->Args({10, 1, 4})
    ->Args({10, 1, 5})
    ->Args({10, 1, 6})
    ->Args({10, 0, 1})
    ->Args({31, 1, 1})
    ->Args({31, 1, 2})
    ->Args({64, 1, 1})
    ->Args({64, 1, 2})
    ->Args({128, 1, 1})
    ->Args({128, 1, 2})
    ->ArgNames({"lights", "compute", "visibility"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
