// Caller image formats and layers: bloom and the Gaussian blur on B10G11R11_UFLOAT and the other
// float colour formats the device supports, Hi-Z on every depth format, one layer of an array
// image, and refusals that name the format, the layer count or the feature they refused.
// Validation with synchronization validation is on (support/gpu_test.h).
#include "core/formats.h"

#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "core/barriers.h"
#include "core/check.h"
#include "core/half.h"
#include "core/packed_float.h"
#include "reference/bloom_reference.h"
#include "reference/blur_reference.h"
#include "reference/occlusion_reference.h"
#include "support/environment.h"
#include "support/flare_scene.h"
#include "support/gpu_test.h"

namespace glint::test {
namespace {

constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kB10 = VK_FORMAT_B10G11R11_UFLOAT_PACK32;

class FormatsTest : public GpuTest {};

// Usage a test image of `format` can have on this device: storage only where the format allows it
// (creating a storage image of a format without STORAGE_IMAGE is invalid).
VkImageUsageFlags usage_for(VkFormat format) {
  VkImageUsageFlags u = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (detail::format_features(context(), format) & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT)
    u |= VK_IMAGE_USAGE_STORAGE_BIT;
  return u;
}

detail::OwnedImage image_of(const CpuImage& pixels, VkFormat format) {
  detail::OwnedImage img(context(), {pixels.width, pixels.height}, format, usage_for(format));
  detail::upload(context(), img.state, pixels);
  return img;
}

detail::OwnedImage poisoned(VkExtent2D extent, VkFormat format) {
  detail::OwnedImage img(context(), extent, format, usage_for(format));
  detail::fill(context(), img.state, std::nanf(""));
  return img;
}

// The store rounding of channel c of `format`, relative: a conversion may round to nearest or
// toward zero (Vulkan, "Floating-Point Format Conversions"; the 11- and 10-bit formats name both),
// so one unit in the last place of an M-bit mantissa, 2^-M. B10G11R11: 6 bits for R, G, 5 for B.
double store_ulp(VkFormat format, int c) {
  if (format == kB10) return std::ldexp(1.0, c == 2 ? -5 : -6);
  if (format == kF16) return std::ldexp(1.0, -10);
  return 0.0;
}

// The smallest normal value's ulp of a channel: the absolute error of a denormal (or a flush).
double store_floor(VkFormat format) {
  // Both formats have denormals below 2^-14; a device that flushes them loses less than 2^-14.
  return (format == kB10 || format == kF16) ? std::ldexp(1.0, -14) : 0.0;
}

// Per channel: |gpu - ref| <= (store_ulp + 2^-14) * |ref| + store_floor. ref is clamped to what
// the format holds (UFLOAT: 0 to its largest finite value). 2^-14 bounds the fp32 arithmetic of
// the kernels relative to the float64 reference: the output is a sum of non-negative terms, each
// passing through fewer than 2^10 fp32 roundings of 2^-24 (levels x taps x the bilinear steps).
struct Deviation {
  size_t outside = 0;
  double worst = 0;  // max |gpu - ref| / bound
  std::string first;
};
Deviation compare(const CpuImage& gpu, const reference::DoubleImage& ref, VkFormat out_format) {
  Deviation d;
  for (uint32_t y = 0; y < ref.height; ++y) {
    for (uint32_t x = 0; x < ref.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        double r = ref.at(x, y)[c];
        if (out_format == kB10) r = std::clamp(r, 0.0, detail::ufloat_max(c == 2 ? 5 : 6));
        const double g = gpu.at(x, y)[c];
        const double bound =
            (store_ulp(out_format, c) + std::ldexp(1.0, -14)) * std::abs(r) + store_floor(out_format) + 1e-30;
        const double ratio = std::abs(g - r) / bound;
        if (!(ratio <= 1.0)) {
          if (d.outside++ == 0) {
            d.first = detail::concat("(", x, ", ", y, ") channel ", c, ": ", g, " vs ", r);
          }
        }
        if (std::isfinite(ratio))
          d.worst = std::max(d.worst, ratio);
        else
          d.worst = INFINITY;
      }
    }
  }
  return d;
}

CpuImage run_bloom(const BloomConfig& config, const CpuImage& input, VkFormat in_format, VkFormat out_format) {
  Bloom bloom(context(), config);
  auto in = image_of(input, in_format);
  auto out = poisoned({input.width, input.height}, out_format);
  context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
  return detail::download(context(), out.state);
}

// B10G11R11_UFLOAT in, out, and mixed with RGBA16F / RGBA32F, every filter, against the float64
// reference within the output format's rounding.
TEST_F(FormatsTest, BloomReadsAndWritesB10G11R11WithinItsRounding) {
  const CpuImage input = random_hdr(61, 47, 21);
  const struct { VkFormat in, out; } pairs[] = {{kB10, kB10}, {kF16, kB10}, {kB10, kF32}};
  for (BloomFilter filter : {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9}) {
    for (const auto& p : pairs) {
      BloomConfig config;
      config.filter = filter;
      config.precision = Precision::fp32;
      config.iterations = 4;
      config.intensity = 0.8f;
      const CpuImage gpu = run_bloom(config, input, p.in, p.out);
      const std::string what = std::string(bloom_filter_name(filter)) + " " + detail::format_name(p.in) + " -> " +
                               detail::format_name(p.out);
      ASSERT_TRUE(all_finite(gpu)) << what << ": unwritten (poisoned) texels remain";
      const CpuImage stored = as_stored(input, p.in);
      const Deviation d = compare(gpu, reference::bloom(stored, config), p.out);
      EXPECT_EQ(d.outside, 0u) << what << ", first " << d.first << ", worst " << d.worst << " x bound";
      // Alpha: 1 from a B10G11R11 input (it has none); a B10G11R11 output has none to check.
      if (p.out != kB10) {
        for (size_t i = 3; i < gpu.rgba.size(); i += 4) ASSERT_EQ(gpu.rgba[i], stored.rgba[i]) << what;
      }
      // The bound is tight enough to see a wrong parameter.
      BloomConfig other = config;
      other.radius = 1.1f;
      EXPECT_GT(compare(gpu, reference::bloom(stored, other), p.out).outside, 0u) << what;
    }
  }
}

// Intensity 0 copies: B10G11R11 to B10G11R11 is bit for bit.
TEST_F(FormatsTest, BloomCopyOfB10G11R11IsExact) {
  const CpuImage input = as_stored(random_hdr(33, 20, 4), kB10);
  BloomConfig config;
  config.intensity = 0.0f;
  const CpuImage gpu = run_bloom(config, input, kB10, kB10);
  EXPECT_EQ(std::memcmp(gpu.rgba.data(), input.rgba.data(), input.rgba.size() * 4), 0);
}

// The float colour formats without a GLSL qualifier glint compiles: read where the device samples
// them, written where it stores them without a format, refused by name otherwise.
TEST_F(FormatsTest, OtherFloatFormatsFollowTheDeviceFeatures) {
  const CpuImage input = random_hdr(40, 24, 5);
  for (VkFormat f : {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R16G16B16_SFLOAT, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32}) {
    const VkFormatFeatureFlags2 features = detail::format_features(context(), f);
    const std::string name = detail::format_name(f);
    const bool transferable = f != VK_FORMAT_E5B9G9R9_UFLOAT_PACK32;  // the test has no packer for it
    BloomConfig config;
    config.precision = Precision::fp32;
    config.iterations = 3;
    Bloom bloom(context(), config);
    // As input.
    if ((features & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT) && transferable) {
      const CpuImage gpu = run_bloom(config, input, f, kF32);
      EXPECT_LT(reference::relative_l2(gpu, reference::bloom(as_stored(input, f), config)), 1e-3) << name;
    } else if (!(features & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) {
      auto out = poisoned({8, 8}, kF32);
      Image in = out.state;
      in.format = f;  // refused before the image is used
      try {
        context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in, out.state); });
        ADD_FAILURE() << name << " input: no error, yet the device cannot sample it";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::unsupported_format);
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot sample"), std::string::npos) << e.what();
      }
    }
    // As output.
    const bool writable = (features & VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT) &&
                          (features & VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT);
    std::printf("%s on %s: input %s, output %s\n", name.c_str(), context().info().name.c_str(),
                (features & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT) ? (transferable ? "compared" : "untested")
                                                                   : "refused by name",
                writable ? (transferable ? "compared (noformat kernel)" : "untested") : "refused by name");
    if (writable && transferable) {
      const CpuImage gpu = run_bloom(config, input, kF32, f);
      EXPECT_LT(reference::relative_l2(gpu, reference::bloom(input, config)), 1e-3) << name;
    } else if (!writable) {
      auto in = image_of(input, kF32);
      Image out = in.state;
      out.format = f;
      out.usage |= VK_IMAGE_USAGE_STORAGE_BIT;
      try {
        context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out); });
        ADD_FAILURE() << name << " output: no error, yet the device cannot store it";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::unsupported_format);
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot write"), std::string::npos) << e.what();
      }
    }
  }
}

