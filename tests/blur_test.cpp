// The blur family on the GPU (lavapipe in CI, validation and synchronization validation on)
// against the float64 reference of docs/BLUR.md, plus the properties docs/BLUR.md promises, measured on
// GPU output: constants stay constant, impulse responses are symmetric, sum to 1 and have the
// expected sigma, odd and degenerate sizes work, and `auto` meets its error bound.
#include <glint/blur.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <vector>

#include "blur/blur_steps.h"
#include "core/half.h"
#include "reference/blur_reference.h"
#include "support/gpu_test.h"

namespace glint::test {
namespace {

constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;

// Tolerances (relative L2 against the float64 reference of the same algorithm):
// - fp32 end to end: fp32 sums of at most a few hundred products of weights <= 1, each with
//   relative rounding 2^-24, plus the GPU's own exp-free arithmetic: 1e-5 is ~100x the bound.
// - fp16 storage: each stored image adds at most 2^-11 relative when rounding to nearest and
//   2^-10 when truncating (lavapipe truncates, docs/BLOOM.md "Precision"); a chain stores at most
//   four images before the output (3 pyramid levels, or levels + output), so 4 * 2^-10 ~ 4e-3.
constexpr double kTolFp32 = 1e-5;
constexpr double kTolFp16 = 4e-3;

class BlurTest : public GpuTest {};

// Runs a Gaussian blur of `input` into a NaN-poisoned output and reads it back.
CpuImage run_gauss(GaussianBlur& blur, const CpuImage& input, VkFormat format = kF32) {
  auto in = make_image(input, format);
  auto out = make_poisoned({input.width, input.height}, format);
  context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
  return detail::download(context(), out.state);
}

std::array<CpuImage, 3> run_pyramid(BlurPyramid& pyramid, const CpuImage& input, VkFormat format = kF32) {
  auto in = make_image(input, format);
  context().run_once([&](VkCommandBuffer cmd) { pyramid.record(cmd, in.state); });
  return {detail::download(context(), pyramid.level(1)), detail::download(context(), pyramid.level(2)),
          detail::download(context(), pyramid.level(3))};
}

std::array<double, 3> sigmas_of(const BlurPyramidConfig& c) {
  return {c.sigma_texels[0], c.sigma_texels[1], c.sigma_texels[2]};
}

blur_plan::Plan plan_of(const GaussianBlur& blur) {
  const BlurChoice& c = blur.choice();
  blur_plan::Plan p;
  p.method =
      c.linear_sampling
          ? blur_plan::Method::separable_linear
          : static_cast<blur_plan::Method>(c.method == BlurMethod::separable ? 0u : static_cast<uint32_t>(c.method));
  p.sigma_px = blur.config().sigma_px;
  p.radius = c.radius;
  p.levels = c.levels;
  p.level_sigma = c.level_sigma;
  p.dual_offset = c.dual_offset;
  return p;
}

// The float64 reference of what `blur` computes (its chosen method and parameters).
reference::DoubleImage reference_of(const GaussianBlur& blur, const CpuImage& input) {
  const blur_plan::Plan p = plan_of(blur);
  const double sigma = blur.config().sigma_px;
  switch (blur.choice().method) {
    case BlurMethod::pyramid:
      return reference::gaussian_pyramid(input, p);
    case BlurMethod::dual:
      return reference::gaussian_dual(input, p);
    default:
      return blur.choice().linear_sampling ? reference::gaussian_separable_linear(input, sigma)
                                           : reference::gaussian_separable(input, sigma);
  }
}

// ---- BlurPyramid ----

TEST_F(BlurTest, PyramidMatchesReferenceOnRandomInput) {
  for (Precision precision : {Precision::fp32, Precision::fp16}) {
    BlurPyramidConfig config;
    config.sigma_texels = {0.8f, 1.2f, 2.0f};
    config.precision = precision;
    BlurPyramid pyramid(context(), config);
    const CpuImage input = random_hdr(97, 61, 11);  // odd sizes: 48x30, 24x15, 12x7
    const auto levels = run_pyramid(pyramid, input);
    const auto ref = reference::blur_pyramid(input, sigmas_of(config));
    for (int k = 0; k < 3; ++k) {
      SCOPED_TRACE(testing::Message() << "level " << k + 1 << (precision == Precision::fp16 ? " fp16" : " fp32"));
      EXPECT_EQ(levels[k].width, ref[k].width);
      EXPECT_EQ(levels[k].height, ref[k].height);
      EXPECT_LT(reference::rgba_relative_l2(levels[k], ref[k]), precision == Precision::fp16 ? kTolFp16 : kTolFp32);
    }
  }
}

// BlurPyramid's levels on both kernels (docs/BLUR.md "Streamed separable"), each selected on every
// device: at 200x136 every level halves exactly (100x68, 50x34, 25x17), so each reads its source
// as the exact 2:1 mean, which the streamed kernel takes (100 columns are two strips, 68 rows three
// bands); at 97x61 only 48x30 -> 24x15 does, and the tiles run the other levels' any-ratio mean.
// The streamed kernel loads the mean in four fetches a texel under `stream` and as two column
// means under `gpu_order` (the test counts those steps).
TEST_F(BlurTest, PyramidLevelsOnBothKernelsMatchTheReference) {
  using blur_steps::SeparableKernel;
  for (SeparableKernel kernel : {SeparableKernel::stream, SeparableKernel::tiles, SeparableKernel::gpu_order}) {
    for (Precision precision : {Precision::fp32, Precision::fp16}) {
      BlurPyramidConfig config;
      config.sigma_texels = {1.2f, 0.8f, 2.0f};
      config.precision = precision;
      BlurPyramid pyramid(context(), config);
      detail::BlurAccess::select_separable(pyramid, kernel);
      for (auto [w, h, box] :
           {std::tuple<uint32_t, uint32_t, bool>{200, 136, false}, {97, 61, false}, {200, 136, true}, {97, 61, true}}) {
        CpuImage input = random_hdr(w, h, w + h);
        input.at(w / 3, h / 2)[2] = std::nanf("");
        // A 2x2 box of fp16's largest finite values: a sum of two of them would not fit an fp16
        // shared copy (the column means must stay means). Its own run, since its energy would
        // outweigh the rest of the image in the relative L2.
        if (box)
          for (uint32_t y : {2u, 3u})
            for (uint32_t x : {4u, 5u})
              for (int c = 0; c < 3; ++c) input.at(x, y)[c] = 65504.0f;
        const auto levels = run_pyramid(pyramid, input, precision == Precision::fp16 ? kF16 : kF32);
        uint32_t exact = 0;  // levels whose size is exactly half the one above
        for (uint32_t k = 1, pw = w, ph = h; k <= 3;
             pw = pyramid.level_size(k).width, ph = pyramid.level_size(k).height, ++k)
          exact += pw == 2 * pyramid.level_size(k).width && ph == 2 * pyramid.level_size(k).height;
        EXPECT_EQ(detail::BlurAccess::streamed(pyramid), kernel == SeparableKernel::tiles ? 0u : exact);
        EXPECT_EQ(detail::BlurAccess::gpu_ordered(pyramid), kernel == SeparableKernel::gpu_order ? exact : 0u);
        const auto ref = reference::blur_pyramid(input, sigmas_of(config));
        for (int k = 0; k < 3; ++k) {
          SCOPED_TRACE(testing::Message() << (kernel == SeparableKernel::stream  ? "stream "
                                              : kernel == SeparableKernel::tiles ? "tiles "
                                                                                 : "gpu_order ")
                                          << w << "x" << h << (box ? " box of 65504" : "") << " level " << k + 1
                                          << (precision == Precision::fp16 ? " fp16" : " fp32"));
          ASSERT_TRUE(all_finite(levels[k]));
          EXPECT_LT(reference::rgba_relative_l2(levels[k], ref[k]), precision == Precision::fp16 ? kTolFp16 : kTolFp32);
        }
      }
    }
  }
}

// Under the default selection GPUs load the streamed levels' 2:1 means as column means and CPU
// devices in four fetches (docs/BLUR.md "Streamed separable"). At 1920x1080 the levels 960x540 and
// 480x270 halve exactly and make enough streamed workgroups for a GPU; planning is enough to count.
TEST_F(BlurTest, PyramidLoadsColumnMeansOnGpusOnlyByDefault) {
  BlurPyramid pyramid(context());
  pyramid.prepare({1920, 1080});
  const uint32_t streamed = detail::BlurAccess::streamed(pyramid);
  EXPECT_GE(streamed, 1u);
  if (context().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    EXPECT_EQ(detail::BlurAccess::gpu_ordered(pyramid), 0u);
  } else {
    EXPECT_EQ(detail::BlurAccess::gpu_ordered(pyramid), streamed);
  }
}

TEST_F(BlurTest, PyramidLevelSizesAndDegenerateInputs) {
  struct Case {
    uint32_t w, h;
    LevelSize l1, l3;
  } cases[] = {{1920, 1080, {960, 540}, {240, 135}},
               {1, 1, {1, 1}, {1, 1}},
               {1, 37, {1, 18}, {1, 4}},
               {37, 1, {18, 1}, {4, 1}},
               {3, 5, {1, 2}, {1, 1}},
               {64, 64, {32, 32}, {8, 8}}};
  BlurPyramid pyramid(context());
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << c.w << "x" << c.h);
    pyramid.prepare({c.w, c.h});
    EXPECT_EQ(pyramid.level_size(1).width, c.l1.width);
    EXPECT_EQ(pyramid.level_size(1).height, c.l1.height);
    EXPECT_EQ(pyramid.level_size(3).width, c.l3.width);
    EXPECT_EQ(pyramid.level_size(3).height, c.l3.height);
    if (uint64_t(c.w) * c.h > 4096) continue;  // GPU run only for the small ones
    const CpuImage input = random_hdr(c.w, c.h, c.w * 31 + c.h);
    const auto levels = run_pyramid(pyramid, input);
    const auto ref = reference::blur_pyramid(input, sigmas_of(pyramid.config()));
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(all_finite(levels[k]));
      EXPECT_LT(reference::rgba_relative_l2(levels[k], ref[k]), kTolFp16) << "level " << k + 1;
    }
  }
}

