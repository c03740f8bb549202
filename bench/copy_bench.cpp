// The copy-bandwidth floor, measured in the same run as the effects: a compute kernel that reads
// one RGBA16F image and writes another (src/bloom/shaders/image_copy.comp), timed with timestamps. Effects
// quote their time as a ratio to this (docs/PERF.md, "The floor").
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "bench_support.h"
#include "bloom/shaders/bloom_params.h"
#include "core/barriers.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

constexpr int kCopies = 16;

detail::ComputePipeline copy_pipeline(const Context& ctx, detail::Workgroup2D workgroup) {
  detail::PipelineDesc desc;
  desc.kernel_id = "image_copy_rgba16f";
  desc.bindings = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  desc.push_constant_bytes = sizeof(BloomPush);
  desc.workgroup = workgroup;
  return detail::ComputePipeline(ctx, desc);
}

// Records the barriers that make `images.src` readable and `images.dst` writable by `stage`.
void prepare_pair(VkCommandBuffer cmd, ImagePair& images, VkPipelineStageFlags2 stage, VkImageLayout src_layout,
                  VkAccessFlags2 src_access, VkImageLayout dst_layout, VkAccessFlags2 dst_access) {
  detail::Barriers b;
  b.use(images.src.state, src_layout, stage, src_access);
  b.use(images.dst.state, dst_layout, stage, dst_access);
  b.flush(cmd);
}