// Formats that are no float colour format are refused with their name, by bloom and both blurs,
// and nothing is recorded.
TEST_F(FormatsTest, RefusalsNameTheFormat) {
  auto good = image_of(random_hdr(16, 16, 2), kF16);
  auto out = poisoned({16, 16}, kF16);
  Bloom bloom(context());
  GaussianBlur gauss(context());
  BlurPyramid pyramid(context());
  for (VkFormat f : {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R32G32B32A32_UINT, VK_FORMAT_R16G16_SFLOAT,
                     VK_FORMAT_D32_SFLOAT, static_cast<VkFormat>(987654)}) {
    const std::string name = detail::format_name(f);
    EXPECT_EQ(name.find("unsupported"), std::string::npos) << name;
    for (int role = 0; role < 2; ++role) {
      Image in = good.state, o = out.state;
      (role == 0 ? in : o).format = f;
      const uint64_t commands = detail::recorded_commands();
      auto expect_named = [&](const char* who, auto&& record) {
        try {
          context().run_once([&](VkCommandBuffer cmd) { record(cmd); });
          ADD_FAILURE() << who << ": no error for " << name;
        } catch (const Error& e) {
          EXPECT_EQ(e.code(), ErrorCode::unsupported_format) << e.what();
          EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
          EXPECT_NE(std::string(e.what()).find(role == 0 ? "input" : "output"), std::string::npos) << e.what();
        }
      };
      expect_named("Bloom", [&](VkCommandBuffer cmd) { bloom.record(cmd, in, o); });
      expect_named("GaussianBlur", [&](VkCommandBuffer cmd) { gauss.record(cmd, in, o); });
      if (role == 0) expect_named("BlurPyramid", [&](VkCommandBuffer cmd) { pyramid.record(cmd, in); });
      EXPECT_EQ(detail::recorded_commands(), commands) << name;
    }
  }
  EXPECT_EQ(detail::format_name(static_cast<VkFormat>(987654)), "VkFormat 987654");
  EXPECT_EQ(detail::format_name(kB10), "VK_FORMAT_B10G11R11_UFLOAT_PACK32");
}