TEST_F(BlurTest, PyramidKeepsAConstantConstantAndRewritesEveryTexel) {
  BlurPyramidConfig config;
  config.precision = Precision::fp32;
  BlurPyramid pyramid(context(), config);
  // First a random frame, then a constant one: a texel the second frame did not write would
  // still hold the first frame's value (the levels cannot be poisoned from outside).
  run_pyramid(pyramid, random_hdr(45, 29, 3));
  const CpuImage constant(45, 29, 2.5f);
  const auto levels = run_pyramid(pyramid, constant);
  for (int k = 0; k < 3; ++k)
    for (float v : levels[k].rgba) ASSERT_NEAR(v, 2.5f, 2.5f * 1e-6f) << "level " << k + 1;
}

TEST_F(BlurTest, PyramidEffectiveSigmaMatchesMeasuredImpulse) {
  // An impulse at the centre of a 2x2 block of a 256x256 image; level k's response, measured in
  // input pixels (texel size 2^k), has the documented effective sigma. The 2x2 block of the
  // impulse's own level-0 texel contributes nothing extra: the effective sigma already counts the
  // first area downsample, whose box is exactly that texel's 2x2 footprint.
  BlurPyramidConfig config;
  config.precision = Precision::fp32;
  BlurPyramid pyramid(context(), config);
  const CpuImage impulse = reference::impulse_image(256, 256, 128, 128);
  const auto levels = run_pyramid(pyramid, impulse);
  for (uint32_t k = 1; k <= 3; ++k) {
    const double scale = double(1u << k);
    // The impulse sits in level-k texel 128 / 2^k; its centroid lies half a level-0 pixel
    // left/above the texel centre; impulse_sigma measures about the centroid anyway.
    const auto stats = reference::impulse_sigma(levels[k - 1], 128 >> k, 128 >> k);
    EXPECT_NEAR(stats.sum * scale * scale, 1.0, 1e-5) << "level " << k;
    const double expected = pyramid.effective_sigma_px(k).x_px;
    // Measured in level texels, converted to pixels; the impulse's position within the 2^k block
    // adds a discretization variance of at most (scale^2 - 1) / 12 - already in the model for
    // the box; allow 5%.
    EXPECT_NEAR(stats.sigma_x * scale, expected, 0.05 * expected) << "level " << k;
    EXPECT_NEAR(stats.sigma_y * scale, expected, 0.05 * expected) << "level " << k;
  }
}

