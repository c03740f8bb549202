// Tests of the blur planner (src/blur/blur_plan.h): Gaussian taps, the discrete variance and its
// inverse, the pyramid's variance bookkeeping and the per-method plans of docs/BLUR.md. CPU only.
// Expected values are derived here from the formulas of docs/BLUR.md, not copied from outputs.
#include "blur/blur_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "blur/blur_plan_internal.h"

namespace glint::blur_plan {
namespace {

// The discrete variance of docs/BLUR.md "Gaussian taps from sigma", written out independently.
double variance_by_formula(double sigma, double truncation = 3.0) {
  const int r = std::max(1, int(std::ceil(truncation * sigma)));
  double sum = 0.0, second = 0.0;
  for (int t = -r; t <= r; ++t) {
    const double w = std::exp(-double(t * t) / (2.0 * sigma * sigma));
    sum += w;
    second += w * t * t;
  }
  return second / sum;
}

TEST(BlurPlan, TapsSumToOneAndFollowTheRadiusRule) {
  for (double sigma : {0.3, 0.5, 1.0, 1.2, 2.0, 3.7, 16.0, 64.0}) {
    const std::vector<double> w = gaussian_half_taps(sigma);
    const size_t r = std::max<size_t>(1, size_t(std::ceil(3.0 * sigma)));
    ASSERT_EQ(w.size(), r + 1) << "sigma " << sigma;
    double sum = w[0];
    for (size_t t = 1; t < w.size(); ++t) {
      sum += 2.0 * w[t];
      EXPECT_LT(w[t], w[t - 1]) << "taps must decrease with |t|, sigma " << sigma;
      // The ratio of neighbouring taps is that of the Gaussian.
      EXPECT_NEAR(w[t] / w[0], std::exp(-double(t * t) / (2 * sigma * sigma)), 1e-12);
    }
    EXPECT_NEAR(sum, 1.0, 1e-14) << "sigma " << sigma;
  }
  EXPECT_EQ(2 * gaussian_half_taps(1.2).size() - 1, 9u) << "the default sigma 1.2 gives 9 taps";
  EXPECT_EQ(gaussian_half_taps(1.2, kPyramidTruncation), gaussian_half_taps(1.2));
  EXPECT_EQ(gaussian_half_taps(1.2, kGaussTruncation).size(), 6u) << "R = ceil(4 * 1.2) = 5";
  EXPECT_EQ(gaussian_half_taps(3.0, kGaussTruncation).size() - 1, kFusedMaxRadius) << "sigma 3 is the fused limit";
  EXPECT_THROW(gaussian_half_taps(1.0, 0.0), std::invalid_argument);
  EXPECT_EQ(gaussian_half_taps(0.0), std::vector<double>{1.0}) << "sigma 0 is the identity";
  EXPECT_THROW(gaussian_half_taps(-1.0), std::invalid_argument);
  EXPECT_THROW(gaussian_half_taps(std::nan("")), std::invalid_argument);
}

TEST(BlurPlan, DiscreteVarianceAndItsInverse) {
  for (double sigma : {0.4, 0.7, 1.2, 2.5, 5.9, 17.3, 63.1}) {
    const double v = discrete_variance(sigma);
    EXPECT_NEAR(v, variance_by_formula(sigma), 1e-12 * v);
    EXPECT_LT(v, sigma * sigma) << "truncation at 3 sigma lowers the variance";
    if (sigma >= 1.0) {  // once sampling resolves the bell, only the truncation lowers it
      EXPECT_GT(v, 0.95 * sigma * sigma);
    }
    EXPECT_NEAR(sigma_for_variance(v), sigma, 1e-9 * sigma) << "sigma " << sigma;
    const double v4 = discrete_variance(sigma, kGaussTruncation);
    EXPECT_NEAR(v4, variance_by_formula(sigma, 4.0), 1e-12 * v4);
    EXPECT_GE(v4, v) << "a longer (or the same) tail, a larger (or the same) variance";
    EXPECT_NEAR(sigma_for_variance(v4, kGaussTruncation), sigma, 1e-9 * sigma);
  }
  EXPECT_EQ(sigma_for_variance(0.0), 0.0);
  EXPECT_EQ(sigma_for_variance(-1.0), 0.0);
}

TEST(BlurPlan, PyramidEffectiveSigmaOfTheDefaults) {
  // Even chain (3840 -> 1920 -> 960 -> 480): each level adds the 2x2 box, a quarter of a
  // previous-level texel squared, and 4^k var(1.2).
  const double v = variance_by_formula(1.2);
  const double var1 = 1.0 * 0.25 + 4.0 * v;
  const double var2 = var1 + 4.0 * 0.25 + 16.0 * v;
  const double var3 = var2 + 16.0 * 0.25 + 64.0 * v;
  const std::vector<double> s = pyramid_effective_sigma(3840, {1.2, 1.2, 1.2});
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s[0], std::sqrt(var1), 1e-9);
  EXPECT_NEAR(s[1], std::sqrt(var2), 1e-9);
  EXPECT_NEAR(s[2], std::sqrt(var3), 1e-9);
  EXPECT_NEAR(s[0], 2.449, 1e-3);
  EXPECT_NEAR(s[1], 5.477, 1e-3);
  EXPECT_NEAR(s[2], 11.224, 1e-3);
  // Odd chain 5 -> 2 -> 1 -> 1: r = 2.5 then 2 then 1 (the last level adds only its blur).
  const std::vector<double> odd = pyramid_effective_sigma(5, {1.0, 1.0, 1.0});
  const double w1 = variance_by_formula(1.0);
  const double o1 = (2.5 * 2.5 - 1) / 12 + 2.5 * 2.5 * w1;
  const double o2 = o1 + 2.5 * 2.5 * 3.0 / 12 + 25.0 * w1;
  const double o3 = o2 + 25.0 * w1;
  EXPECT_NEAR(odd[0], std::sqrt(o1), 1e-9);
  EXPECT_NEAR(odd[1], std::sqrt(o2), 1e-9);
  EXPECT_NEAR(odd[2], std::sqrt(o3), 1e-9);
}

TEST(BlurPlan, SeparablePlan) {
  const Plan p = plan_method(Method::separable, 1.2, 3840, 2160, 1e-2);
  EXPECT_EQ(p.method, Method::separable);
  EXPECT_EQ(p.radius, 5u) << "GaussianBlur truncates at 4 sigma";
  EXPECT_NEAR(p.effective_sigma_px, std::sqrt(variance_by_formula(1.2, 4.0)), 1e-12);
  EXPECT_GT(p.expected_relative_l2, 0.0);
  EXPECT_LT(p.expected_relative_l2, 1e-3) << "truncation at 4 sigma leaves the bound to the methods";
  // Above the fused radius (12) the two line passes cost more bytes and a dispatch.
  const Plan big = plan_method(Method::separable, 4.0, 3840, 2160, 1e-2);
  EXPECT_EQ(big.radius, 16u);
  EXPECT_GT(big.cost, p.cost);
  const Plan lin = plan_method(Method::separable_linear, 1.2, 3840, 2160, 1e-2);
  EXPECT_EQ(lin.radius, p.radius);
  EXPECT_EQ(lin.expected_relative_l2, p.expected_relative_l2);
}

TEST(BlurPlan, PyramidPlanSolvesTheVarianceEquation) {
  for (double sigma : {3.0, 8.0, 24.0, 64.0}) {
    const Plan p = plan_method(Method::pyramid, sigma, 4096, 4096, 1.0);
    ASSERT_EQ(p.method, Method::pyramid);
    ASSERT_GE(p.levels, 1u);
    EXPECT_GE(p.level_sigma, 0.5) << "sigma " << sigma;
    EXPECT_LE(p.level_sigma, 3.0) << "sigma " << sigma;
    // docs/BLUR.md "pyramid" on an exact chain, s = 2^k: the binomials add 0.75 4^j for j < k,
    // i.e. (s^2 - 1) / 4; the cubic B-spline adds s^2 / 3 (docs: s^2 / 3 - 1/6, see blur_plan.cpp).
    const auto solve = [&](double s) { return (sigma * sigma - (s * s - 1) / 4 - s * s / 3) / (s * s); };
    const double s = double(1u << p.levels);
    EXPECT_NEAR(variance_by_formula(p.level_sigma, 4.0), solve(s), 1e-6 * solve(s)) << "sigma " << sigma;
    // With a loose bound the deepest level whose sigma_k is still >= 0.5 is taken.
    EXPECT_LT(solve(2 * s), variance_by_formula(0.5, 4.0)) << "sigma " << sigma;
    EXPECT_NEAR(p.effective_sigma_px, sigma, 1e-9 * sigma) << "variances add up";
    EXPECT_EQ(p.radius, uint32_t(std::max(1.0, std::ceil(4 * p.level_sigma))));
  }
  // The default bound takes fewer levels than a loose one, and meets the bound from sigma 4 on.
  const Plan tight = plan_method(Method::pyramid, 24.0, 4096, 4096, 1e-2);
  EXPECT_LE(tight.levels, plan_method(Method::pyramid, 24.0, 4096, 4096, 0.5).levels);
  EXPECT_LE(tight.expected_relative_l2, 1e-2);
  EXPECT_GE(tight.level_sigma, 0.5);
  // The padded extent caps k (docs/BLUR.md "Borders"): a 16x16 image at sigma 64 may take up to
  // floor(log2(16 + 8 x 64)) = 9 levels, enough for a level sigma in range.
  const Plan small = plan_method(Method::pyramid, 64.0, 16, 16, 1.0);
  EXPECT_LE(small.levels, 9u);
  EXPECT_LE(small.level_sigma, 3.0);
  EXPECT_GE(small.level_sigma, 0.5);
  EXPECT_NEAR(small.effective_sigma_px, 64.0, 1e-9 * 64.0);
}

TEST(BlurPlan, DualPlanMatchesTheSigma) {
  double previous_levels = 0;
  for (double sigma : {2.0, 4.0, 8.0, 16.0, 32.0, 64.0}) {
    const Plan p = plan_method(Method::dual, sigma, 4096, 4096, 1e-2);
    ASSERT_EQ(p.method, Method::dual);
    EXPECT_GE(p.dual_offset, 0.5);
    EXPECT_LE(p.dual_offset, 2.0);
    EXPECT_NEAR(p.effective_sigma_px, sigma, 1e-6 * sigma) << "o solves sigma(k, o) = sigma";
    EXPECT_GE(p.levels, previous_levels);
    previous_levels = p.levels;
    EXPECT_GT(p.expected_relative_l2, 0.0);
    EXPECT_EQ(p.cost > 0, true);
  }
  // Below the smallest dual blur: one level at o = 0.5, effective sigma above the request.
  const Plan tiny = plan_method(Method::dual, 0.5, 256, 256, 1e-2);
  EXPECT_EQ(tiny.levels, 1u);
  EXPECT_EQ(tiny.dual_offset, 0.5);
  EXPECT_GT(tiny.effective_sigma_px, 0.5);
}

TEST(BlurPlan, AutoTakesTheCheapestPlanWithinTheBound) {
  for (double bound : {1e-2, 0.1}) {
    for (double sigma : {0.5, 2.0, 6.0, 16.0, 48.0, 64.0}) {
      const Plan a = plan_auto(sigma, 3840, 2160, bound);
      EXPECT_NE(a.method, Method::separable_linear);
      if (a.method != Method::separable) {
        EXPECT_LE(a.expected_relative_l2, bound);
      }
      for (Method m : {Method::separable, Method::pyramid, Method::dual}) {
        const Plan p = plan_method(m, sigma, 3840, 2160, bound);
        if (p.expected_relative_l2 <= bound) {
          EXPECT_LE(a.cost, p.cost) << "sigma " << sigma << " bound " << bound;
        }
      }
    }
  }
  // From sigma 4 on, the pyramid meets the default bound more cheaply than full resolution.
  EXPECT_EQ(plan_auto(16.0, 3840, 2160, 1e-2).method, Method::pyramid);
  EXPECT_EQ(plan_auto(64.0, 3840, 2160, 1e-2).method, Method::pyramid);
  EXPECT_EQ(plan_auto(1.2, 3840, 2160, 1e-2).method, Method::separable);
  EXPECT_THROW(plan_auto(0.0, 64, 64, 1e-2), std::invalid_argument);
  EXPECT_THROW(plan_auto(2.0, 0, 64, 1e-2), std::invalid_argument);
}

// RGBA16F levels and output (what GaussianBlur stores by default): where the last level's two fp16
// shared copies would take the pyramid over the bound, the plan keeps them in fp32 and counts two
// roundings fewer (docs/BLUR.md "Error model"); where the fp16 copies meet it, it keeps them.
TEST(BlurPlan, PyramidKeepsFp32SharedCopiesOnlyWhereTheBoundNeedsThem) {
  Storage half;
  half.level_unit = half.output_unit = store_unit(10);
  half.level_half = half.output_half = true;
  const double two_copies = 2.0 * std::ldexp(1.0, -10);
  const Plan tight = plan_method(Method::pyramid, 64.0, 3840, 2160, 1e-2, half);
  EXPECT_TRUE(tight.fp32_shared);
  EXPECT_LE(tight.expected_relative_l2, 1e-2);
  // The fp16 copies would add two units, times 1 + the modelled error, to the same plan: over.
  EXPECT_GT(tight.expected_relative_l2 + two_copies, 1e-2) << "the fp16 copies would have met the bound";
  // A loose bound keeps the fp16 copies.
  EXPECT_FALSE(plan_method(Method::pyramid, 64.0, 3840, 2160, 0.5, half).fp32_shared);
  // Twice the shared bytes at the last level: its taps counted once more than with fp16 copies
  // (docs/BLUR.md "Cost model").
  const double last =
      double(tight.padding.padded_width >> tight.levels) * (tight.padding.padded_height >> tight.levels);
  const Work half_copies = detail::pyramid_work(tight.levels, tight.radius, 3840, 2160, tight.padding, false);
  EXPECT_DOUBLE_EQ(tight.work.shared_taps - half_copies.shared_taps, last * 2.0 * (2.0 * tight.radius + 1.0));
  // fp32 levels have no fp16 copies to drop.
  Storage full;
  EXPECT_FALSE(plan_method(Method::pyramid, 64.0, 3840, 2160, 1e-2, full).fp32_shared);
  // sigma 16 meets the default bound with the fp16 copies, and auto takes the pyramid at both.
  EXPECT_FALSE(plan_method(Method::pyramid, 16.0, 3840, 2160, 1e-2, half).fp32_shared);
  EXPECT_EQ(plan_auto(64.0, 3840, 2160, 1e-2, half).method, Method::pyramid);
  EXPECT_EQ(plan_auto(16.0, 3840, 2160, 1e-2, half).method, Method::pyramid);
}

// docs/BLUR.md "Borders": the padded chain is an exact 2:1 chain (sizes multiples of 2^k, pads
// multiples of 2^k) that extends the input by at least the reach of every level on both sides,
// and no further than needed by one level-k block.
TEST(BlurPlan, PaddingMakesAnExactChainBeyondTheReachOfEveryLevel) {
  for (uint32_t w : {1u, 7u, 203u, 512u, 1921u}) {
    for (double sigma : {1.0, 4.0, 20.0, 50.0}) {
      for (Method m : {Method::pyramid, Method::dual}) {
        const Plan p = plan_method(m, sigma, w, 157, 1e-2);
        const Padding& pad = p.padding;
        const uint32_t block = 1u << p.levels;
        SCOPED_TRACE(testing::Message() << "w " << w << " sigma " << sigma << " method " << unsigned(m));
        EXPECT_EQ(pad.pad_x % block, 0u);
        EXPECT_EQ(pad.padded_width % block, 0u);
        EXPECT_EQ(pad.padded_height % block, 0u);
        EXPECT_GE(pad.padded_width, w + 2 * pad.pad_x) << "the right pad is at least the left one";
        EXPECT_LT(pad.padded_width, w + 2 * pad.pad_x + block);
        // At least the reach of the level-k filter: the pyramid's blur radius and B-spline (R + 2
        // level texels), the dual's k up passes (o + 1 level texels each, halved per level).
        const double reach = m == Method::pyramid ? (p.radius + 2.0) * block : (p.dual_offset + 1.0) * block;
        EXPECT_GE(pad.pad_x, reach);
        // The same plan's padding_of() recomputes it (the reference uses that).
        const Padding again = padding_of(p, w, 157);
        EXPECT_EQ(again.pad_x, pad.pad_x);
        EXPECT_EQ(again.padded_height, pad.padded_height);
      }
    }
  }
  const Plan sep = plan_method(Method::separable, 3.0, 100, 50, 1e-2);
  EXPECT_EQ(sep.padding.pad_x, 0u);
  EXPECT_EQ(sep.padding.padded_width, 100u);
}

// The fit recovers the constants that generated the measurements, and keeps every constant
// positive when the data would drive one below zero.
TEST(BlurPlan, CostModelFitRecoversItsConstants) {
  CostModel truth;
  truth.us_per_dispatch = 40.0;
  truth.us_per_byte = 2e-4;
  truth.us_per_shared_tap = 3e-2;
  truth.us_per_fetch_tap = 5e-3;
  std::vector<Work> work;
  std::vector<double> us;
  for (Method m : {Method::separable, Method::pyramid, Method::dual}) {
    for (double sigma : {1.5, 8.0}) {
      for (uint32_t n : {32u, 128u}) {
        work.push_back(plan_method(m, sigma, n, n, 1e-2).work);
        us.push_back(truth.estimate_us(work.back()));
      }
    }
  }
  const CostModel fit = fit_cost_model(work, us);
  EXPECT_NEAR(fit.us_per_dispatch, truth.us_per_dispatch, 1e-6 * truth.us_per_dispatch);
  EXPECT_NEAR(fit.us_per_byte, truth.us_per_byte, 1e-6 * truth.us_per_byte);
  EXPECT_NEAR(fit.us_per_shared_tap, truth.us_per_shared_tap, 1e-6 * truth.us_per_shared_tap);
  EXPECT_NEAR(fit.us_per_fetch_tap, truth.us_per_fetch_tap, 1e-6 * truth.us_per_fetch_tap);
  // Times that fall with the work: no negative constant comes out.
  std::vector<double> falling(us.size());
  for (size_t i = 0; i < us.size(); ++i) falling[i] = 100.0 / (1.0 + double(i));
  const CostModel odd = fit_cost_model(work, falling);
  EXPECT_GT(odd.us_per_dispatch, 0.0);
  EXPECT_GT(odd.us_per_byte, 0.0);
  EXPECT_GT(odd.us_per_shared_tap, 0.0);
  EXPECT_GT(odd.us_per_fetch_tap, 0.0);
  EXPECT_THROW(fit_cost_model({Work{}}, {1.0}), std::invalid_argument);
}

// auto ranks by the device's model: where taps are dear and dispatches cheap (a CPU device), a
// 401-tap separable blur loses to the pyramid that the H100's dispatch-bound model may prefer on
// a small image; the choice always meets the bound.
TEST(BlurPlan, AutoFollowsTheDevicesCostModel) {
  CostModel cpu;
  cpu.us_per_dispatch = 50.0;
  cpu.us_per_byte = 1e-3;
  cpu.us_per_shared_tap = 3e-2;
  cpu.us_per_fetch_tap = 1e-2;
  const Plan a = plan_auto(50.0, 512, 512, 0.02, cpu);
  EXPECT_EQ(a.method, Method::pyramid);
  EXPECT_LE(a.expected_relative_l2, 0.02);
  EXPECT_DOUBLE_EQ(a.cost, cpu.estimate_us(a.work));
  const Plan sep = plan_method(Method::separable, 50.0, 512, 512, 0.02);
  EXPECT_GT(cpu.estimate_us(sep.work), 10.0 * a.cost);
}

}  // namespace
}  // namespace glint::blur_plan
