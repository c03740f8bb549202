// Tests of the float64 blur reference (tools/reference/blur_reference.h) on its own: CPU only, no
// Vulkan. Properties of docs/BLUR.md (conservation, constants, symmetry, measured sigma) on random
// inputs from generators started at fixed values, a plain gather convolution against the reference's scatter order, and
// the planner's modelled errors against errors measured with the reference.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "reference/blur_reference.h"

namespace glint::reference {
namespace {

using blur_plan::Method;
using blur_plan::Plan;

// Random HDR in all four channels: log-uniform over [e^-4, e^5], a few texels 6x brighter.
CpuImage random_hdr(uint32_t w, uint32_t h, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> expo(-4.0f, 5.0f), u(0.0f, 1.0f);
  CpuImage img(w, h);
  for (float& v : img.rgba) v = (u(rng) < 0.01f ? 6.0f : 1.0f) * std::exp(expo(rng));
  return img;
}

double sum_channel(const DoubleImage& img, int k) {
  double s = 0.0;
  for (size_t i = size_t(k); i < img.rgba.size(); i += 4) s += img.rgba[i];
  return s;
}

// The separable clamped convolution written as the kernels write it (gather), independently of
// the reference's scatter order.
DoubleImage gather_blur(const DoubleImage& src, const std::vector<double>& half) {
  const auto r = int64_t(half.size()) - 1;
  auto pass = [&](const DoubleImage& in, bool vertical) {
    DoubleImage out = in;
    for (uint32_t y = 0; y < in.height; ++y)
      for (uint32_t x = 0; x < in.width; ++x)
        for (int k = 0; k < 4; ++k) {
          double s = 0.0;
          for (int64_t t = -r; t <= r; ++t) {
            const int64_t xi = vertical ? x : std::clamp<int64_t>(x + t, 0, in.width - 1);
            const int64_t yi = vertical ? std::clamp<int64_t>(y + t, 0, in.height - 1) : y;
            s += half[size_t(std::abs(t))] * in.at(uint32_t(xi), uint32_t(yi))[k];
          }
          out.at(x, y)[k] = s;
        }
    return out;
  };
  return pass(pass(src, false), true);
}

TEST(BlurReference, SanitizeReplacesNanAndClampsInfinities) {
  CpuImage img(2, 1, 1.5f);
  img.at(0, 0)[0] = std::numeric_limits<float>::quiet_NaN();
  img.at(0, 0)[1] = std::numeric_limits<float>::infinity();
  img.at(1, 0)[2] = -std::numeric_limits<float>::infinity();
  img.at(1, 0)[3] = 1e6f;
  const DoubleImage s = sanitize(img);
  EXPECT_EQ(s.at(0, 0)[0], 0.0);
  EXPECT_EQ(s.at(0, 0)[1], 65504.0);
  EXPECT_EQ(s.at(1, 0)[2], -65504.0);
  EXPECT_EQ(s.at(1, 0)[3], 65504.0);
  EXPECT_EQ(s.at(0, 0)[2], 1.5);
  EXPECT_EQ(sanitize(img, kBlurMaxValueFp32).at(1, 0)[3], 1e6);
}

TEST(BlurReference, AreaDownsampleConservesTheMean) {
  struct Case {
    uint32_t ws, hs, wd, hd;
  };
  for (const Case c : {Case{8, 6, 4, 3}, Case{7, 5, 3, 2}, Case{9, 9, 4, 4}, Case{3, 3, 1, 1}, Case{1, 9, 1, 4},
                       Case{9, 1, 4, 1}, Case{1, 1, 1, 1}, Case{5, 4, 2, 4}, Case{13, 11, 5, 3}}) {
    const DoubleImage src = sanitize(random_hdr(c.ws, c.hs, 7 + c.ws * 31 + c.hs));
    const DoubleImage dst = area_downsample(src, c.wd, c.hd);
    ASSERT_EQ(dst.width, c.wd);
    ASSERT_EQ(dst.height, c.hd);
    for (int k = 0; k < 4; ++k) {
      // Each destination texel covers (ws/wd)(hs/hd) source texels: sum(dst) * that area = sum(src).
      const double area = double(c.ws) * c.hs / (double(c.wd) * c.hd);
      EXPECT_NEAR(sum_channel(dst, k) * area, sum_channel(src, k), 1e-12 * sum_channel(src, k))
          << c.ws << "x" << c.hs << " -> " << c.wd << "x" << c.hd;
    }
  }
  // Exact 2:1 is the mean of each 2x2 block; odd sizes keep the last row and column (3 -> 1 is
  // the mean of all three).
  const DoubleImage src = sanitize(random_hdr(6, 3, 99));
  const DoubleImage half = area_downsample(src, 3, 1);
  for (uint32_t x = 0; x < 3; ++x)
    for (int k = 0; k < 4; ++k) {
      double mean = 0.0;
      for (uint32_t y = 0; y < 3; ++y) mean += (src.at(2 * x, y)[k] + src.at(2 * x + 1, y)[k]) / 6.0;
      EXPECT_NEAR(half.at(x, 0)[k], mean, 1e-12 * mean);
    }
  EXPECT_THROW(area_downsample(src, 7, 1), std::invalid_argument);
}

TEST(BlurReference, BinomialDownsampleIsOneThreeThreeOne) {
  // An impulse at source (6, 4) of 16x10: along each axis, destination texel 3 (source 5..8 with
  // [1 3 3 1] / 8, reading at 5.75 and 7.25 - 1.5) holds 3/8 of it and texel 2 (source 3..6) 1/8.
  const DoubleImage d = binomial_downsample(to_double(impulse_image(16, 10, 6, 4)), 8, 5);
  EXPECT_NEAR(d.at(3, 2)[0], 9.0 / 64, 1e-15);
  EXPECT_NEAR(d.at(2, 2)[1], 3.0 / 64, 1e-15);
  EXPECT_NEAR(d.at(3, 1)[2], 3.0 / 64, 1e-15);
  EXPECT_NEAR(d.at(2, 1)[3], 1.0 / 64, 1e-15);
  EXPECT_EQ(d.at(4, 2)[0], 0.0);
  EXPECT_NEAR(sum_channel(d, 0) * 4, 1.0, 1e-15);
  // 1xN: the identity along x, [1 3 3 1] / 8 along y.
  const DoubleImage col = binomial_downsample(to_double(impulse_image(1, 10, 0, 4)), 1, 5);
  EXPECT_NEAR(col.at(0, 2)[0], 3.0 / 8, 1e-15);
  EXPECT_NEAR(col.at(0, 1)[0], 1.0 / 8, 1e-15);
}

TEST(BlurReference, ConstantImagesStayConstant) {
  const CpuImage flat(23, 9, 3.25f);
  const DoubleImage d = to_double(flat);
  auto all_equal = [](const DoubleImage& img, double v) {
    for (double x : img.rgba)
      if (std::abs(x - v) > 1e-12 * v) return false;
    return true;
  };
  EXPECT_TRUE(all_equal(fused_level_blur(d, 11, 4, 1.2), 3.25));
  EXPECT_TRUE(all_equal(fused_level_blur(d, 11, 4, 1.2, blur_plan::kGaussTruncation, true), 3.25));
  EXPECT_TRUE(all_equal(gaussian_separable(flat, 2.5), 3.25));
  EXPECT_TRUE(all_equal(gaussian_separable_linear(flat, 2.5), 3.25));
  EXPECT_TRUE(all_equal(exact_gaussian(flat, 4.0), 3.25));
  Plan p;
  p.levels = 2;
  p.level_sigma = 0.8;
  p.dual_offset = 1.3;
  EXPECT_TRUE(all_equal(gaussian_pyramid(flat, p), 3.25));
  EXPECT_TRUE(all_equal(gaussian_dual(flat, p), 3.25));
  for (const DoubleImage& level : blur_pyramid(flat, {1.2, 1.2, 1.2})) EXPECT_TRUE(all_equal(level, 3.25));
}

TEST(BlurReference, ScatterOrderEqualsGather) {
  // Radius 8 on 23x17 reaches both edges; sigma 3 on 3x2 and on 1x7 and 7x1 has R > size.
  struct Case {
    uint32_t w, h;
    double sigma;
  };
  for (const Case c : {Case{23, 17, 2.5}, Case{3, 2, 3.0}, Case{1, 7, 3.0}, Case{7, 1, 3.0}, Case{1, 1, 1.0}}) {
    const CpuImage img = random_hdr(c.w, c.h, 5 + c.w);
    const DoubleImage expected =
        gather_blur(sanitize(img), blur_plan::gaussian_half_taps(c.sigma, blur_plan::kGaussTruncation));
    EXPECT_LT(rgba_max_abs(gaussian_separable(img, c.sigma), expected), 1e-12 * 900)
        << c.w << "x" << c.h << " sigma " << c.sigma;
  }
}

TEST(BlurReference, SeparableImpulseResponse) {
  for (double sigma : {0.7, 1.2, 2.0, 5.5}) {
    const uint32_t n = 2 * uint32_t(std::ceil(4 * sigma)) + 9, c = n / 2;
    const DoubleImage out = gaussian_separable(impulse_image(n, n, c, c), sigma);
    for (uint32_t a = 0; a <= c; ++a)
      for (uint32_t b = 0; b <= c; ++b) {
        const double v = out.at(c + a, c + b)[1];
        EXPECT_EQ(v, out.at(c - a, c + b)[1]);
        EXPECT_EQ(v, out.at(c + a, c - b)[1]);
        EXPECT_NEAR(v, out.at(c + b, c + a)[1], 1e-17) << "the same taps along x and y";
      }
    const ImpulseStats s = impulse_sigma(out, c, c, 2);
    EXPECT_NEAR(s.sum, 1.0, 1e-13);
    EXPECT_NEAR(s.shift_x, 0.0, 1e-12);
    const double expected = std::sqrt(blur_plan::discrete_variance(sigma, blur_plan::kGaussTruncation));
    EXPECT_NEAR(s.sigma_x, expected, 1e-6) << sigma;
    EXPECT_NEAR(s.sigma_y, expected, 1e-6) << sigma;
  }
}

TEST(BlurReference, ExactGaussianHasItsSigma) {
  for (double sigma : {3.0, 10.0}) {
    const uint32_t n = 2 * uint32_t(std::ceil(6 * sigma)) + 3, c = n / 2;
    const ImpulseStats s = impulse_sigma(exact_gaussian(impulse_image(n, n, c, c), sigma), c, c);
    EXPECT_NEAR(s.sum, 1.0, 1e-13);
    EXPECT_NEAR(s.sigma_x, sigma, 1e-6 * sigma);
    EXPECT_NEAR(s.sigma_y, sigma, 1e-6 * sigma);
  }
}

TEST(BlurReference, LinearSamplingEqualsSeparable) {
  for (double sigma : {1.2, 2.0, 3.3}) {
    const CpuImage img = random_hdr(31, 19, 11);
    const DoubleImage direct = gaussian_separable(img, sigma);
    const double scale = rgba_max_abs(direct, DoubleImage{31, 19, std::vector<double>(31 * 19 * 4, 0.0)});
    EXPECT_LT(rgba_max_abs(gaussian_separable_linear(img, sigma), direct), 1e-12 * scale) << sigma;
    // The sampler model (8-bit sub-texel weights) moves the result, by a bounded amount.
    const double e8 = rgba_relative_l2(gaussian_separable_linear(img, sigma, 8), direct);
    EXPECT_GT(e8, 0.0);
    EXPECT_LT(e8, 1e-2);
  }
}

TEST(BlurReference, BlurPyramidLevelSizesAndSigma) {
  const CpuImage img = impulse_image(320, 192, 160, 96);  // exact 2:1 chain: 160x96, 80x48, 40x24
  const std::array<DoubleImage, 3> levels = blur_pyramid(img, {1.2, 1.2, 1.2});
  EXPECT_EQ(levels[0].width, 160u);
  EXPECT_EQ(levels[2].width, 40u);
  EXPECT_EQ(levels[2].height, 24u);
  // Level sums: each level texel is 4^k input texels, so sum * 4^k is the impulse's mass.
  for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(sum_channel(levels[k], 0) * std::pow(4.0, double(k + 1)), 1.0, 1e-12);
  // Odd, 1xN, Nx1, 1x1 sizes follow half().
  const std::array<DoubleImage, 3> odd = blur_pyramid(random_hdr(7, 1, 3), {1.0, 0.5, 2.0});
  EXPECT_EQ(odd[0].width, 3u);
  EXPECT_EQ(odd[1].width, 1u);
  EXPECT_EQ(odd[2].height, 1u);
  EXPECT_EQ(blur_pyramid(random_hdr(1, 1, 3), {1.2, 1.2, 1.2})[2].width, 1u);
}

// The impulse at the centre of an image big enough that the response does not reach the border.
uint32_t impulse_size(double sigma) { return 64 * uint32_t(std::ceil((8 * sigma + 40) / 64)); }

TEST(BlurReference, PyramidAndDualImpulseSigma) {
  for (double sigma : {2.0, 4.0, 8.0, 16.0, 32.0, 64.0}) {
    // Wider than impulse_size: the whole response must fit for its sum and moments.
    const uint32_t n = 64 * uint32_t(std::ceil((12 * sigma + 64) / 64)), c = n / 2;
    const CpuImage img = impulse_image(n, n, c, c);
    const Plan pyr = blur_plan::plan_method(Method::pyramid, sigma, n, n, 0.1);
    const ImpulseStats sp = impulse_sigma(gaussian_pyramid(img, pyr), c, c);
    EXPECT_NEAR(sp.sum, 1.0, 1e-9) << "pyramid sigma " << sigma;
    EXPECT_NEAR(sp.sigma_x / sigma, 1.0, 0.05) << "pyramid sigma " << sigma << " k " << pyr.levels;
    EXPECT_NEAR(sp.sigma_y / sigma, 1.0, 0.05) << "pyramid sigma " << sigma << " k " << pyr.levels;
    const Plan dual = blur_plan::plan_method(Method::dual, sigma, n, n, 0.1);
    const DoubleImage d = gaussian_dual(img, dual);
    const ImpulseStats sd = impulse_sigma(d, c, c);
    EXPECT_NEAR(sd.sum, 1.0, 1e-9) << "dual sigma " << sigma;
    EXPECT_NEAR(sd.sigma_x / sigma, 1.0, 0.05) << "dual sigma " << sigma << " k " << dual.levels;
    EXPECT_NEAR(sd.sigma_y / sigma, 1.0, 0.05) << "dual sigma " << sigma << " k " << dual.levels;
    // The dual's taps are symmetric under x <-> y.
    EXPECT_NEAR(sd.sigma_x, sd.sigma_y, 1e-9 * sigma);
  }
}

TEST(BlurReference, ModelledErrorsMatchMeasuredOnes) {
  // The planner's error model and the reference are separate code: on an impulse at a modelled
  // position (the centre, a multiple of 2^k on an exact 2:1 chain) the measured error is at most
  // the modelled worst one; the dual's model takes the worst over the diagonal positions, which
  // the measurement repeats (k <= 4, where the model is not scaled).
  for (double sigma : {3.0, 12.0}) {
    const uint32_t n = impulse_size(sigma), c = n / 2;
    const Plan pyr = blur_plan::plan_method(Method::pyramid, sigma, n, n, 0.2);
    const CpuImage img = impulse_image(n, n, c, c);
    const DoubleImage exact = exact_gaussian(img, sigma);
    const double ep = rgba_relative_l2(gaussian_pyramid(img, pyr), exact);
    EXPECT_LE(ep, pyr.expected_relative_l2 * 1.001) << sigma;
    EXPECT_GT(ep, pyr.expected_relative_l2 * 0.3) << sigma;
    const Plan dual = blur_plan::plan_method(Method::dual, sigma, n, n, 0.2);
    ASSERT_LE(dual.levels, 4u);
    double worst = 0.0;
    for (uint32_t m = 0; m < 4; ++m) {
      const uint32_t q = c + m * (1u << dual.levels) / 4;
      const CpuImage moved = impulse_image(n, n, q, q);
      worst = std::max(worst, rgba_relative_l2(gaussian_dual(moved, dual), exact_gaussian(moved, sigma)));
    }
    EXPECT_NEAR(worst / dual.expected_relative_l2, 1.0, 0.02) << sigma;
  }
}

TEST(BlurReference, AutoMeetsItsBound) {
  for (double bound : {1e-2, 0.1}) {
    for (double sigma : {0.5, 1.5, 4.0, 12.0, 40.0, 64.0}) {
      // On an impulse (the white-noise bound) ...
      const uint32_t n = impulse_size(sigma), c = n / 2;
      const Plan a = blur_plan::plan_auto(sigma, n, n, bound);
      const CpuImage img = impulse_image(n, n, c, c);
      auto run = [](const CpuImage& in, const Plan& p) {
        switch (p.method) {
          case Method::pyramid:
            return gaussian_pyramid(in, p);
          case Method::dual:
            return gaussian_dual(in, p);
          default:
            return gaussian_separable(in, p.sigma_px);
        }
      };
      EXPECT_LE(rgba_relative_l2(run(img, a), exact_gaussian(img, sigma)), bound)
          << "impulse, sigma " << sigma << " method " << unsigned(a.method);
      // ... and on random HDR, whose mean makes the relative error smaller, over the whole image:
      // the padded chains clamp at full resolution as the exact Gaussian does (docs/BLUR.md
      // "Borders"). Up to sigma 12, to keep the exact Gaussian cheap.
      if (sigma > 12) continue;
      const CpuImage hdr = random_hdr(193, 161, 21);
      const Plan b = blur_plan::plan_auto(sigma, 193, 161, bound);
      EXPECT_LE(rgba_relative_l2(run(hdr, b), exact_gaussian(hdr, sigma)), bound)
          << "random HDR, sigma " << sigma << " method " << unsigned(b.method);
      // Every method, not only auto's choice, meets its own expected error there.
      for (Method m : {Method::pyramid, Method::dual}) {
        const Plan p = blur_plan::plan_method(m, sigma, 193, 161, bound);
        EXPECT_LE(rgba_relative_l2(run(hdr, p), exact_gaussian(hdr, sigma)), p.expected_relative_l2)
            << "random HDR, sigma " << sigma << " method " << unsigned(m);
      }
    }
  }
}

TEST(BlurReference, MetricsAndHalfRounding) {
  DoubleImage a{2, 1, {1, 2, 3, 4, 5, 6, 7, 8}};
  DoubleImage b = a;
  EXPECT_EQ(rgba_relative_l2(a, b), 0.0);
  b.rgba[7] = 9;
  EXPECT_NEAR(rgba_relative_l2(a, b), 1.0 / std::sqrt(1 + 4 + 9 + 16 + 25 + 36 + 49 + 81.0), 1e-15);
  EXPECT_EQ(rgba_max_abs(a, b), 1.0);
  a.rgba[0] = std::nan("");
  EXPECT_TRUE(std::isnan(rgba_relative_l2(a, b)));
  EXPECT_TRUE(std::isnan(rgba_max_abs(a, b)));
  EXPECT_THROW(rgba_relative_l2(a, DoubleImage{1, 1, {0, 0, 0, 0}}), std::invalid_argument);
  // fp16 storage of intermediates changes the result by about 2^-11 relative, not more.
  const CpuImage hdr = random_hdr(40, 30, 8);
  Plan p;
  p.levels = 2;
  p.level_sigma = 1.0;
  p.dual_offset = 1.0;
  for (bool dual : {false, true}) {
    const DoubleImage exact = dual ? gaussian_dual(hdr, p) : gaussian_pyramid(hdr, p);
    const double e = rgba_relative_l2(dual ? gaussian_dual(hdr, p, true) : gaussian_pyramid(hdr, p, true), exact);
    EXPECT_GT(e, 0.0);
    EXPECT_LT(e, 1e-3);
  }
}

}  // namespace
}  // namespace glint::reference