TEST_F(BlurTest, PyramidSanitizesNanAndInfinity) {
  CpuImage input = random_hdr(40, 30, 5);
  input.at(3, 4)[0] = std::nanf("");
  input.at(20, 10)[1] = INFINITY;
  input.at(30, 20)[2] = -INFINITY;
  BlurPyramid pyramid(context());
  const auto levels = run_pyramid(pyramid, input, kF32);
  const auto ref = reference::blur_pyramid(input, sigmas_of(pyramid.config()));
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(all_finite(levels[k])) << "level " << k + 1;
    EXPECT_LT(reference::rgba_relative_l2(levels[k], ref[k]), kTolFp16) << "level " << k + 1;
  }
}

TEST_F(BlurTest, PyramidRejectsBadConfigAndRecordsNothingTwice) {
  BlurPyramidConfig bad;
  bad.sigma_texels[1] = std::nanf("");
  EXPECT_THROW(BlurPyramid(context(), bad), Error);
  bad.sigma_texels = {1.0f, 1.0f, 9.0f};
  try {
    BlurPyramid p(context(), bad);
    FAIL() << "sigma 9 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sigma_texels[2]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.3 to 4"), std::string::npos) << e.what();
  }
  BlurPyramid pyramid(context());
  EXPECT_THROW(pyramid.level(0), Error);
  EXPECT_THROW(pyramid.level(4), Error);
  auto in = make_image(random_hdr(33, 17, 1), kF16);
  context().run_once([&](VkCommandBuffer cmd) { pyramid.record(cmd, in.state); });
  const uint64_t before = context().objects_created();
  context().run_once([&](VkCommandBuffer cmd) { pyramid.record(cmd, in.state); });
  EXPECT_EQ(context().objects_created(), before) << "a second frame at the same size created Vulkan objects";
}

// ---- GaussianBlur ----

