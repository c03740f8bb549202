// Object occlusion cull benchmark (include/glint/object_cull.h): single-phase cull of 1 M and 10 M
// bounding spheres and boxes against the Hi-Z of a 1920x1080 depth buffer, on device-local
// buffers. GPU time from timestamps (median frame of one command buffer), bytes/s over the bytes a
// cull must move (ObjectCuller::min_bytes_moved), the visible share, and a check of the first 4096
// objects' states against the float64 reference (mismatches outside the documented ambiguity
// must be 0).
#include <benchmark/benchmark.h>
#include <glint/object_cull.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "bench_support.h"
#include "core/barriers.h"
#include "core/resources.h"
#include "reference/object_cull_reference.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;

Buffer view_of(const detail::OwnedBuffer& b, bool after_copy) {
  Buffer v{b.buffer(), 0, b.size(), kUsage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  if (after_copy) {
    v.stage = VK_PIPELINE_STAGE_2_COPY_BIT;
    v.access = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  }
  return v;
}

detail::OwnedBuffer upload(const Context& ctx, const void* data, VkDeviceSize bytes) {
  detail::OwnedBuffer buf(ctx, bytes, kUsage, false);
  detail::OwnedBuffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  std::memcpy(staging.mapped(), data, bytes);
  staging.flush();
  ctx.run_once([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, staging.buffer(), buf.buffer(), 1, &region);
  });
  return buf;
}

void BM_ObjectCull(benchmark::State& state) {
  const auto count = static_cast<uint32_t>(state.range(0));
  const Context& ctx = context();
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(ctx.physical_device(), &props);
  if (uint64_t(count) * sizeof(GlintCullObject) > props.limits.maxStorageBufferRange) {
    state.SkipWithError("the object buffer exceeds this device's maxStorageBufferRange");
    for (auto _ : state) {
    }
    return;
  }
  const uint32_t w = 1920, h = 1080;
  const auto scene = reference::random_scene(w, h, 0, 2024, false, 1);
  reference::ObjectCamera cam{};
  for (int i = 0; i < 16; ++i) cam.view[i] = i % 5 == 0 ? 1.0f : 0.0f;
  reference::perspective(1.0, double(w) / h, 0.1, 100.0, false, true, cam.proj);
  // Objects spread over the view volume and around it, 1/4 boxes, sizes from sub-pixel to large.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<GlintCullObject> objects(count);
  for (auto& o : objects) {
    const float d = 0.5f + 60.0f * u(rng), x = (u(rng) * 2.4f - 1.2f) * d, y = (u(rng) * 2.4f - 1.2f) * d;
    const float r = d * 0.02f * u(rng) * u(rng);
    o = {};
    if (u(rng) < 0.25f) {
      o.kind = GLINT_OBJECT_BOX;
      const float c[3] = {x, y, -d};
      for (int a = 0; a < 3; ++a) {
        o.sphere_or_min[a] = c[a] - r;
        o.box_max[a] = c[a] + r;
      }
    } else {
      o.kind = GLINT_OBJECT_SPHERE;
      o.sphere_or_min[0] = x;
      o.sphere_or_min[1] = y;
      o.sphere_or_min[2] = -d;
      o.sphere_or_min[3] = r;
    }
  }
  detail::OwnedImage depth(ctx, {w, h}, VK_FORMAT_D32_SFLOAT,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  detail::upload_r32(ctx, depth.state, scene.depth.depth);
  HiZConfig hc;
  hc.extent = {w, h};
  HiZPyramid hiz(ctx, hc);
  ObjectCullConfig cc;
  cc.max_objects = count;
  cc.capacity = count;
  ObjectCuller culler(ctx, cc);
  auto obj_buf = upload(ctx, objects.data(), VkDeviceSize(count) * sizeof(GlintCullObject));
  detail::OwnedBuffer vis(ctx, VkDeviceSize(count) * 4, kUsage, false),
      list(ctx, VkDeviceSize(count) * 4, kUsage, false);
  detail::OwnedBuffer indirect(ctx, sizeof(GlintObjectCullIndirect), kUsage, false);
  detail::OwnedBuffer stats(ctx, sizeof(GlintObjectCullStats), kUsage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  ObjectCullBuffers buffers{view_of(obj_buf, true), {}, view_of(vis, false)};
  ObjectCullOutputs outputs{view_of(list, false), view_of(indirect, false), view_of(stats, false)};
  ObjectCullFrame frame;
  std::copy(cam.view, cam.view + 16, frame.view);
  std::copy(cam.proj, cam.proj + 16, frame.proj);
  frame.count = count;
  ctx.run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, depth.state); });
  const int frames = ctx.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 2 : 16;
  Profiler profiler(ctx, frames + 1);
  std::vector<double> all;
  for (auto _ : state) {
    const double ms = median_frame_ms(ctx, profiler, frames, [&](VkCommandBuffer cmd) {
      culler.record(cmd, hiz, depth.state, frame, buffers, outputs);
    });
    all.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
  }
  // Per-stage times of one more frame (the medians above are of whole frames).
  Profiler stages(ctx, 8);
  ctx.run_once([&](VkCommandBuffer cmd) {
    stages.reset(cmd);
    stages.mark(cmd, "start");
    culler.record(cmd, hiz, depth.state, frame, buffers, outputs, &stages);
  });
  for (const auto& st : stages.results()) {
    std::string key = st.label + "_us";
    std::replace(key.begin(), key.end(), ' ', '_');
    state.counters[key] = st.ms * 1e3;
  }
  ctx.run_once([&](VkCommandBuffer cmd) {
    detail::Barriers b;
    b.use(outputs.stats, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.use(buffers.visibility, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
  });
  stats.invalidate();
  const GlintObjectCullStats st = *static_cast<const GlintObjectCullStats*>(stats.mapped());
  // The first objects' states against the reference.
  const uint32_t checked = std::min(count, 4096u);
  detail::OwnedBuffer back(ctx, VkDeviceSize(checked) * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  ctx.run_once([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, VkDeviceSize(checked) * 4};
    vkCmdCopyBuffer(cmd, vis.buffer(), back.buffer(), 1, &region);
  });
  back.invalidate();
  const auto* states = static_cast<const uint32_t*>(back.mapped());
  const auto pyramid = reference::hiz_pyramid(scene.depth, false, hiz.levels());
  uint64_t mismatches = 0;
  for (uint32_t i = 0; i < checked; ++i) {
    const auto v = reference::judge_object(objects[i], cam, scene.depth, pyramid);
    if (!v.ambiguous && v.expected != states[i]) ++mismatches;
    if (v.brute == GLINT_OBJECT_STATE_VISIBLE && states[i] != GLINT_OBJECT_STATE_VISIBLE) ++mismatches;
  }
  const double bytes = double(culler.min_bytes_moved(count, st.written));
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["objects_per_second"] =
      benchmark::Counter(double(count), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["visible_share"] = double(st.visible) / count;
  state.counters["occluded_share"] = double(st.occluded) / count;
  state.counters["mismatches_vs_f64"] = double(mismatches + (st.total != count));
  state.SetLabel("1920x1080 D32 on " + ctx.info().name);
}

BENCHMARK(BM_ObjectCull)
    ->Arg(1000000)
    ->Arg(10000000)
    ->ArgNames({"objects"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
