#include "support/gpu_test.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "core/barriers.h"
#include "core/half.h"
#include "core/packed_float.h"
#include "support/environment.h"

namespace glint::test {

const Context& context() {
  static std::unique_ptr<Context> ctx = [] {
    // Validation is always on, except where GLINT_VALIDATION=0 says the layer is absent.
    ContextOptions options;
    options.validation = true;
    return std::make_unique<Context>(Context::create(tools::context_options_from_environment(options)));
  }();
  return *ctx;
}

void GpuTest::SetUp() { messages_before_ = context().validation_messages(); }

void GpuTest::TearDown() {
  const uint32_t after = context().validation_messages();
  if (after != messages_before_) {
    auto log = context().validation_log();
    std::string text;
    for (size_t i = messages_before_; i < log.size(); ++i) text += log[i] + "\n";
    ADD_FAILURE() << (after - messages_before_) << " validation message(s):\n" << text;
  }
}

CpuImage random_hdr(uint32_t width, uint32_t height, uint32_t stream, float bright_fraction, float peak) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> base(0.0f, 1.5f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  CpuImage img(width, height);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      float* px = img.at(x, y);
      const bool bright = unit(rng) < bright_fraction;
      for (int c = 0; c < 3; ++c) px[c] = bright ? 2.0f + unit(rng) * (peak - 2.0f) : base(rng);
      px[3] = unit(rng);
    }
  }
  return img;
}

detail::OwnedImage make_image(const CpuImage& pixels, VkFormat format) {
  detail::OwnedImage img(context(), {pixels.width, pixels.height}, format, detail::kToolImageUsage);
  detail::upload(context(), img.state, pixels);
  return img;
}

detail::OwnedImage make_poisoned(VkExtent2D extent, VkFormat format) {
  detail::OwnedImage img(context(), extent, format, detail::kToolImageUsage);
  detail::fill(context(), img.state, std::nanf(""));
  return img;
}

bool all_finite(const CpuImage& image) {
  for (float v : image.rgba) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

bool bit_equal(const CpuImage& a, const CpuImage& b) {
  return a.width == b.width && a.height == b.height && a.rgba.size() == b.rgba.size() &&
         std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(float)) == 0;
}

CpuImage as_stored(const CpuImage& img, VkFormat format) {
  CpuImage out = img;
  for (size_t i = 0; i < out.rgba.size(); i += 4) {
    float* t = &out.rgba[i];
    if (format == VK_FORMAT_R16G16B16A16_SFLOAT) {
      for (int c = 0; c < 4; ++c) t[c] = detail::round_to_half(t[c]);
    } else if (format == VK_FORMAT_B10G11R11_UFLOAT_PACK32) {
      detail::unpack_b10g11r11(detail::pack_b10g11r11(t[0], t[1], t[2]), t);
      t[3] = 1.0f;  // no alpha: reads as 1
    } else if (format == VK_FORMAT_R32G32B32_SFLOAT) {
      t[3] = 1.0f;
    }
  }
  return out;
}

void to_host(VkCommandBuffer cmd, Buffer& b) {
  detail::Barriers barriers;
  barriers.use(b, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
  barriers.flush(cmd);
}

AdoptInfo adopt_info_of_context() {
  AdoptInfo a;
  a.instance = context().instance();
  a.api_version = VK_API_VERSION_1_3;
  a.physical_device = context().physical_device();
  a.device = context().device();
  a.queue_family_index = context().queue_family_index();
  return a;
}

}  // namespace glint::test