struct MethodCase {
  BlurMethod method;
  bool linear;
  float sigma;
};
const MethodCase kMethodCases[] = {
    {BlurMethod::separable, false, 1.2f},  // fused, radius 5 (11 taps: truncation at 4 sigma)
    {BlurMethod::separable, false, 3.5f},  // two line passes, radius 14
    {BlurMethod::separable, false, 6.0f},  // two line passes, radius 24
    {BlurMethod::separable, true, 1.2f},   // linear sampling, 5 fetches
    {BlurMethod::separable, true, 4.0f},  {BlurMethod::pyramid, false, 4.0f}, {BlurMethod::pyramid, false, 9.0f},
    {BlurMethod::pyramid, false, 20.0f},  // 3 levels: levels 1 and 2 by the separable binomial (blur_down.comp)
    {BlurMethod::dual, false, 3.0f},      {BlurMethod::dual, false, 8.0f},
};

std::string describe(const MethodCase& c) {
  return std::string(blur_method_name(c.method)) + (c.linear ? "+linear" : "") + " sigma " + std::to_string(c.sigma);
}

GaussianBlurConfig config_of(const MethodCase& c, Precision precision = Precision::fp32) {
  GaussianBlurConfig config;
  config.method = c.method;
  config.linear_sampling = c.linear;
  config.sigma_px = c.sigma;
  config.precision = precision;
  return config;
}

// Sampler weight precision: the linear-sampling variant's error against exact arithmetic is
// |fraction error| * |difference of the two texels|, at most 2^-bits of the local contrast. With
// the device's subTexelPrecisionBits (>= 4 by the spec, 8 on lavapipe and NVIDIA) the relative L2
// on random HDR input stays under 2^-bits * 4 (contrast of random HDR against its blur is < 4x the
// blurred RMS).
double linear_tolerance() {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(context().physical_device(), &props);
  return 4.0 * std::ldexp(1.0, -static_cast<int>(props.limits.subTexelPrecisionBits));
}

TEST_F(BlurTest, EveryMethodMatchesItsReferenceOnRandomInput) {
  const CpuImage input = random_hdr(83, 57, 21);
  for (const MethodCase& c : kMethodCases) {
    for (Precision precision : {Precision::fp32, Precision::fp16}) {
      SCOPED_TRACE(describe(c) + (precision == Precision::fp16 ? " fp16" : " fp32"));
      GaussianBlur blur(context(), config_of(c, precision));
      const VkFormat out_format = precision == Precision::fp16 ? kF16 : kF32;
      const CpuImage stored = as_stored(input, out_format);
      const CpuImage out = run_gauss(blur, stored, out_format);
      ASSERT_TRUE(all_finite(out)) << "unwritten or non-finite texels";
      double tol = precision == Precision::fp16 ? kTolFp16 : kTolFp32;
      if (c.linear) tol = std::max(tol, linear_tolerance());
      EXPECT_LT(reference::rgba_relative_l2(out, reference_of(blur, stored)), tol);
    }
  }
}

// The caller's NaN becomes 0 and +-Inf the largest finite value of the chain (docs/BLUR.md
// "Notation") in whichever step reads the input first: the fused, line and linear kernels, the
// pyramid's binomial downsample and the dual's first level. Not the linear-sampling variant, whose
// hardware filter blends texels before the shader sees them (GaussianBlurConfig::linear_sampling).
TEST_F(BlurTest, EveryMethodSanitizesNanAndInfinity) {
  CpuImage input = random_hdr(83, 57, 23);
  input.at(3, 4)[0] = std::nanf("");
  input.at(40, 20)[1] = INFINITY;
  input.at(80, 50)[2] = -INFINITY;
  input.at(0, 56)[3] = std::nanf("");
  for (const MethodCase& c : kMethodCases) {
    if (c.linear) continue;
    SCOPED_TRACE(describe(c));
    GaussianBlur blur(context(), config_of(c, Precision::fp16));
    const CpuImage out = run_gauss(blur, input, kF16);
    ASSERT_TRUE(all_finite(out)) << "a non-finite input texel reached the output";
    EXPECT_LT(reference::rgba_relative_l2(out, reference_of(blur, input)), kTolFp16);
  }
}

