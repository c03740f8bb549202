#include "bench_support.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>

#include "support/environment.h"
#include "support/transfer.h"

namespace glint::bench {

namespace {
bool g_kernel_statistics = false;
}  // namespace

void set_kernel_statistics(bool on) { g_kernel_statistics = on; }

const Context& context() {
  static std::unique_ptr<Context> ctx = [] {
    ContextOptions options;
    options.kernel_statistics = g_kernel_statistics;
    auto c = std::make_unique<Context>(Context::create(tools::context_options_from_environment(options)));
    std::fprintf(stderr, "glint_bench: device %s\n", c->info().name.c_str());
    return c;
  }();
  return *ctx;
}

CpuImage random_hdr(uint32_t width, uint32_t height, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> base(0.0f, 1.5f), unit(0.0f, 1.0f);
  CpuImage img(width, height);
  for (size_t i = 0; i < size_t(width) * height; ++i) {
    const bool bright = unit(rng) < 0.02f;
    for (int c = 0; c < 3; ++c) img.rgba[i * 4 + c] = bright ? 2.0f + 38.0f * unit(rng) : base(rng);
    img.rgba[i * 4 + 3] = 1.0f;
  }
  return img;
}

double median_frame_ms(const Context& context, Profiler& profiler, int frames,
                       const std::function<void(VkCommandBuffer)>& record_frame) {
  context.run_once([&](VkCommandBuffer cmd) {
    profiler.reset(cmd);
    profiler.mark(cmd, "start");
    for (int i = 0; i < frames; ++i) {
      record_frame(cmd);
      profiler.mark(cmd, "frame");
    }
  });
  std::vector<double> ms;
  for (const auto& s : profiler.results()) ms.push_back(s.ms);
  return median_of(ms);
}

std::vector<Profiler::Stage> stage_marks(const Context& context, uint32_t capacity,
                                         const std::function<void(VkCommandBuffer, Profiler*)>& record_frame) {
  Profiler stages(context, capacity);
  context.run_once([&](VkCommandBuffer cmd) {
    stages.reset(cmd);
    stages.mark(cmd, "start");
    record_frame(cmd, &stages);
  });
  return stages.results();
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

detail::OwnedBuffer device_buffer(const Context& ctx, const void* data, VkDeviceSize bytes, VkBufferUsageFlags usage) {
  detail::OwnedBuffer buf(ctx, std::max<VkDeviceSize>(bytes, 16), usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
  if (data && bytes) {
    detail::OwnedBuffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    std::memcpy(staging.mapped(), data, bytes);
    staging.flush();
    ctx.run_once([&](VkCommandBuffer cmd) {
      VkBufferCopy region{0, 0, bytes};
      vkCmdCopyBuffer(cmd, staging.buffer(), buf.buffer(), 1, &region);
    });
  }
  return buf;
}

Buffer buffer_view(const detail::OwnedBuffer& b, VkBufferUsageFlags usage, bool after_copy) {
  Buffer v{b.buffer(),      0, b.size(), usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_PIPELINE_STAGE_2_NONE,
           VK_ACCESS_2_NONE};
  if (after_copy) {
    v.stage = VK_PIPELINE_STAGE_2_COPY_BIT;
    v.access = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  }
  return v;
}

std::vector<double> time_frames(benchmark::State& state, int frames,
                                const std::function<void(VkCommandBuffer)>& record_frame) {
  const Context& ctx = context();
  Profiler profiler(ctx, frames + 1);
  std::vector<double> frame_ms;
  for (auto _ : state) {
    const double median = median_frame_ms(ctx, profiler, frames, record_frame);
    frame_ms.push_back(median);
    state.SetIterationTime(median * 1e-3);
  }
  return frame_ms;
}

ImagePair rgba16f_pair(const Context& ctx, VkExtent2D extent, uint32_t stream) {
  const VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
  ImagePair pair{detail::OwnedImage(ctx, extent, format, detail::kToolImageUsage),
                 detail::OwnedImage(ctx, extent, format, detail::kToolImageUsage)};
  detail::upload(ctx, pair.src.state, random_hdr(extent.width, extent.height, stream));
  return pair;
}

detail::OwnedImage depth_image(const Context& ctx, const reference::DepthImage& d) {
  detail::OwnedImage img(ctx, {d.width, d.height}, VK_FORMAT_D32_SFLOAT,
                         VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  detail::upload_r32(ctx, img.state, d.depth);
  return img;
}

}  // namespace glint::bench
