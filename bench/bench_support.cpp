#include "bench_support.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>

#include "support/environment.h"

namespace glint::bench {

const Context& context() {
  static std::unique_ptr<Context> ctx = [] {
    auto c = std::make_unique<Context>(Context::create(tools::context_options_from_environment()));
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

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace glint::bench