// Both kernels of a same-size separable step, each selected on every device (the streamed one is
// the default; docs/BLUR.md "Streamed separable"), against the float64 reference: radius 2 (a step
// of 8 rows longer than the 2 RADIUS lag), 5 and 12 (the largest), the pyramid's same-size level
// blur (radius 8), fp32 and fp16; with them the pyramid's downsamples and upsample on either of
// their kernels (blur_down.comp and blur_upsample.comp tile; blur_down_stream.comp walks bands of
// kDownBandRows rows with its four fetches a row under `stream`, and of kDownShuffleBandRows with
// its taps gathered by subgroup shuffles under `gpu_order`, and `device` on GPUs, where the device
// can (the test counts those steps), blur_upsample_stream.comp bands of
// kUpBandRows rows, every other row an invocation), one level at sigma 4 (2x) and several at sigma 16. The sizes cross
// the streamed kernels' strips of 64 (or fewer) columns and bands of 32 and 64 rows by one texel or part of one, and
// hold rows and columns shorter than its apron; NaN (and in fp16 Inf) texels check that its loads sanitize.
TEST_F(BlurTest, StreamedAndTiledSeparableKernelsMatchTheReference) {
  const std::pair<uint32_t, uint32_t> sizes[] = {{83, 57}, {129, 65}, {300, 97}, {1, 40}, {40, 1}, {5, 3}};
  const MethodCase cases[] = {{BlurMethod::separable, false, 0.5f},
                              {BlurMethod::separable, false, 1.2f},
                              {BlurMethod::separable, false, 3.0f},
                              {BlurMethod::pyramid, false, 4.0f},    // one level: its blur is same-size
                              {BlurMethod::pyramid, false, 16.0f}};  // levels downsampled on either kernel
  using blur_steps::SeparableKernel;
  const bool shuffles = blur_steps::down_shuffles_supported(context());
  const bool gpu = context().info().type != VK_PHYSICAL_DEVICE_TYPE_CPU;
  for (SeparableKernel kernel :
       {SeparableKernel::device, SeparableKernel::stream, SeparableKernel::tiles, SeparableKernel::gpu_order}) {
    for (const MethodCase& c : cases) {
      for (Precision precision : {Precision::fp32, Precision::fp16}) {
        GaussianBlur blur(context(), config_of(c, precision));
        detail::BlurAccess::select_separable(blur, kernel);
        const VkFormat format = precision == Precision::fp16 ? kF16 : kF32;
        for (auto [w, h] : sizes) {
          const std::string where = describe(c) +
                                    (kernel == SeparableKernel::device      ? " device"
                                     : kernel == SeparableKernel::stream    ? " stream"
                                     : kernel == SeparableKernel::gpu_order ? " gpu_order"
                                                                            : " tiles") +
                                    (precision == Precision::fp16 ? " fp16 " : " fp32 ") + std::to_string(w) + "x" +
                                    std::to_string(h);
          SCOPED_TRACE(where);
          CpuImage input = random_hdr(w, h, w * 31 + h);
          input.at(w / 2, h / 3)[0] = std::nanf("");
          // +Inf clamps to the chain's largest finite value, which the reference knows for fp16.
          if (precision == Precision::fp16) input.at(w - 1, h - 1)[1] = INFINITY;
          const CpuImage stored = as_stored(input, format);
          const CpuImage out = run_gauss(blur, stored, format);
          // A radius-12 strip in fp32 needs 19.2 KiB of shared memory, the largest of these; every
          // device has 16 KiB at least, so only there may the streamed kernel fall back.
          // The level blur and a pyramid's downsamples and upsample; the downsample and upsample
          // kernels use no shared memory, so every device runs them where they are selected.
          const uint32_t pyramid_steps = c.method == BlurMethod::pyramid ? blur.choice().levels + 1u : 0u;
          const uint32_t streamed = detail::BlurAccess::streamed(blur);
          if (kernel == SeparableKernel::tiles) {
            EXPECT_EQ(streamed, 0u);
          } else if ((kernel == SeparableKernel::stream || kernel == SeparableKernel::gpu_order) &&
                     (c.sigma < 3.0f || precision == Precision::fp16)) {
            EXPECT_EQ(streamed, 1u + pyramid_steps);
          } else {
            EXPECT_GE(streamed, pyramid_steps);
          }
          // The downsamples gather their taps where the selection asks for it and the device can:
          // `gpu_order` everywhere, `device` on GPUs (GaussianBlur's level blurs read same-size
          // sources, which have one load order).
          const bool gathered =
              shuffles && (kernel == SeparableKernel::gpu_order || (kernel == SeparableKernel::device && gpu));
          EXPECT_EQ(detail::BlurAccess::gpu_ordered(blur),
                    gathered && c.method == BlurMethod::pyramid ? blur.choice().levels : 0u);
          ASSERT_TRUE(all_finite(out)) << "unwritten or non-finite texels";
          EXPECT_LT(reference::rgba_relative_l2(out, reference_of(blur, stored)),
                    precision == Precision::fp16 ? kTolFp16 : kTolFp32);
        }
      }
    }
  }
}

TEST_F(BlurTest, OddAndDegenerateSizes) {
  const std::pair<uint32_t, uint32_t> sizes[] = {{1, 1}, {1, 29}, {29, 1}, {7, 3}, {4097, 3}};
  for (const MethodCase& c : kMethodCases) {
    GaussianBlur blur(context(), config_of(c));
    for (auto [w, h] : sizes) {
      SCOPED_TRACE(describe(c) + " at " + std::to_string(w) + "x" + std::to_string(h));
      const CpuImage input = random_hdr(w, h, w + 7 * h);
      const CpuImage out = run_gauss(blur, input);
      ASSERT_TRUE(all_finite(out));
      // fp32 texel positions near x carry an error of ulp(x) <= x * 2^-23, which moves bilinear
      // weights by as much: at 4097 texels that is 5e-4 of the local contrast, not 1e-5.
      const double position_tol = std::max(w, h) * std::ldexp(1.0, -23);
      const double tol = c.linear ? linear_tolerance() : kTolFp32 + position_tol;
      EXPECT_LT(reference::rgba_relative_l2(out, reference_of(blur, input)), tol);
    }
  }
}