// The Gaussian blur writes B10G11R11 through every method's last kernel, within its rounding.
TEST_F(FormatsTest, GaussianBlurWritesB10G11R11) {
  const CpuImage input = as_stored(random_hdr(53, 37, 9), kB10);
  for (BlurMethod method : {BlurMethod::separable, BlurMethod::pyramid, BlurMethod::dual}) {
    GaussianBlurConfig config;
    config.sigma_px = 3.0f;
    config.method = method;
    config.precision = Precision::fp32;
    GaussianBlur blur(context(), config);
    auto in = image_of(input, kB10);
    auto out = poisoned({input.width, input.height}, kB10);
    context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
    const CpuImage gpu = detail::download(context(), out.state);
    ASSERT_TRUE(all_finite(gpu));
    // The same blur into RGBA32F: the B10G11R11 output must be that, rounded to its format.
    GaussianBlur blur32(context(), config);
    auto out32 = poisoned({input.width, input.height}, kF32);
    context().run_once([&](VkCommandBuffer cmd) { blur32.record(cmd, in.state, out32.state); });
    const CpuImage wide = detail::download(context(), out32.state);
    reference::DoubleImage ref{wide.width, wide.height, std::vector<double>(wide.rgba.begin(), wide.rgba.end())};
    const Deviation d = compare(gpu, ref, kB10);
    EXPECT_EQ(d.outside, 0u) << blur_method_name(method) << ", first " << d.first;
  }
}

