// Object occlusion cull benchmark (include/glint/object_cull.h): single-phase cull of 1 M and 10 M
// bounding spheres and boxes against the Hi-Z of a 1920x1080 depth buffer, on device-local
// buffers. GPU time from timestamps (median frame of one command buffer) and per stage, bytes/s
// over the bytes a cull must move (ObjectCuller::min_bytes_moved), the visible share, a check of
// the first 4096 objects' states against the float64 reference (mismatches outside the documented
// ambiguity must be 0) and their false-positive share (hidden by brute force, kept by the cull:
// docs/charts/object_cull_fp_time.svg plots it against the time, per kind of bound).
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
#include "visibility/object_cull_internal.h"

namespace glint::bench {
namespace {

constexpr VkBufferUsageFlags kUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
const char* const kBounds[] = {"mixed", "spheres", "boxes"};

// `count` objects; bounds 0: 1/4 boxes, 1: all spheres, 2: all boxes (the same centres and sizes,
// so the bounds' false-positive shares and times compare). `previous`: the previous test kernel
// (object_cull_v1.comp), for the comparison with the current one in one run.
void run_object_cull(benchmark::State& state, uint32_t count, int bounds, bool previous = false) {
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
    const bool box = u(rng) < 0.25f;
    o = {};
    if (bounds == 0 ? box : bounds == 2) {
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
  detail::OwnedImage depth = depth_image(ctx, scene.depth);
  HiZConfig hc;
  hc.extent = {w, h};
  HiZPyramid hiz(ctx, hc);
  ObjectCullConfig cc;
  cc.max_objects = count;
  cc.capacity = count;
  ObjectCuller culler(ctx, cc);
  detail::object_cull_select_kernel(culler,
                                    previous ? detail::ObjectCullKernel::previous : detail::ObjectCullKernel::current);
  auto obj_buf = device_buffer(ctx, objects.data(), VkDeviceSize(count) * sizeof(GlintCullObject), kUsage);
  auto vis = device_buffer(ctx, nullptr, VkDeviceSize(count) * 4, kUsage);
  auto list = device_buffer(ctx, nullptr, VkDeviceSize(count) * 4, kUsage);
  auto indirect = device_buffer(ctx, nullptr, sizeof(GlintObjectCullIndirect), kUsage);
  detail::OwnedBuffer stats(ctx, sizeof(GlintObjectCullStats), kUsage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  ObjectCullBuffers buffers{buffer_view(obj_buf, kUsage, true), {}, buffer_view(vis, kUsage, false)};
  ObjectCullOutputs outputs{buffer_view(list, kUsage, false), buffer_view(indirect, kUsage, false),
                            buffer_view(stats, kUsage, false)};
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
  uint64_t mismatches = 0, hidden = 0, false_positives = 0;
  for (uint32_t i = 0; i < checked; ++i) {
    const auto v = reference::judge_object(objects[i], cam, scene.depth, pyramid);
    if (!v.ambiguous && v.expected != states[i]) ++mismatches;
    if (v.brute == GLINT_OBJECT_STATE_VISIBLE && states[i] != GLINT_OBJECT_STATE_VISIBLE) ++mismatches;
    // False positive: hidden at full resolution with the exact bound (frustum or occluded), kept.
    if (v.brute != GLINT_OBJECT_STATE_VISIBLE) {
      ++hidden;
      false_positives += states[i] == GLINT_OBJECT_STATE_VISIBLE;
    }
  }
  const double bytes = double(culler.min_bytes_moved(count, st.written));
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["objects_per_second"] =
      benchmark::Counter(double(count), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["visible_share"] = double(st.visible) / count;
  state.counters["occluded_share"] = double(st.occluded) / count;
  state.counters["mismatches_vs_f64"] = double(mismatches + (st.total != count));
  // Of the first objects that are hidden by brute force, the share the cull keeps (draws anyway).
  state.counters["false_positive_share"] = hidden ? double(false_positives) / double(hidden) : 0.0;
  state.counters["checked_hidden"] = double(hidden);
  state.SetLabel(std::string("1920x1080 D32, ") + kBounds[bounds] + (previous ? ", previous kernel" : "") + " on " +
                 ctx.info().name);
}

// Args: objects (1/4 boxes).
void BM_ObjectCull(benchmark::State& state) { run_object_cull(state, static_cast<uint32_t>(state.range(0)), 0); }

// Args: objects, bounds (1: all spheres, 2: all boxes).
void BM_ObjectCullBounds(benchmark::State& state) {
  run_object_cull(state, static_cast<uint32_t>(state.range(0)), static_cast<int>(state.range(1)));
}

// Args: objects, bounds (0: 1/4 boxes, 1: spheres, 2: boxes); the previous test kernel
// (object_cull_v1.comp), to compare with BM_ObjectCull / BM_ObjectCullBounds in the same run.
void BM_ObjectCullPrevious(benchmark::State& state) {
  run_object_cull(state, static_cast<uint32_t>(state.range(0)), static_cast<int>(state.range(1)), true);
}

BENCHMARK(BM_ObjectCull)
    ->Arg(1000000)
    ->Arg(10000000)
    ->ArgNames({"objects"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_ObjectCullBounds)
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->ArgNames({"objects", "bounds"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_ObjectCullPrevious)
    ->Args({1000000, 0})
    ->Args({10000000, 0})
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->ArgNames({"objects", "bounds"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