TEST_F(BlurTest, ConstantStaysConstant) {
  const CpuImage constant(50, 38, 3.25f);
  for (const MethodCase& c : kMethodCases) {
    GaussianBlur blur(context(), config_of(c));
    const CpuImage out = run_gauss(blur, constant);
    for (float v : out.rgba) ASSERT_NEAR(v, 3.25f, 3.25f * 2e-6f) << describe(c);
  }
}

// A 2x2 impulse at the centre of an even-sized image is mirror-symmetric, so is every method's
// response to it (each method commutes with mirroring at sizes divisible by 2^levels); it sums to
// 4 and its measured sigma is the effective sigma (plus the 2x2 block's own variance 1/4).
TEST_F(BlurTest, ImpulseResponseIsSymmetricSumsToOneAndHasTheExpectedSigma) {
  const uint32_t n = 256;
  CpuImage impulse(n, n, 0.0f);
  for (uint32_t y = n / 2 - 1; y <= n / 2; ++y)
    for (uint32_t x = n / 2 - 1; x <= n / 2; ++x)
      for (int ch = 0; ch < 4; ++ch) impulse.at(x, y)[ch] = 1.0f;
  for (const MethodCase& c : kMethodCases) {
    SCOPED_TRACE(describe(c));
    GaussianBlur blur(context(), config_of(c));
    const CpuImage out = run_gauss(blur, impulse);
    double sum = 0, mx = 0, asym = 0, cx = 0, cy = 0;
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x) {
        const double v = out.at(x, y)[0];
        sum += v;
        cx += v * (x + 0.5 - n / 2.0) * (x + 0.5 - n / 2.0);
        cy += v * (y + 0.5 - n / 2.0) * (y + 0.5 - n / 2.0);
        mx = std::max(mx, std::abs(v));
        asym = std::max({asym, std::abs(v - out.at(n - 1 - x, y)[0]), std::abs(v - out.at(x, n - 1 - y)[0]),
                         std::abs(v - out.at(y, x)[0])});
      }
    EXPECT_NEAR(sum, 4.0, 4e-5);
    const double sym_tol = c.linear ? mx * linear_tolerance() : mx * 1e-5;
    EXPECT_LE(asym, sym_tol) << "mirror or transpose asymmetry";
    const double expected = std::sqrt(blur.choice().effective_sigma_px * blur.choice().effective_sigma_px + 0.25);
    // The dual filter is shift-variant (REFERENCES.md): its sigma is an average over impulse
    // positions, and one position may differ by up to ~10 %; the Gaussian methods by < 5 %.
    const double sigma_tol = (c.method == BlurMethod::dual ? 0.10 : 0.05) * expected;
    EXPECT_NEAR(std::sqrt(cx / sum), expected, sigma_tol);
    EXPECT_NEAR(std::sqrt(cy / sum), expected, sigma_tol);
    EXPECT_NEAR(blur.choice().effective_sigma_px, c.sigma, 0.05 * c.sigma);
  }
}

// The printed error covers what the caller's output holds: with an RGBA16F output (and fp16
// intermediates) the stores' rounding is part of expected_relative_error, measured over the
// whole image against the exact float64 Gaussian of an RGBA32F input (what `glint gauss` does).
// The separable blur clamps at full resolution like the exact Gaussian, so the borders count too.
TEST_F(BlurTest, ExpectedErrorIncludesTheRoundingOfEveryStore) {
  const CpuImage random = random_hdr(96, 80, 77);
  for (float sigma : {1.0f, 3.0f, 20.0f}) {
    double expected[2] = {};
    for (Precision precision : {Precision::fp16, Precision::fp32}) {
      SCOPED_TRACE(testing::Message() << "sigma " << sigma << (precision == Precision::fp16 ? " fp16" : " fp32"));
      GaussianBlurConfig config;
      config.sigma_px = sigma;
      config.method = BlurMethod::separable;
      config.precision = precision;
      GaussianBlur blur(context(), config);
      const VkFormat out_format = precision == Precision::fp16 ? kF16 : kF32;
      auto in = make_image(random, kF32);
      auto out = make_poisoned({random.width, random.height}, out_format);
      context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
      const CpuImage result = detail::download(context(), out.state);
      const double measured = reference::rgba_relative_l2(result, reference::exact_gaussian(random, sigma));
      expected[precision == Precision::fp16 ? 0 : 1] = blur.choice().expected_relative_error;
      EXPECT_LE(measured, blur.choice().expected_relative_error);
    }
    // fp16 stores add at least the output's rounding, 2^-10 relative, to the fp32 path's error.
    EXPECT_GE(expected[0], expected[1] + std::ldexp(1.0, -10));
  }
}