// Records one copy of `src` into `dst` (both width x height) with the image_copy kernel.
void record_copy(VkCommandBuffer cmd, ImagePair& images, const detail::ComputePipeline& copy, uint32_t width,
                 uint32_t height) {
  prepare_pair(cmd, images, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
               VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  BloomPush push{};
  push.dst_width = static_cast<int32_t>(width);
  push.dst_height = static_cast<int32_t>(height);
  copy.dispatch(cmd,
                {{images.src.state.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
                 {images.dst.state.view, VK_IMAGE_LAYOUT_GENERAL}},
                push, width, height);
}

void set_copy_counters(benchmark::State& state, uint32_t width, uint32_t height, const std::vector<double>& ms) {
  const double bytes = double(width) * height * 16.0;  // 8 bytes read + 8 written per texel
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(ms) * 1e3;
  state.counters["floor_bytes"] = bytes;
}

// The floor is the fastest copy the kernel makes: before timing, one frame of kCopies copies in
// each of the device's 2D workgroup (the shape glint's simple 2D kernels run in), 32x8 and 64x4
// picks the fastest shape, and the iterations time that shape alone (counters workgroup_x/y and
// the label name it). On the H200 32x8 copied 3840x2160 in 43.4 us against 48.1 in 16x8, and
// 1920x1080 in 10.0 against 14.2 (docs/PERF.md, "The floor").
void BM_CopyFloor(benchmark::State& state) {
  const auto width = static_cast<uint32_t>(state.range(0));
  const auto height = static_cast<uint32_t>(state.range(1));
  const Context& ctx = context();
  auto images = rgba16f_pair(ctx, {width, height}, 7);
  std::vector<detail::Workgroup2D> shapes = {detail::choose_workgroup_2d(ctx)};
  for (detail::Workgroup2D s : {detail::Workgroup2D{32, 8}, detail::Workgroup2D{64, 4}}) {
    const bool listed = s.x == shapes[0].x && s.y == shapes[0].y;
    if (!listed && s.x * s.y <= ctx.info().max_workgroup_invocations) shapes.push_back(s);
  }
  Profiler profiler(ctx, kCopies + 1);
  detail::ComputePipeline copy;
  detail::Workgroup2D chosen = shapes[0];
  double best = 0;
  for (detail::Workgroup2D s : shapes) {
    detail::ComputePipeline candidate = copy_pipeline(ctx, s);
    const double m = median_frame_ms(ctx, profiler, kCopies,
                                     [&](VkCommandBuffer cmd) { record_copy(cmd, images, candidate, width, height); });
    if (!copy || m < best) best = m, chosen = s, copy = std::move(candidate);
  }
  std::vector<double> all;
  for (auto _ : state) {
    const double m = median_frame_ms(ctx, profiler, kCopies,
                                     [&](VkCommandBuffer cmd) { record_copy(cmd, images, copy, width, height); });
    all.push_back(m);
    state.SetIterationTime(m * 1e-3);
  }
  set_copy_counters(state, width, height, all);
  state.counters["workgroup_x"] = chosen.x;
  state.counters["workgroup_y"] = chosen.y;
  state.SetLabel("RGBA16F image copy (" + std::to_string(chosen.x) + "x" + std::to_string(chosen.y) + ") on " +
                 ctx.info().name);
}

BENCHMARK(BM_CopyFloor)
    ->Args({640, 480})
    ->Args({1920, 1080})
    ->Args({3840, 2160})
    ->Args({7680, 4320})
    ->ArgNames({"w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The same bytes moved other ways, so that the floor above can be judged against the device's
// other copy paths (docs/PERF.md, "The floor"): the image_copy kernel in the device's 2D workgroup
// (method 0), in 8x8 (1) and in 32x8 (2); vkCmdCopyImage between the two images (3);
// vkCmdCopyBuffer of 8 bytes a texel between two buffers (4).
void BM_CopyFloorMethods(benchmark::State& state) {
  const auto method = static_cast<int>(state.range(0));
  const auto width = static_cast<uint32_t>(state.range(1));
  const auto height = static_cast<uint32_t>(state.range(2));
  const Context& ctx = context();
  auto images = rgba16f_pair(ctx, {width, height}, 7);
  const VkDeviceSize bytes_each = VkDeviceSize(width) * height * 8;
  detail::OwnedBuffer src_buffer, dst_buffer;
  Buffer src_use, dst_use;
  if (method == 4) {
    const std::vector<uint8_t> zeros(bytes_each);
    src_buffer = device_buffer(ctx, zeros.data(), bytes_each, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    dst_buffer = device_buffer(ctx, nullptr, bytes_each, 0);
    src_use = buffer_view(src_buffer, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    dst_use = buffer_view(dst_buffer, 0, false);
  }
  const detail::Workgroup2D shape = method == 1   ? detail::Workgroup2D{8, 8}
                                    : method == 2 ? detail::Workgroup2D{32, 8}
                                                  : detail::choose_workgroup_2d(ctx);
  if (method <= 2 && shape.x * shape.y > ctx.info().max_workgroup_invocations) {
    state.SkipWithError(("a " + std::to_string(shape.x) + "x" + std::to_string(shape.y) +
                         " workgroup exceeds the device's maxComputeWorkGroupInvocations")
                            .c_str());
    return;
  }
  detail::ComputePipeline copy;
  if (method <= 2) copy = copy_pipeline(ctx, shape);
  Profiler profiler(ctx, kCopies + 1);
  std::vector<double> all;
  for (auto _ : state) {
    const double m = median_frame_ms(ctx, profiler, kCopies, [&](VkCommandBuffer cmd) {
      if (method <= 2) {
        record_copy(cmd, images, copy, width, height);
        return;
      }
      if (method == 3) {
        prepare_pair(cmd, images, VK_PIPELINE_STAGE_2_COPY_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_ACCESS_2_TRANSFER_WRITE_BIT);
        VkImageCopy region{};
        region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.extent = {width, height, 1};
        vkCmdCopyImage(cmd, images.src.state.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, images.dst.state.image,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      } else {
        detail::Barriers b;
        b.use(src_use, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        b.use(dst_use, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        b.flush(cmd);
        const VkBufferCopy region{0, 0, bytes_each};
        vkCmdCopyBuffer(cmd, src_buffer.buffer(), dst_buffer.buffer(), 1, &region);
      }
    });
    all.push_back(m);
    state.SetIterationTime(m * 1e-3);
  }
  set_copy_counters(state, width, height, all);
  static const char* const kNames[] = {"image_copy kernel, device workgroup", "image_copy kernel, 8x8",
                                       "image_copy kernel, 32x8", "vkCmdCopyImage", "vkCmdCopyBuffer"};
  state.SetLabel(std::string(kNames[method]) + " on " + ctx.info().name);
}

BENCHMARK(BM_CopyFloorMethods)
    ->ArgsProduct({{0, 1, 2, 3, 4}, {1920}, {1080}})
    ->ArgsProduct({{0, 1, 2, 3, 4}, {3840}, {2160}})
    ->ArgNames({"method", "w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// What a dispatch costs beyond its work: one frame of `dispatches` copies of a small image, in the
// device's 2D workgroup. Dependent (dependent:1): each copy reads what the one before it wrote (A
// to B, B to A, ...), with the barrier between them, as the stages of an effect chain do.
// Independent (dependent:0): every copy reads the same image into an image of its own, all their
// barriers recorded before the first, so nothing waits between them. median_us / dispatches is
// the launch (independent) or the launch, drain and barrier (dependent) of one small dispatch: the
// fixed part of each stage of bloom's and the culls' chains (docs/PERF.md, "The floor").
void BM_DispatchChain(benchmark::State& state) {
  const bool dependent = state.range(0) != 0;
  const auto dispatches = static_cast<uint32_t>(state.range(1));
  const auto width = static_cast<uint32_t>(state.range(2));
  const auto height = static_cast<uint32_t>(state.range(3));
  const Context& ctx = context();
  auto images = rgba16f_pair(ctx, {width, height}, 7);
  std::vector<detail::OwnedImage> outs;
  for (uint32_t i = 1; !dependent && i < dispatches; ++i) {
    outs.emplace_back(ctx, VkExtent2D{width, height}, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  }
  const detail::ComputePipeline copy = copy_pipeline(ctx, detail::choose_workgroup_2d(ctx));
  BloomPush push{};
  push.dst_width = static_cast<int32_t>(width);
  push.dst_height = static_cast<int32_t>(height);
  auto frame = [&](VkCommandBuffer cmd) {
    if (dependent) {
      for (uint32_t i = 0; i < dispatches; ++i) {
        record_copy(cmd, images, copy, width, height);
        std::swap(images.src, images.dst);
      }
      return;
    }
    detail::Barriers b;
    b.use(images.src.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    b.use(images.dst.state, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
          VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    for (detail::OwnedImage& o : outs) {
      b.use(o.state, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    }
    b.flush(cmd);
    for (uint32_t i = 0; i < dispatches; ++i) {
      const VkImageView dst = i == 0 ? images.dst.state.view : outs[i - 1].state.view;
      copy.dispatch(cmd,
                    {{images.src.state.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}, {dst, VK_IMAGE_LAYOUT_GENERAL}},
                    push, width, height);
    }
  };
  const std::vector<double> all = time_frames(state, kCopies, frame);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["us_per_dispatch"] = median_of(all) * 1e3 / dispatches;
  state.SetLabel(std::string(dependent ? "dependent" : "independent") + " RGBA16F copies on " + ctx.info().name);
}

BENCHMARK(BM_DispatchChain)
    ->ArgsProduct({{0, 1}, {1, 4, 16}, {64}, {64}})
    ->ArgsProduct({{0, 1}, {1, 4, 16}, {480}, {270}})
    ->ArgNames({"dependent", "dispatches", "w", "h"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace glint::bench