// An engine's output format, prepared: prepare(extent, format) makes what recording into it needs,
// so that the first record() creates no Vulkan object (an engine warms its effects up before the
// first frame), and a bloom shape change makes it again. Every float colour format the device
// stores. Pipelines are compiled once per context (src/core/pipeline.cpp), so each format and filter
// runs on a context of its own, where nothing was compiled before; and on another, with prepare(extent)
// alone, the first record() into B10G11R11 does compile pipelines: what the overload exists for,
// and what makes the checks able to fail.
TEST_F(FormatsTest, PrepareWithAnOutputFormatMakesWhatRecordingIntoItNeeds) {
  const CpuImage input = random_hdr(48, 30, 21);
  const VkExtent2D e{input.width, input.height};
  ContextOptions options;
  options.validation = true;
  options = tools::context_options_from_environment(options);
  int prepared = 0;
  for (VkFormat f :
       {kB10, kF16, kF32, VK_FORMAT_R16G16B16_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32}) {
    const std::string name = detail::format_name(f);
    if (!(usage_for(f) & VK_IMAGE_USAGE_STORAGE_BIT)) continue;  // the device cannot store it
    bool stores = true;
    try {
      detail::check_color_write(context(), f, "test", "output");
    } catch (const Error&) {
      stores = false;  // STORAGE_IMAGE without a qualifier and without STORAGE_WRITE_WITHOUT_FORMAT
    }
    if (!stores) continue;
    ++prepared;
    // A context for each filter as well: pipelines made in one round would otherwise be found
    // made in the next, and its checks could not fail.
    for (BloomFilter filter : {BloomFilter::cod13, BloomFilter::dual}) {
      Context ctx = Context::create(options);
      detail::OwnedImage in(ctx, e, kF16, usage_for(kF16));
      detail::upload(ctx, in.state, input);
      detail::OwnedImage out(ctx, e, f, usage_for(f));
      BloomConfig bc;
      bc.filter = filter;
      Bloom bloom(ctx, bc);
      GaussianBlur blur(ctx);
      bloom.prepare(e, f);
      blur.prepare(e, f);
      uint64_t objects = ctx.objects_created();
      ctx.run_once([&](VkCommandBuffer cmd) {
        bloom.record(cmd, in.state, out.state);
        blur.record(cmd, in.state, out.state);
      });
      EXPECT_EQ(ctx.objects_created(), objects) << name << ": the first record() created Vulkan objects";
      // A shape change makes the prepared output's pipelines again, with the others.
      bc.filter = filter == BloomFilter::cod13 ? BloomFilter::gauss9 : BloomFilter::cod13;
      bloom.set_config(bc);
      objects = ctx.objects_created();
      ctx.run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
      EXPECT_EQ(ctx.objects_created(), objects) << name << ": recording after a shape change created objects";
      EXPECT_EQ(ctx.validation_messages(), 0u) << name;
    }
  }
  EXPECT_GT(prepared, 1) << "every device stores RGBA16F and RGBA32F";
  if (usage_for(kB10) & VK_IMAGE_USAGE_STORAGE_BIT) {
    Context ctx = Context::create(options);
    detail::OwnedImage in(ctx, e, kF16, usage_for(kF16));
    detail::upload(ctx, in.state, input);
    detail::OwnedImage out(ctx, e, kB10, usage_for(kB10));
    Bloom bloom(ctx);
    bloom.prepare(e);
    const uint64_t objects = ctx.objects_created();
    ctx.run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
    EXPECT_GT(ctx.objects_created(), objects) << "prepare(extent) alone made B10G11R11's pipelines";
  }
}

// Layer 1 of a two-layer image: processed as asked, layer 0 (poisoned) untouched, in and out.
TEST_F(FormatsTest, BloomAndBlurProcessOneLayerOfAnArrayImage) {
  const CpuImage input = random_hdr(48, 30, 13);
  const VkExtent2D e{input.width, input.height};
  detail::OwnedImage in(context(), e, kF32, detail::kToolImageUsage, 1, 2);
  detail::OwnedImage out(context(), e, kF32, detail::kToolImageUsage, 1, 2);
  Image in0 = in.state, in1 = in.state, out0 = out.state, out1 = out.state;
  in1.view = in.layer_view(1);
  in1.base_array_layer = 1;
  out1.view = out.layer_view(1);
  out1.base_array_layer = 1;
  const CpuImage nan(e.width, e.height, std::nanf(""));
  detail::upload(context(), in0, nan);
  detail::upload(context(), in1, input);
  detail::upload(context(), out0, nan);
  detail::upload(context(), out1, nan);
  BloomConfig config;
  config.precision = Precision::fp32;
  Bloom bloom(context(), config);
  context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in1, out1); });
  const CpuImage gpu = detail::download(context(), out1);
  EXPECT_LT(reference::relative_l2(gpu, reference::bloom(input, config)), 1e-3);
  const CpuImage untouched = detail::download(context(), out0);
  EXPECT_TRUE(std::all_of(untouched.rgba.begin(), untouched.rgba.end(), [](float v) { return std::isnan(v); }))
      << "layer 0 of the output was written";
  const CpuImage in_layer0 = detail::download(context(), in0);
  EXPECT_TRUE(std::all_of(in_layer0.rgba.begin(), in_layer0.rgba.end(), [](float v) { return std::isnan(v); }));

  // The blur reads layer 1 and writes layer 0 of the same image (different subresources).
  GaussianBlurConfig gc;
  gc.sigma_px = 2.0f;
  gc.method = BlurMethod::separable;
  gc.precision = Precision::fp32;
  GaussianBlur blur(context(), gc);
  detail::upload(context(), out0, nan);
  context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, out1, out0); });
  const CpuImage blurred = detail::download(context(), out0);
  const CpuImage source = detail::download(context(), out1);
  EXPECT_LT(reference::relative_l2(blurred, reference::gaussian_separable(source, gc.sigma_px)), 1e-3);
  EXPECT_EQ(std::memcmp(source.rgba.data(), gpu.rgba.data(), gpu.rgba.size() * 4), 0) << "layer 1 changed";

  // A view of two layers is refused by name.
  Image both = in1;
  both.layer_count = 2;
  try {
    context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, both, out1); });
    ADD_FAILURE() << "layer_count 2 accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("Image::layer_count = 2"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Hi-Z on every depth format.