// auto meets its bound against the exact Gaussian across the sigma range, on an impulse (the
// modelled worst case) and on random HDR input.
TEST_F(BlurTest, AutoMeetsItsErrorBoundAcrossTheSigmaRange) {
  const float sigmas[] = {0.5f, 1.0f, 2.5f, 6.0f, 16.0f, 40.0f, 64.0f};
  for (float sigma : sigmas) {
    SCOPED_TRACE(testing::Message() << "sigma " << sigma);
    GaussianBlurConfig config;
    config.sigma_px = sigma;
    config.precision = Precision::fp32;
    GaussianBlur blur(context(), config);
    const uint32_t n = std::max(64u, static_cast<uint32_t>(std::ceil(sigma * 8)) & ~1u);  // impulse stays interior
    const CpuImage random = random_hdr(n, n, static_cast<uint32_t>(sigma * 10));
    const CpuImage out = run_gauss(blur, random);
    const double bound = config.max_relative_error;
    EXPECT_LE(blur.choice().expected_relative_error, bound) << blur_method_name(blur.choice().method);
    // The bound holds over the whole image (docs/BLUR.md "Borders").
    EXPECT_LT(reference::rgba_relative_l2(out, reference::exact_gaussian(random, sigma)), bound)
        << blur_method_name(blur.choice().method);
    const CpuImage impulse = reference::impulse_image(n, n, n / 2, n / 2);
    const CpuImage response = run_gauss(blur, impulse);
    // The model is the worst over impulse positions; the GPU adds fp32 rounding only.
    EXPECT_LT(reference::rgba_relative_l2(response, reference::exact_gaussian(impulse, sigma)), bound * 1.01 + 1e-5)
        << blur_method_name(blur.choice().method);
  }
}

// A natural-like HDR image whose content is strongest at the borders, where a chain that clamps
// at its coarse levels differs most from the exact Gaussian (which clamps at full resolution): a
// bright sky along the top edge, a bright wall along the left edge, a dark band along the right,
// soft blobs (some centred on an edge or a corner), sharp-edged rectangles and a little noise.
// Non-negative, as the rounding bound assumes.
CpuImage natural_like(uint32_t width, uint32_t height, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  struct Blob {
    double x, y, r, a;
  };
  std::vector<Blob> blobs = {{0.0, 0.0, 0.2, 6.0}, {double(width), 0.6 * height, 0.1, 4.0}};
  for (int i = 0; i < 6; ++i)
    blobs.push_back({unit(rng) * width, unit(rng) * height, 0.03 + 0.2 * unit(rng), 3 * unit(rng)});
  struct Rect {
    double x0, y0, x1, y1, a;
  };
  std::vector<Rect> rects;
  for (int i = 0; i < 5; ++i) {
    const double x = unit(rng) * width, y = unit(rng) * height;
    rects.push_back({x, y, x + 0.3 * width * unit(rng), y + 0.3 * height * unit(rng), 2 * unit(rng)});
  }
  CpuImage img(width, height);
  const double scale = std::min(width, height);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      double v = 0.2 + 0.3 * x / width;
      if (y < height / 5) v += 3.0 - 0.01 * y;  // sky
      if (x < width / 8) v += 2.0;              // wall
      if (x + width / 10 >= width) v *= 0.1;    // dark band
      for (const Blob& b : blobs) {
        const double d2 = ((x - b.x) * (x - b.x) + (y - b.y) * (y - b.y)) / (b.r * b.r * scale * scale);
        v += b.a * std::exp(-0.5 * d2);
      }
      for (const Rect& r : rects) v += (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1) ? r.a : 0.0;
      float* px = img.at(x, y);
      for (int c = 0; c < 4; ++c) px[c] = float(v * (0.6 + 0.2 * c) * (0.95 + 0.1 * unit(rng)));
    }
  }
  return img;
}

// The promise `glint gauss` prints: for every method and sigma, the relative L2 error of the
// output against the exact float64 Gaussian with clamp-to-edge at full resolution, over the WHOLE
// image (borders included), is within BlurChoice::expected_relative_error (the planner's expected
// error, rounding of every store included). Odd sizes, a natural-like image with strong borders
// and white noise; RGBA32F and RGBA16F outputs (what --fp32 and the default write).
TEST_F(BlurTest, WholeImageErrorIsWithinTheExpectedErrorForEveryMethodAndSigma) {
  struct Input {
    const char* name;
    CpuImage image;
  };
  const Input inputs[] = {{"natural", natural_like(203, 157, 11)}, {"noise", random_hdr(97, 75, 12)}};
  for (const Input& input : inputs) {
    for (float sigma : {1.0f, 3.0f, 8.0f, 20.0f, 50.0f}) {
      const reference::DoubleImage exact = reference::exact_gaussian(input.image, sigma);
      for (BlurMethod method : {BlurMethod::separable, BlurMethod::pyramid, BlurMethod::dual, BlurMethod::automatic}) {
        // The line separable at sigma 50 is slow on a CPU device: once, on the natural image.
        if (method == BlurMethod::separable && sigma > 20.0f && input.image.width < 200) continue;
        for (Precision precision : {Precision::fp32, Precision::fp16}) {
          SCOPED_TRACE(testing::Message() << input.name << " sigma " << sigma << " " << blur_method_name(method)
                                          << (precision == Precision::fp16 ? " fp16" : " fp32"));
          GaussianBlurConfig config;
          config.sigma_px = sigma;
          config.method = method;
          config.precision = precision;
          config.max_relative_error = 0.02f;
          GaussianBlur blur(context(), config);
          const CpuImage out = run_gauss(blur, input.image, precision == Precision::fp16 ? kF16 : kF32);
          const double measured = reference::rgba_relative_l2(out, exact);
          EXPECT_LE(measured, blur.choice().expected_relative_error) << blur_method_name(blur.choice().method);
        }
      }
    }
  }
}

