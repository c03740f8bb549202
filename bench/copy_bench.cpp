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

// The same bytes moved other ways, so that the floor above can be judged against the device's
// other copy paths (docs/PERF.md, "The floor"): method 0 is BM_CopyFloor's kernel (the 2D
// workgroup the device gets), 1 and 2 the same kernel in 8x8 and 32x8 workgroups, 3
// vkCmdCopyImage between the two images, 4 vkCmdCopyBuffer of 8 bytes a texel between buffers.
void BM_CopyFloorMethods(benchmark::State& state) {
  const auto method = static_cast<int>(state.range(0));
  const auto width = static_cast<uint32_t>(state.range(1));
  const auto height = static_cast<uint32_t>(state.range(2));
  const Context& ctx = context();
  auto [src, dst] = rgba16f_pair(ctx, {width, height}, 7);
  const VkDeviceSize bytes_each = VkDeviceSize(width) * height * 8;
  detail::OwnedBuffer src_buffer, dst_buffer;
  Buffer src_use, dst_use;
  if (method == 4) {
    src_buffer = detail::OwnedBuffer(ctx, bytes_each,
                                     VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
    dst_buffer = detail::OwnedBuffer(ctx, bytes_each, VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
    src_use = {src_buffer.buffer(), 0, bytes_each, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT};
    dst_use = {dst_buffer.buffer(), 0, bytes_each, VK_BUFFER_USAGE_TRANSFER_DST_BIT};
  }
  detail::PipelineDesc desc;
  desc.kernel_id = "image_copy_rgba16f";
  desc.bindings = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  desc.push_constant_bytes = sizeof(BloomPush);
  desc.workgroup = method == 1   ? detail::Workgroup2D{8, 8}
                   : method == 2 ? detail::Workgroup2D{32, 8}
                                 : detail::choose_workgroup_2d(ctx);
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
      if (method <= 2) {
        b.use(src.state, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
              VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        b.use(dst.state, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
              VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        b.flush(cmd);
        copy.dispatch(
            cmd,
            {{src.state.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}, {dst.state.view, VK_IMAGE_LAYOUT_GENERAL}},
            push, width, height);
      } else if (method == 3) {
        b.use(src.state, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
              VK_ACCESS_2_TRANSFER_READ_BIT);
        b.use(dst.state, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
              VK_ACCESS_2_TRANSFER_WRITE_BIT);
        b.flush(cmd);
        VkImageCopy region{};
        region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.extent = {width, height, 1};
        vkCmdCopyImage(cmd, src.state.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.state.image,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      } else {
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
  const double bytes = double(width) * height * 16.0;  // 8 bytes read + 8 written per texel
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["median_us"] = median_of(all) * 1e3;
  state.counters["floor_bytes"] = bytes;
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

}  // namespace
}  // namespace glint::bench