class HiZDepthFormat : public GpuTest, public ::testing::WithParamInterface<VkFormat> {};

TEST_P(HiZDepthFormat, MatchesTheReference) {
  const VkFormat format = GetParam();
  const std::string name = detail::format_name(format);
  HiZConfig config;
  config.extent = {133, 70};
  config.format = format;
  if (!(detail::format_features(context(), format) & VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT)) {
    // Refused by name; nothing else to test on this device.
    try {
      HiZPyramid hiz(context(), config);
      FAIL() << name << " accepted, yet the device cannot sample it";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::unsupported_format);
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    GTEST_SKIP() << "device '" << context().info().name << "' cannot sample " << name;
  }
  for (bool reversed : {false, true}) {
    config.reversed_z = reversed;
    std::mt19937 rng(reversed ? 3 : 4);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    reference::DepthImage depth{config.extent.width, config.extent.height,
                                std::vector<float>(size_t(config.extent.width) * config.extent.height)};
    for (float& v : depth.depth) v = unit(rng);
    // The values the kernel reads (UNORM depth quantized).
    reference::DepthImage read = depth;
    const int bits = quantize_for_format(read, format);
    detail::OwnedImage img(context(), config.extent, format,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
    detail::upload_r32(context(), img.state, depth.depth);
    HiZPyramid hiz(context(), config);
    context().run_once([&](VkCommandBuffer cmd) {  // every level poisoned with NaN
      detail::Barriers b;
      b.use(hiz.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
            VK_ACCESS_2_TRANSFER_WRITE_BIT, hiz.levels());
      b.flush(cmd);
      VkClearColorValue nan{};
      for (float& c : nan.float32) c = std::nanf("");
      VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, hiz.levels(), 0, 1};
      vkCmdClearColorImage(cmd, hiz.image().image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &nan, 1, &range);
    });
    context().run_once([&](VkCommandBuffer cmd) { hiz.record(cmd, img.state); });
    const auto ref = reference::hiz_pyramid(read, reversed, hiz.levels());
    // A max or min is exact, so each level holds input values as read. The UNORM-to-float
    // conversion may differ from the correctly rounded quotient by an ulp (2^-24 relative).
    const double rel = bits ? std::ldexp(1.0, -23) : 0.0;
    for (uint32_t k = 1; k <= hiz.levels(); ++k) {
      const VkExtent2D le{std::max(1u, config.extent.width >> k), std::max(1u, config.extent.height >> k)};
      const auto gpu = detail::download_r32(context(), hiz.image(), k - 1, le, hiz.levels());
      size_t bad = 0;
      for (size_t i = 0; i < gpu.size(); ++i) {
        const double r = ref[k - 1].depth[i];
        if (!(std::abs(double(gpu[i]) - r) <= rel * r) && bad++ < 3) {
          ADD_FAILURE() << name << (reversed ? " reversed" : "") << " level " << k << " texel " << i << ": " << gpu[i]
                        << " vs " << r;
        }
      }
      EXPECT_EQ(bad, 0u) << name << " level " << k;
    }
    EXPECT_EQ(img.state.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  }
}

INSTANTIATE_TEST_SUITE_P(DepthFormats, HiZDepthFormat,
                         ::testing::Values(VK_FORMAT_D16_UNORM, VK_FORMAT_X8_D24_UNORM_PACK32,
                                           VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT,
                                           VK_FORMAT_D32_SFLOAT_S8_UINT),
                         [](const ::testing::TestParamInfo<VkFormat>& p) {
                           return detail::format_name(p.param).substr(10);  // without "VK_FORMAT_"
                         });

TEST_F(FormatsTest, HiZRefusesColourFormatsByName) {
  HiZConfig config;
  config.extent = {16, 16};
  config.format = VK_FORMAT_R16_UNORM;
  try {
    HiZPyramid hiz(context(), config);
    ADD_FAILURE() << "R16_UNORM accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::unsupported_format);
    EXPECT_NE(std::string(e.what()).find("VK_FORMAT_R16_UNORM"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("VK_FORMAT_D24_UNORM_S8_UINT"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace glint::test