// RGBA16F at sigma 64 and the default bound: the pyramid keeps its last level's shared copies in
// fp32 to meet the bound (blur_plan::Plan::fp32_shared). The output matches the float64
// reference of the same plan and the exact Gaussian within the expected error it reports.
TEST_F(BlurTest, PyramidWithFp32SharedCopiesMeetsItsBound) {
  const CpuImage input = as_stored(natural_like(301, 203, 31), kF16);
  GaussianBlurConfig config;
  config.method = BlurMethod::pyramid;
  config.sigma_px = 64.0f;
  config.precision = Precision::fp16;
  GaussianBlur blur(context(), config);
  const CpuImage out = run_gauss(blur, input, kF16);
  ASSERT_TRUE(all_finite(out)) << "unwritten or non-finite texels";
  EXPECT_EQ(blur.choice().method, BlurMethod::pyramid);
  EXPECT_LE(blur.choice().expected_relative_error, config.max_relative_error);
  EXPECT_LT(reference::rgba_relative_l2(out, reference_of(blur, input)), kTolFp16);
  EXPECT_LE(reference::rgba_relative_l2(out, reference::exact_gaussian(input, 64.0)),
            blur.choice().expected_relative_error);
}

// The cost model auto ranks by is the device's: measured once per Context (the same constants
// on a second call), or the config's when one is passed in, which then decides the choice.
TEST_F(BlurTest, AutoRanksByTheDevicesCostModel) {
  const BlurCostModel measured = measure_blur_cost_model(context());
  EXPECT_GT(measured.us_per_dispatch, 0.0);
  EXPECT_GT(measured.us_per_byte, 0.0);
  EXPECT_GT(measured.us_per_shared_tap, 0.0);
  EXPECT_GT(measured.us_per_fetch_tap, 0.0);
  const BlurCostModel again = measure_blur_cost_model(context());
  EXPECT_EQ(again.us_per_dispatch, measured.us_per_dispatch);
  EXPECT_EQ(again.us_per_fetch_tap, measured.us_per_fetch_tap);
  GaussianBlurConfig config;
  config.sigma_px = 50.0f;
  config.max_relative_error = 0.02f;
  // Taps dear, dispatches free: the pyramid (a few fetches per texel) beats 401 taps.
  config.cost_model = {1e-3, 1e-6, 1.0, 1.0};
  GaussianBlur taps_dear(context(), config);
  taps_dear.prepare({512, 512});
  EXPECT_EQ(taps_dear.choice().method, BlurMethod::pyramid);
  EXPECT_LE(taps_dear.choice().expected_relative_error, 0.02);
  // Dispatches dear, taps free: the one or two dispatches of the separable blur win.
  config.cost_model = {1e6, 1e-9, 1e-9, 1e-9};
  GaussianBlur dispatch_dear(context(), config);
  dispatch_dear.prepare({512, 512});
  EXPECT_EQ(dispatch_dear.choice().method, BlurMethod::separable);
  EXPECT_GT(dispatch_dear.choice().estimated_us, 1e6);
}

TEST_F(BlurTest, GaussRejectsBadInputAndCreatesNothingPerFrame) {
  GaussianBlurConfig bad;
  bad.sigma_px = 0.25f;
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad.sigma_px = 65.0f;
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad = {};
  bad.max_relative_error = std::nanf("");
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad = {};
  bad.linear_sampling = true;  // needs method separable
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad = {};
  bad.method = static_cast<BlurMethod>(9);
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad = {};
  bad.cost_model.us_per_dispatch = 3.0;  // the others zero: neither measured nor passed in
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad.cost_model = {3.0, 1e-6, -1e-7, 1e-7};
  EXPECT_THROW(GaussianBlur(context(), bad), Error);
  bad.cost_model = {3.0, 1e-6, std::nan(""), 1e-7};
  EXPECT_THROW(GaussianBlur(context(), bad), Error);

  GaussianBlur blur(context());
  auto in = make_image(random_hdr(40, 20, 2), kF16);
  auto other = make_poisoned({41, 20}, kF16);
  EXPECT_THROW(context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, other.state); }), Error);
  EXPECT_THROW(context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, in.state); }), Error);
  EXPECT_THROW(blur.prepare({0, 10}), Error);
  auto out = make_poisoned({40, 20}, kF16);
  context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
  const uint64_t before = context().objects_created();
  context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
  EXPECT_EQ(context().objects_created(), before);
}

}  // namespace
}  // namespace glint::test
