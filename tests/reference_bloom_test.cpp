// Tests of the float64 bloom reference (tools/reference/bloom_reference.h) on its own: CPU only,
// no Vulkan. Hand-computed values check the formulas of docs/BLOOM.md stage by stage; property
// tests (uniformity, symmetry, monotonicity, locality) check the assembled pipeline on random
// inputs from generators started at fixed values.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/half.h"
#include "reference/bloom_reference.h"

namespace glint::reference {
namespace {

constexpr BloomFilter kFilters[] = {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9};
constexpr FireflyGuard kGuards[] = {FireflyGuard::off, FireflyGuard::karis, FireflyGuard::karis_smooth};

// A config whose prefilter is the identity for any texel with luma >= 1e-4 (threshold 0, knee 0:
// factor = max(l, 0) / max(l, 1e-4) = 1), so downsample and blur can be checked in isolation.
BloomConfig identity_prefilter_config(BloomFilter filter) {
  BloomConfig c;
  c.threshold = 0.0f;
  c.soft_knee = 0.0f;
  c.filter = filter;
  c.firefly_guard = FireflyGuard::off;
  c.iterations = 1;
  return c;
}

// Random RGB in [lo, hi] per channel, alpha in [0, 1].
CpuImage random_image(uint32_t w, uint32_t h, uint32_t stream, float lo, float hi) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> rgb(lo, hi), alpha(0.0f, 1.0f);
  CpuImage img(w, h);
  for (size_t i = 0; i < img.rgba.size(); i += 4) {
    img.rgba[i] = rgb(rng);
    img.rgba[i + 1] = rgb(rng);
    img.rgba[i + 2] = rgb(rng);
    img.rgba[i + 3] = alpha(rng);
  }
  return img;
}

// Random RGB in [0.1, 1] on a 1/1024 grid, so that adding 1, 2 or 0.5 in float is exact and an
// impulse added on top of it is exactly the intended one.
CpuImage gridded_background(uint32_t w, uint32_t h, uint32_t stream) {
  CpuImage img = random_image(w, h, stream, 0.1f, 1.0f);
  for (float& v : img.rgba) v = std::round(v * 1024.0f) / 1024.0f;
  return img;
}

// Non-constant background whose luma is below threshold - knee of the default config (1 - 0.5):
// every channel is at most 0.45, so luma <= 0.45 and the prefilter gives exactly 0 there.
CpuImage dark_background(uint32_t w, uint32_t h, uint32_t stream) { return random_image(w, h, stream, 0.0f, 0.45f); }

// Random HDR: channels log-uniform over [e^-4, e^5] (0.018 to 148), a few texels up to 900.
CpuImage random_hdr(uint32_t w, uint32_t h, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> expo(-4.0f, 5.0f), u(0.0f, 1.0f);
  CpuImage img(w, h);
  for (size_t i = 0; i < img.rgba.size(); i += 4) {
    const float boost = u(rng) < 0.01f ? 6.0f : 1.0f;
    for (size_t k = 0; k < 3; ++k) img.rgba[i + k] = boost * std::exp(expo(rng));
    img.rgba[i + 3] = u(rng);
  }
  return img;
}

void set_rgb(CpuImage& img, uint32_t x, uint32_t y, float r, float g, float b) {
  float* p = img.at(x, y);
  p[0] = r;
  p[1] = g;
  p[2] = b;
}

// The light bloom added at each pixel, summed over RGB: out - in.
std::vector<double> added_light(const DoubleImage& out, const CpuImage& in) {
  std::vector<double> added(size_t(in.width) * in.height);
  for (size_t p = 0; p < added.size(); ++p)
    for (size_t k = 0; k < 3; ++k) added[p] += out.rgba[p * 4 + k] - double(in.rgba[p * 4 + k]);
  return added;
}

double total(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s;
}

// Centroid and central second moments of the added light.
struct Glow {
  double energy = 0, cx = 0, cy = 0, mxx = 0, myy = 0, mxy = 0;
};

Glow glow_of(const DoubleImage& out, const CpuImage& in) {
  const std::vector<double> added = added_light(out, in);
  Glow g;
  for (uint32_t y = 0; y < in.height; ++y)
    for (uint32_t x = 0; x < in.width; ++x) {
      const double l = added[size_t(y) * in.width + x];
      g.energy += l;
      g.cx += l * x;
      g.cy += l * y;
    }
  g.cx /= g.energy;
  g.cy /= g.energy;
  for (uint32_t y = 0; y < in.height; ++y)
    for (uint32_t x = 0; x < in.width; ++x) {
      const double l = added[size_t(y) * in.width + x];
      g.mxx += l * (x - g.cx) * (x - g.cx);
      g.myy += l * (y - g.cy) * (y - g.cy);
      g.mxy += l * (x - g.cx) * (y - g.cy);
    }
  g.mxx /= g.energy;
  g.myy /= g.energy;
  g.mxy /= g.energy;
  return g;
}

CpuImage to_float(const DoubleImage& d) {
  CpuImage img(d.width, d.height);
  for (size_t i = 0; i < d.rgba.size(); ++i) img.rgba[i] = static_cast<float>(d.rgba[i]);
  return img;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::array<double, 3> prefiltered(const BloomConfig& config, double r, double g, double b) {
  const double in[3] = {r, g, b};
  std::array<double, 3> out{};
  prefilter(config, in, out.data());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Luma and prefilter

TEST(BloomReferenceLuma, Rec709Weights) {
  EXPECT_DOUBLE_EQ(luma(1, 0, 0), 0.2126);
  EXPECT_DOUBLE_EQ(luma(0, 1, 0), 0.7152);
  EXPECT_DOUBLE_EQ(luma(0, 0, 1), 0.0722);
  EXPECT_NEAR(luma(2, 4, 1), 3.3582, 1e-12);
}

TEST(BloomReferencePrefilter, BelowThresholdMinusKneeIsExactlyZero) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct Case {
    float threshold, soft_knee;
  };
  for (const Case c : {Case{1.0f, 0.5f}, Case{2.0f, 0.25f}, Case{1.0f, 0.0f}, Case{5.0f, 1.0f}}) {
    BloomConfig config;
    config.threshold = c.threshold;
    config.soft_knee = c.soft_knee;
    const double edge = double(c.threshold) * (1.0 - double(c.soft_knee));  // threshold - knee
    for (int i = 0; i < 2000; ++i) {
      // A random colour scaled to a random luma strictly below the edge.
      double rgb[3] = {u(rng), u(rng), u(rng)};
      const double target = edge * u(rng) * 0.9999;
      const double scale = target / luma(rgb[0], rgb[1], rgb[2]);
      for (double& v : rgb) v *= scale;
      const auto out = prefiltered(config, rgb[0], rgb[1], rgb[2]);
      ASSERT_EQ(out[0], 0.0) << "t=" << c.threshold << " knee=" << c.soft_knee << " luma " << target;
      ASSERT_EQ(out[1], 0.0);
      ASSERT_EQ(out[2], 0.0);
    }
  }
}

TEST(BloomReferencePrefilter, WellAboveKneeScalesByExcessOverLuma) {
  BloomConfig config;  // threshold 1, knee 0.5: the knee ends at luma 1.5
  // Hand-computed: luma(2, 4, 1) = 3.3582, factor = (3.3582 - 1) / 3.3582 = 0.70222142814603.
  const auto out = prefiltered(config, 2, 4, 1);
  EXPECT_NEAR(out[0], 1.40444285629206, 1e-12);
  EXPECT_NEAR(out[1], 2.80888571258412, 1e-12);
  EXPECT_NEAR(out[2], 0.70222142814603, 1e-12);
  // Grey 4: factor 3/4.
  const auto grey = prefiltered(config, 4, 4, 4);
  for (double v : grey) EXPECT_NEAR(v, 3.0, 1e-12);

  // Random colours with luma well above threshold + knee.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    double rgb[3] = {u(rng), u(rng), u(rng)};
    const double l = 1.6 + 50.0 * u(rng);
    const double s = l / (0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]);
    for (double& v : rgb) v *= s;
    const auto o = prefiltered(config, rgb[0], rgb[1], rgb[2]);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(o[size_t(k)], rgb[k] * (l - 1.0) / l, 1e-9 * rgb[k]);
  }
}

TEST(BloomReferencePrefilter, InsideKneeFollowsQuadraticCurve) {
  BloomConfig config;  // threshold 1, knee 0.5
  // Grey g has luma g, and the output of a grey is the contribution itself:
  // luma 1:    soft = 0.5,  contribution = 0.25 / 2.0001   = 0.124993750312484
  // luma 0.75: soft = 0.25, contribution = 0.0625 / 2.0001 = 0.031248437578121
  for (double v : prefiltered(config, 1, 1, 1)) EXPECT_NEAR(v, 0.124993750312484, 1e-12);
  for (double v : prefiltered(config, 0.75, 0.75, 0.75)) EXPECT_NEAR(v, 0.031248437578121, 1e-12);
}

TEST(BloomReferencePrefilter, ContinuousAndMonotonicAcrossTheKnee) {
  BloomConfig config;
  config.threshold = 2.0f;
  config.soft_knee = 0.5f;  // knee 1: curve between luma 1 and 3
  // For a grey the output luma is max(l - t, contribution), whose slope is at most 1: over a
  // step h the output may not jump by more than h, and it never decreases.
  const double h = 1e-4;
  double prev = 0.0;
  for (double g = 0.0; g <= 5.0; g += h) {
    const auto o = prefiltered(config, g, g, g);
    const double l = luma(o[0], o[1], o[2]);
    ASSERT_GE(l, prev) << "at grey " << g;
    ASSERT_LE(l - prev, 1.0001 * h) << "jump at grey " << g;
    prev = l;
  }
  // Both edges of the knee, approached from either side.
  for (double edge : {1.0, 3.0}) {
    const double d = 1e-7;
    const auto below = prefiltered(config, edge - d, edge - d, edge - d);
    const auto above = prefiltered(config, edge + d, edge + d, edge + d);
    EXPECT_NEAR(below[1], above[1], 3 * d) << "edge " << edge;
  }
  // Past the upper edge the line l - t takes over: at luma 3 the output is 1 (not 4/(4.0001)).
  const auto at3 = prefiltered(config, 3.0 + 1e-9, 3.0 + 1e-9, 3.0 + 1e-9);
  EXPECT_NEAR(at3[0], 1.0, 1e-8);
}

TEST(BloomReferencePrefilter, SanitizesNaNNegativeAndInf) {
  // Source texels clamp to 65504 whatever max_brightness is (that one clamps level 0).
  BloomConfig config = identity_prefilter_config(BloomFilter::cod13);
  config.max_brightness = 1000.0f;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto a = prefiltered(config, nan, -3.0, inf);
  EXPECT_EQ(a[0], 0.0);
  EXPECT_EQ(a[1], 0.0);
  EXPECT_DOUBLE_EQ(a[2], 65504.0);
  const auto b = prefiltered(config, 5000.0, 1.0, -inf);
  EXPECT_DOUBLE_EQ(b[0], 5000.0);
  EXPECT_DOUBLE_EQ(b[1], 1.0);
  EXPECT_EQ(b[2], 0.0);
  const auto c = prefiltered(config, 1e9, 70000.0, 65504.0);
  EXPECT_DOUBLE_EQ(c[0], 65504.0);
  EXPECT_DOUBLE_EQ(c[1], 65504.0);
  EXPECT_DOUBLE_EQ(c[2], 65504.0);
}

TEST(BloomReferenceLevels, MaxBrightnessClampsLevel0PerChannel) {
  // A uniform 4000 image: level 0 is 4000 everywhere before the clamp, max_brightness 1000 after;
  // level 1 is the mean of level 0, so also 1000. A per-pixel clamp would give the same here; the
  // point below tells them apart: one pixel of 4000 in black gives a level-0 peak under 1000.
  for (FireflyGuard guard : kGuards) {
    BloomConfig config = identity_prefilter_config(BloomFilter::cod13);
    config.firefly_guard = guard;
    config.iterations = 2;
    config.max_brightness = 1000.0f;
    CpuImage flat(16, 16, 0.0f);
    for (uint32_t y = 0; y < 16; ++y)
      for (uint32_t x = 0; x < 16; ++x) set_rgb(flat, x, y, 4000, 500, 4000);
    const auto levels = downsampled_levels(flat, config);
    for (const DoubleImage& level : levels)
      for (size_t i = 0; i < level.rgba.size(); i += 4) {
        EXPECT_NEAR(level.rgba[i], 1000.0, 1e-9) << firefly_guard_name(guard);
        EXPECT_NEAR(level.rgba[i + 1], 500.0, 1e-9) << firefly_guard_name(guard);
      }
    CpuImage point(16, 16, 0.0f);
    set_rgb(point, 8, 8, 4000, 4000, 4000);
    config.firefly_guard = FireflyGuard::off;
    double sum = 0.0;
    const auto point_levels = downsampled_levels(point, config);
    for (double v : point_levels[0].rgba) sum += v;
    // Energy of level 0 (RGB, plus 64 alphas of 1) is a quarter of the point's: nothing clipped.
    EXPECT_NEAR(sum - 64.0, 3 * 4000.0 / 4.0, 1e-6);
  }
}

// ---------------------------------------------------------------------------------------------
// Mip chain and the individual filters

TEST(BloomReferenceLevels, MipChainSizesAndClamp) {
  struct Case {
    uint32_t w, h, iterations;
    std::vector<std::pair<uint32_t, uint32_t>> sizes;
  };
  const std::vector<Case> cases = {
      {1920, 1080, 5, {{960, 540}, {480, 270}, {240, 135}, {120, 67}, {60, 33}}},
      {3, 5, 5, {{1, 2}}},
      {1, 1, 5, {{1, 1}}},
      {1, 40, 5, {{1, 20}}},
      {40, 1, 5, {{20, 1}}},
      {16, 16, 8, {{8, 8}, {4, 4}, {2, 2}}},
      {17, 9, 5, {{8, 4}, {4, 2}}},
      {5, 5, 1, {{2, 2}}},
  };
  for (const Case& c : cases) {
    BloomConfig config;
    config.iterations = c.iterations;
    const auto levels = downsampled_levels(random_image(c.w, c.h, 21, 0.0f, 2.0f), config);
    ASSERT_EQ(levels.size(), c.sizes.size()) << c.w << "x" << c.h;
    for (size_t k = 0; k < levels.size(); ++k) {
      EXPECT_EQ(levels[k].width, c.sizes[k].first) << c.w << "x" << c.h << " level " << k;
      EXPECT_EQ(levels[k].height, c.sizes[k].second) << c.w << "x" << c.h << " level " << k;
      EXPECT_EQ(levels[k].rgba.size(), size_t(levels[k].width) * levels[k].height * 4);
    }
  }
}

// Level 0 of (random background + colour impulse at one texel) minus level 0 of the background
// alone: with an identity prefilter and no Karis guard the downsample is linear, so the difference
// is the filter's impulse response times the colour, which is hand-computed below.
std::vector<double> level0_impulse_response(BloomFilter filter, uint32_t w, uint32_t h, uint32_t px, uint32_t py,
                                            uint32_t stream) {
  const BloomConfig config = identity_prefilter_config(filter);
  const CpuImage bg = gridded_background(w, h, stream);
  CpuImage with = bg;
  float* t = with.at(px, py);
  t[0] += 1.0f;
  t[1] += 2.0f;
  t[2] += 0.5f;
  const DoubleImage a = downsampled_levels(with, config)[0];
  const DoubleImage b = downsampled_levels(bg, config)[0];
  std::vector<double> diff(a.rgba.size());
  for (size_t i = 0; i < diff.size(); ++i) diff[i] = a.rgba[i] - b.rgba[i];
  return diff;
}

void expect_response(const std::vector<double>& diff, uint32_t width, const std::vector<double>& expected,
                     const char* what) {
  // Colour (1, 2, 0.5) times the scalar response.
  const double colour[3] = {1.0, 2.0, 0.5};
  ASSERT_EQ(diff.size(), expected.size() * 4);
  for (size_t p = 0; p < expected.size(); ++p)
    for (size_t k = 0; k < 3; ++k)
      EXPECT_NEAR(diff[p * 4 + k], expected[p] * colour[k], 1e-12)
          << what << " texel (" << p % width << ", " << p / width << ") channel " << k;
}

TEST(BloomReferenceLevels, Cod13DownsampleImpulseResponse) {
  // 8x8 -> 4x4, impulse at (4, 4). Texel (x, y) samples at (2x + 0.5, 2y + 0.5) + offsets; a tap
  // at a half-integer next to texel 4 gives it weight 1/2 per axis. Worked out per texel from the
  // centre box (weight 0.5) and the four corner boxes (0.125 each).
  const std::vector<double> expected = {
      0, 0,         0,        0,          //
      0, 0.0390625, 0.046875, 0.0078125,  //
      0, 0.046875,  0.0625,   0.015625,   //
      0, 0.0078125, 0.015625, 0.0078125,  //
  };
  expect_response(level0_impulse_response(BloomFilter::cod13, 8, 8, 4, 4, 31), 4, expected, "cod13");
}

TEST(BloomReferenceLevels, DualDownsampleImpulseResponse) {
  // (4 bilinear(p) + diagonals) / 8 at p = (2x + 0.5, 2y + 0.5): texel (2,2) gets (4/4 + 1/4) / 8;
  // (1,1), (1,2), (2,1) get one diagonal tap of weight 1/4, i.e. 1/32.
  const std::vector<double> expected = {
      0, 0,       0,       0,  //
      0, 0.03125, 0.03125, 0,  //
      0, 0.03125, 0.15625, 0,  //
      0, 0,       0,       0,  //
  };
  expect_response(level0_impulse_response(BloomFilter::dual, 8, 8, 4, 4, 32), 4, expected, "dual");
}

TEST(BloomReferenceLevels, Gauss9AreaDownsampleThenBlur) {
  // 32x1 -> level 0 is 16x1 (the only level). Raising source texels 16 and 17 by the colour raises
  // level texel 8's area average by the colour; the horizontal blur at radius 1 then spreads it as
  // the 9 weights, and the vertical blur of a 1-row level is the identity (weights sum to 1).
  const double w[5] = {0.2270270270, 0.1945945946, 0.1216216216, 0.0540540541, 0.0162162162};
  for (float radius : {1.0f, 0.5f}) {
    BloomConfig config = identity_prefilter_config(BloomFilter::gauss9);
    config.radius = radius;
    const CpuImage bg = gridded_background(32, 1, 33);
    CpuImage with = bg;
    for (uint32_t x : {16u, 17u}) {
      float* t = with.at(x, 0);
      t[0] += 1.0f;
      t[1] += 2.0f;
      t[2] += 0.5f;
    }
    const auto la = downsampled_levels(with, config);
    const auto lb = downsampled_levels(bg, config);
    ASSERT_EQ(la.size(), 1u);
    ASSERT_EQ(la[0].width, 16u);
    std::vector<double> diff(la[0].rgba.size());
    for (size_t i = 0; i < diff.size(); ++i) diff[i] = la[0].rgba[i] - lb[0].rgba[i];
    std::vector<double> expected(16, 0.0);
    if (radius == 1.0f) {
      for (int d = -4; d <= 4; ++d) expected[size_t(8 + d)] = w[std::abs(d)];
    } else {
      // Taps at half-texel offsets read linear interpolations; hat(q) = max(0, 1 - |q - 8|).
      // d = 0: w0 + w1 (hat(8.5) + hat(7.5));  d = 1: 0.5 w1 (8.5) + w2 (8) + 0.5 w3 (7.5);
      // d = 2: 0.5 w3 (8.5) + w4 (8);  d = 3: the nearest taps are 9 and 9.5: nothing.
      expected[8] = w[0] + w[1];
      expected[7] = expected[9] = 0.5 * w[1] + w[2] + 0.5 * w[3];
      expected[6] = expected[10] = 0.5 * w[3] + w[4];
    }
    expect_response(diff, 16, expected, radius == 1.0f ? "gauss9 r=1" : "gauss9 r=0.5");
  }
}

TEST(BloomReferenceLevels, KarisGuardWeightsBoxesByInverseLuma) {
  // 2x1 -> 1x1 with gauss9: two boxes of overlap 1: texel 0 black, texel 1 grey 3 (luma 3).
  // Guard off: mean 1.5. Guard on: (0 + 3/4) / (1/1 + 1/4) = 0.6.
  CpuImage in(2, 1, 0.0f);
  set_rgb(in, 1, 0, 3, 3, 3);
  BloomConfig config = identity_prefilter_config(BloomFilter::gauss9);
  config.firefly_guard = FireflyGuard::off;
  const auto off = downsampled_levels(in, config);
  config.firefly_guard = FireflyGuard::karis;
  const auto on = downsampled_levels(in, config);
  ASSERT_EQ(on.size(), 1u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(off[0].rgba[k], 1.5, 1e-12);
    EXPECT_NEAR(on[0].rgba[k], 0.6, 1e-12);
  }
  // The full bloom of that 1-level pyramid: out = in + intensity * 0.6 everywhere.
  const DoubleImage out = bloom(in, config);
  const double intensity = config.intensity;  // 0.3f, not exactly 0.3
  EXPECT_NEAR(out.rgba[0], intensity * 0.6, 1e-12);
  EXPECT_NEAR(out.rgba[4], 3.0 + intensity * 0.6, 1e-12);
}

TEST(BloomReferenceLevels, KarisGuardUsesLumaOfTheBoxMean) {
  // Same 2x1 -> 1x1 setup with a coloured texel m: (m / (1 + l)) / (1 + 1 / (1 + l)) = m / (2 + l),
  // l = luma(3, 0, 6) = 0.6378 + 0.4332 = 1.071.
  CpuImage in(2, 1, 0.0f);
  set_rgb(in, 1, 0, 3, 0, 6);
  BloomConfig config = identity_prefilter_config(BloomFilter::gauss9);
  config.firefly_guard = FireflyGuard::karis;
  const DoubleImage l0 = downsampled_levels(in, config)[0];
  EXPECT_NEAR(l0.rgba[0], 3.0 / 3.071, 1e-12);
  EXPECT_NEAR(l0.rgba[1], 0.0, 1e-12);
  EXPECT_NEAR(l0.rgba[2], 6.0 / 3.071, 1e-12);
}

TEST(BloomReferenceLevels, Gauss9AreaDownsampleAtOddSize) {
  // 5x1 -> 2x1: texel 0 covers [0, 2.5), texel 1 [2.5, 5), so source texel 2 is split in half:
  // L0 = (a + b + c/2) / 2.5, L1 = (c/2 + d + e) / 2.5. The horizontal blur of a 2-texel level
  // (radius 1, clamp to edge) reads L1 at every positive offset and L0 at every negative one:
  // out0 = (w0 + S) L0 + S L1 and out1 = S L0 + (w0 + S) L1 with S = w1 + w2 + w3 + w4.
  CpuImage in(5, 1, 0.0f);
  const float v[5] = {1.0f, 2.0f, 4.0f, 8.0f, 0.5f};
  for (uint32_t x = 0; x < 5; ++x) set_rgb(in, x, 0, v[x], 2 * v[x], v[4 - x]);
  const BloomConfig config = identity_prefilter_config(BloomFilter::gauss9);
  const auto levels = downsampled_levels(in, config);
  ASSERT_EQ(levels.size(), 1u);
  ASSERT_EQ(levels[0].width, 2u);
  const double w0 = 0.2270270270, S = 0.1945945946 + 0.1216216216 + 0.0540540541 + 0.0162162162;
  for (size_t k = 0; k < 3; ++k) {
    const double c[5] = {in.at(0, 0)[k], in.at(1, 0)[k], in.at(2, 0)[k], in.at(3, 0)[k], in.at(4, 0)[k]};
    const double l0 = (c[0] + c[1] + 0.5 * c[2]) / 2.5;
    const double l1 = (0.5 * c[2] + c[3] + c[4]) / 2.5;
    EXPECT_NEAR(levels[0].at(0, 0)[k], (w0 + S) * l0 + S * l1, 1e-9) << "channel " << k;
    EXPECT_NEAR(levels[0].at(1, 0)[k], S * l0 + (w0 + S) * l1, 1e-9) << "channel " << k;
  }
}

TEST(BloomReferenceLevels, KarisSmoothIsKarisOfTheBinomialFilteredSource) {
  // karis_smooth = the per-box Karis downsample of the source filtered by the 2-D binomial
  // C(10, a) C(10, b) / 1024^2 with clamp to edge. Filter here directly in 2-D (not separably, as
  // the reference and the kernel do), feed the result back with an identity prefilter and per-box
  // Karis, and compare. Odd size so that the general (non 2:1) downsample is covered as well.
  const CpuImage in = random_hdr(23, 18, 43);
  double c10[11];
  for (int m = 0; m <= 10; ++m) {
    double c = 1.0;
    for (int i = 1; i <= m; ++i) c = c * (11 - i) / i;
    c10[m] = c / 1024.0;
  }
  for (BloomFilter filter : kFilters) {
    BloomConfig config = identity_prefilter_config(filter);
    config.firefly_guard = FireflyGuard::karis_smooth;
    const DoubleImage smooth = downsampled_levels(in, config)[0];
    CpuImage filtered(in.width, in.height, 0.0f);
    for (int y = 0; y < int(in.height); ++y)
      for (int x = 0; x < int(in.width); ++x)
        for (int k = 0; k < 4; ++k) {
          double sum = 0.0;
          for (int b = -5; b <= 5; ++b)
            for (int a = -5; a <= 5; ++a) {
              const int i = std::clamp(x + a, 0, int(in.width) - 1), j = std::clamp(y + b, 0, int(in.height) - 1);
              sum += c10[a + 5] * c10[b + 5] * in.at(i, j)[k];
            }
          filtered.at(x, y)[k] = static_cast<float>(sum);
        }
    config.firefly_guard = FireflyGuard::karis;
    const DoubleImage box = downsampled_levels(filtered, config)[0];
    config.firefly_guard = FireflyGuard::karis;
    const DoubleImage raw = downsampled_levels(in, config)[0];
    double err = 0.0, norm = 0.0, differs = 0.0;
    for (size_t i = 0; i < box.rgba.size(); ++i) {
      err = std::max(err, std::abs(smooth.rgba[i] - box.rgba[i]));
      differs = std::max(differs, std::abs(smooth.rgba[i] - raw.rgba[i]));
      norm = std::max(norm, std::abs(box.rgba[i]));
    }
    EXPECT_LT(err, 1e-6 * norm) << bloom_filter_name(filter);      // float rounding of the fed-back image
    EXPECT_GT(differs, 1e-2 * norm) << bloom_filter_name(filter);  // and the prefilter does change level 0
  }
}

TEST(BloomReferenceLevels, KarisGuardOnlyOnTheFirstDownsample) {
  // Level 1 of a guarded pyramid must be the plain (unguarded) downsample of its level 0. Feed
  // level 0 back in as an image with an identity prefilter: its level 0 is then Down(level 0).
  const CpuImage in = random_hdr(64, 48, 41);
  BloomConfig config;
  config.iterations = 2;
  config.firefly_guard = FireflyGuard::karis;
  const auto levels = downsampled_levels(in, config);
  ASSERT_EQ(levels.size(), 2u);
  const DoubleImage& l0 = levels[0];
  CpuImage l0_image(l0.width, l0.height);
  for (size_t i = 0; i < l0.rgba.size(); ++i) l0_image.rgba[i] = static_cast<float>(l0.rgba[i]);

  BloomConfig plain = identity_prefilter_config(BloomFilter::cod13);
  const DoubleImage unguarded = downsampled_levels(l0_image, plain)[0];
  plain.firefly_guard = FireflyGuard::karis;
  const DoubleImage guarded = downsampled_levels(l0_image, plain)[0];
  ASSERT_EQ(unguarded.width, levels[1].width);
  ASSERT_EQ(unguarded.height, levels[1].height);
  double err = 0.0, diff_if_guarded = 0.0, norm = 0.0;
  for (size_t i = 0; i < unguarded.rgba.size(); i += 4)
    for (size_t k = 0; k < 3; ++k) {
      err = std::max(err, std::abs(levels[1].rgba[i + k] - unguarded.rgba[i + k]));
      diff_if_guarded = std::max(diff_if_guarded, std::abs(levels[1].rgba[i + k] - guarded.rgba[i + k]));
      norm = std::max(norm, std::abs(levels[1].rgba[i + k]));
    }
  EXPECT_LT(err, 1e-6 * norm);              // only float rounding of the fed-back level 0
  EXPECT_GT(diff_if_guarded, 1e-3 * norm);  // a guard at level 1 would be visible

  // And the guard does change level 0.
  config.firefly_guard = FireflyGuard::off;
  const auto off = downsampled_levels(in, config);
  double diff0 = 0.0;
  for (size_t i = 0; i < l0.rgba.size(); ++i) diff0 = std::max(diff0, std::abs(l0.rgba[i] - off[0].rgba[i]));
  EXPECT_GT(diff0, 1e-2);
}

// ---------------------------------------------------------------------------------------------
// Upsample

// Up of (random background + unit impulse at small texel (1, 1)) minus Up of the background.
std::vector<double> upsample_impulse_response(BloomFilter filter, double radius) {
  DoubleImage bg;
  bg.width = 3;
  bg.height = 3;
  std::mt19937 rng(51);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 36; ++i) bg.rgba.push_back(u(rng));
  DoubleImage with = bg;
  double* t = with.at(1, 1);
  t[0] += 1.0;
  t[1] += 2.0;
  t[2] += 0.5;
  const DoubleImage a = upsample(with, 6, 6, filter, radius);
  const DoubleImage b = upsample(bg, 6, 6, filter, radius);
  std::vector<double> diff(a.rgba.size());
  for (size_t i = 0; i < diff.size(); ++i) diff[i] = a.rgba[i] - b.rgba[i];
  return diff;
}

TEST(BloomReferenceUpsample, ImpulseResponsesAtHandComputedTexels) {
  // 3x3 -> 6x6: texel x maps to p = x / 2 - 0.25. Per axis the bilinear weight of small texel 1
  // at position q is max(0, 1 - |q - 1|).
  //  cod13 (tent, radius 1), x = 2 (p = 0.75): 0.25*w(-0.25) + 0.5*w(0.75) + 0.25*w(1.75) = 0.4375,
  //    same for x = 3; x = 0 (p = -0.25): 0.25 * w(0.75) = 0.1875.
  //  dual (radius 1) at (2, 2): edges 0 + 0.1875 + 0 + 0.1875, diagonals 0.0625 + 2 * 0.1875 + 0.5625
  //    = 1: (0.375 + 2) / 12; at (0, 0): only the diagonal (0.25, 0.25): 2 * 0.0625 / 12.
  //  gauss9: plain bilinear, (2, 2): 0.75^2.
  struct Probe {
    BloomFilter filter;
    uint32_t x, y;
    double expected;
  };
  const Probe probes[] = {
      {BloomFilter::cod13, 2, 2, 0.4375 * 0.4375},
      {BloomFilter::cod13, 3, 3, 0.4375 * 0.4375},
      {BloomFilter::cod13, 2, 3, 0.4375 * 0.4375},
      {BloomFilter::cod13, 0, 0, 0.1875 * 0.1875},
      {BloomFilter::cod13, 5, 5, 0.1875 * 0.1875},
      {BloomFilter::cod13, 0, 2, 0.1875 * 0.4375},
      {BloomFilter::dual, 2, 2, 2.375 / 12.0},
      {BloomFilter::dual, 3, 3, 2.375 / 12.0},
      {BloomFilter::dual, 0, 0, 0.125 / 12.0},
      {BloomFilter::gauss9, 2, 2, 0.5625},
      {BloomFilter::gauss9, 0, 0, 0.0},
      {BloomFilter::gauss9, 2, 3, 0.75 * 0.75},
  };
  const double colour[3] = {1.0, 2.0, 0.5};
  for (const Probe& p : probes) {
    const auto diff = upsample_impulse_response(p.filter, 1.0);
    for (size_t k = 0; k < 3; ++k)
      EXPECT_NEAR(diff[(size_t(p.y) * 6 + p.x) * 4 + k], p.expected * colour[k], 1e-12)
          << bloom_filter_name(p.filter) << " (" << p.x << ", " << p.y << ")";
  }
}

TEST(BloomReferenceUpsample, RadiusScalesTheTapOffsets) {
  // With radius 2 the cod13 tent at x = 2 (p = 0.75) has taps at -1.25, 0.75, 2.75:
  // 0.5 * 0.75 = 0.375 per axis.
  const auto diff = upsample_impulse_response(BloomFilter::cod13, 2.0);
  EXPECT_NEAR(diff[(2 * 6 + 2) * 4 + 0], 0.375 * 0.375, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Full bloom: properties

TEST(BloomReferenceBloom, UniformImageStaysUniform) {
  // Every filter's weights sum to 1, so a uniform colour c gains exactly intensity * prefilter(c)
  // (docs/BLOOM.md "Composite"), whatever the size, edges and iteration clamp.
  std::mt19937 rng(61);
  std::uniform_real_distribution<float> u(1.5f, 20.0f);
  struct Size {
    uint32_t w, h;
  };
  for (BloomFilter filter : kFilters) {
    for (const Size s : {Size{17, 9}, Size{3, 5}, Size{1, 1}, Size{1, 17}, Size{17, 1}, Size{64, 48}}) {
      for (FireflyGuard guard : kGuards) {
        BloomConfig config;
        config.filter = filter;
        config.firefly_guard = guard;
        config.radius = 1.5f;
        const float c[3] = {u(rng), u(rng), u(rng)};
        CpuImage in(s.w, s.h);
        std::uniform_real_distribution<float> alpha(0.0f, 1.0f);
        for (uint32_t y = 0; y < s.h; ++y)
          for (uint32_t x = 0; x < s.w; ++x) {
            set_rgb(in, x, y, c[0], c[1], c[2]);
            in.at(x, y)[3] = alpha(rng);
          }
        const auto pf = prefiltered(config, c[0], c[1], c[2]);
        const DoubleImage out = bloom(in, config);
        const DoubleImage half = bloom(in, config, true);
        for (uint32_t y = 0; y < s.h; ++y)
          for (uint32_t x = 0; x < s.w; ++x) {
            for (size_t k = 0; k < 3; ++k) {
              const double want = double(c[k]) + double(config.intensity) * pf[k];
              ASSERT_NEAR(out.at(x, y)[k], want, 1e-12 * want)
                  << bloom_filter_name(filter) << " " << s.w << "x" << s.h << " guard " << firefly_guard_name(guard)
                  << " at " << x << "," << y;
              // fp16 storage rounds each stored value the same way everywhere: still uniform.
              ASSERT_EQ(half.at(x, y)[k], half.at(0, 0)[k]);
              ASSERT_NEAR(half.at(x, y)[k], want, 2e-3 * want);
            }
            ASSERT_EQ(out.at(x, y)[3], double(in.at(x, y)[3]));
          }
      }
    }
  }
}

TEST(BloomReferenceBloom, HalfModeRoundsEveryStoredImage) {
  // 16x16 uniform colour, 5 iterations -> levels 8, 4, 2 (N = 3). Each level holds
  // q = half(prefilter(c)) (a uniform downsample or blur reproduces q, and half(q) = q); the
  // accumulation stores A1 = half(q + q) = 2q and A0 = half(q + 2q), which for most q is not 3q
  // (3q needs up to 13 significant bits). So out = c + intensity / 3 * half(3q) exactly.
  const auto h = [](double x) { return double(detail::round_to_half(static_cast<float>(x))); };
  std::mt19937 rng(62);
  std::uniform_real_distribution<float> u(1.5f, 20.0f);
  for (BloomFilter filter : kFilters) {
    BloomConfig config;
    config.filter = filter;
    const float c[3] = {u(rng), u(rng), u(rng)};
    CpuImage in(16, 16, 1.0f);
    for (uint32_t y = 0; y < 16; ++y)
      for (uint32_t x = 0; x < 16; ++x) set_rgb(in, x, y, c[0], c[1], c[2]);
    const auto levels = downsampled_levels(in, config, true);
    ASSERT_EQ(levels.size(), 3u);
    for (const DoubleImage& level : levels)
      for (size_t i = 0; i < level.rgba.size(); ++i) ASSERT_EQ(level.rgba[i], h(level.rgba[i])) << "not an fp16 value";
    const auto pf = prefiltered(config, c[0], c[1], c[2]);
    const DoubleImage out = bloom(in, config, true);
    bool accumulate_rounded = false;
    for (size_t k = 0; k < 3; ++k) {
      const double q = h(pf[k]);
      const double want = double(c[k]) + double(config.intensity) / 3.0 * h(3 * q);
      EXPECT_NEAR(out.at(5, 7)[k], want, 1e-12 * want) << bloom_filter_name(filter) << " channel " << k;
      accumulate_rounded |= h(3 * q) != 3 * q;
    }
    EXPECT_TRUE(accumulate_rounded) << "pick another input stream: the accumulation happened to be exact in fp16";
  }
}

TEST(BloomReferenceBloom, HalfModeStoresTheGauss9HorizontalPass) {
  // 4x4 input of four 2x2 blocks -> level 0 is 2x2 (the only level) holding the block values L,
  // which are fp16 values. On a 2-texel axis with clamp to edge the 9-tap blur is
  // (w0 + S) own + S other, S = w1 + w2 + w3 + w4. The horizontal result is stored (rounded)
  // before the vertical pass reads it: level = half(V(half(H(L)))).
  const auto h = [](double x) { return double(detail::round_to_half(static_cast<float>(x))); };
  const double w0 = 0.2270270270, S = 0.1945945946 + 0.1216216216 + 0.0540540541 + 0.0162162162;
  const float block[2][2][3] = {{{1.5f, 7.25f, 0.375f}, {3.0f, 0.8125f, 9.5f}},
                                {{12.5f, 2.125f, 5.0f}, {0.625f, 6.75f, 1.25f}}};  // [by][bx][channel]
  CpuImage in(4, 4);
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) {
      const float* b = block[y / 2][x / 2];
      set_rgb(in, x, y, b[0], b[1], b[2]);
    }
  const BloomConfig config = identity_prefilter_config(BloomFilter::gauss9);
  const auto levels = downsampled_levels(in, config, true);
  ASSERT_EQ(levels.size(), 1u);
  bool rounding_visible = false;
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 2; ++x)
      for (size_t k = 0; k < 3; ++k) {
        const auto H = [&](uint32_t hx, uint32_t hy) { return (w0 + S) * block[hy][hx][k] + S * block[hy][1 - hx][k]; };
        const double want = h((w0 + S) * h(H(x, y)) + S * h(H(x, 1 - y)));
        const double unrounded_h = h((w0 + S) * H(x, y) + S * H(x, 1 - y));
        EXPECT_EQ(levels[0].at(x, y)[k], want) << x << "," << y << " channel " << k;
        rounding_visible |= want != unrounded_h;
      }
  EXPECT_TRUE(rounding_visible) << "choose other block values: the horizontal rounding changed nothing";
}

TEST(BloomReferenceBloom, BrighterPointAddsMoreEnergy) {
  const CpuImage bg = dark_background(48, 40, 71);
  for (BloomFilter filter : kFilters) {
    for (FireflyGuard guard : kGuards) {
      BloomConfig config;
      config.filter = filter;
      config.firefly_guard = guard;
      double prev = -1.0;
      for (float b : {0.45f, 1.2f, 2.0f, 4.0f, 16.0f, 100.0f, 1000.0f}) {
        CpuImage in = bg;
        set_rgb(in, 20, 17, b, b, b);
        const double e = total(added_light(bloom(in, config), in));
        if (b < 0.5f) {
          EXPECT_EQ(e, 0.0) << bloom_filter_name(filter) << ": a point below threshold - knee must add nothing";
        } else {
          EXPECT_GT(e, prev) << bloom_filter_name(filter) << " guard " << firefly_guard_name(guard) << " brightness "
                             << b;
        }
        prev = e;
      }
    }
  }
}

TEST(BloomReferenceBloom, FireflyGuardDampensAnIsolatedFirefly) {
  const CpuImage bg = dark_background(64, 64, 72);
  for (BloomFilter filter : kFilters) {
    CpuImage in = bg;
    set_rgb(in, 30, 33, 1000, 1000, 1000);
    BloomConfig config;
    config.filter = filter;
    config.firefly_guard = FireflyGuard::off;
    const double off = total(added_light(bloom(in, config), in));
    config.firefly_guard = FireflyGuard::karis;
    const double on = total(added_light(bloom(in, config), in));
    EXPECT_GT(on, 0.0) << bloom_filter_name(filter);
    EXPECT_LT(on, 0.5 * off) << bloom_filter_name(filter);
    // The smoothed guard trades suppression for stability (docs/STABILITY.md): it still dampens.
    config.firefly_guard = FireflyGuard::karis_smooth;
    const double smooth = total(added_light(bloom(in, config), in));
    EXPECT_GT(smooth, on) << bloom_filter_name(filter);
    EXPECT_LT(smooth, 0.9 * off) << bloom_filter_name(filter);
  }
}

TEST(BloomReferenceBloom, SingleCentredPointIsRadiallySymmetricCod13) {
  const CpuImage bg = dark_background(129, 129, 81);
  CpuImage in = bg;
  set_rgb(in, 64, 64, 50, 50, 50);
  BloomConfig config;  // cod13, 5 levels: 64, 32, 16, 8, 4
  const Glow g = glow_of(bloom(in, config), in);
  ASSERT_GT(g.energy, 0.0);
  // The mapping is mirror-symmetric about texel 64 on both axes.
  EXPECT_NEAR(g.cx, 64.0, 1e-6);
  EXPECT_NEAR(g.cy, 64.0, 1e-6);
  EXPECT_NEAR(g.mxx, g.myy, 0.02 * 0.5 * (g.mxx + g.myy));
  EXPECT_NEAR(g.mxy, 0.0, 1e-6 * g.mxx);
}

TEST(BloomReferenceBloom, OffCentrePointIsStillNearlyIsotropic) {
  // Off the symmetry axes x and y see different sub-texel phases at each level; the glow must
  // still be round to within a few percent for every filter.
  // (Positions chosen off the image's mirror axes: x and 159 - x would give equal moments trivially.)
  const CpuImage bg = dark_background(160, 160, 82);
  struct Point {
    uint32_t x, y;
  };
  for (BloomFilter filter : kFilters) {
    for (const Point p : {Point{70, 85}, Point{81, 66}, Point{64, 97}}) {
      CpuImage in = bg;
      set_rgb(in, p.x, p.y, 50, 50, 50);
      BloomConfig config;
      config.filter = filter;
      config.iterations = 4;
      const Glow g = glow_of(bloom(in, config), in);
      EXPECT_NEAR(g.mxx, g.myy, 0.05 * 0.5 * (g.mxx + g.myy))
          << bloom_filter_name(filter) << " at " << p.x << "," << p.y;
      EXPECT_NEAR(g.cx, p.x, 1.5) << bloom_filter_name(filter);
      EXPECT_NEAR(g.cy, p.y, 1.5) << bloom_filter_name(filter);
    }
  }
}

TEST(BloomReferenceBloom, LargerRadiusGivesWiderGlow) {
  const CpuImage bg = dark_background(257, 257, 91);
  for (BloomFilter filter : kFilters) {
    CpuImage in = bg;
    set_rgb(in, 128, 128, 50, 50, 50);
    double prev = 0.0;
    for (float radius : {0.5f, 1.0f, 2.0f, 4.0f}) {
      BloomConfig config;
      config.filter = filter;
      config.radius = radius;
      config.iterations = 4;
      const Glow g = glow_of(bloom(in, config), in);
      const double spread = g.mxx + g.myy;
      EXPECT_GT(spread, prev * 1.05) << bloom_filter_name(filter) << " radius " << radius;
      prev = spread;
    }
  }
}

TEST(BloomReferenceBloom, ZeroIntensityReturnsInputExactly) {
  CpuImage in = random_hdr(37, 23, 101);
  in.at(3, 4)[0] = std::numeric_limits<float>::quiet_NaN();
  in.at(5, 6)[1] = std::numeric_limits<float>::infinity();
  in.at(7, 8)[2] = -2.5f;
  for (BloomFilter filter : kFilters) {
    for (bool half : {false, true}) {
      BloomConfig config;
      config.filter = filter;
      config.intensity = 0.0f;
      const DoubleImage out = bloom(in, config, half);
      ASSERT_EQ(out.width, in.width);
      ASSERT_EQ(out.height, in.height);
      ASSERT_EQ(out.rgba.size(), in.rgba.size());
      for (size_t i = 0; i < in.rgba.size(); ++i)
        ASSERT_TRUE(same_bits(out.rgba[i], double(in.rgba[i]))) << "value " << i;
    }
  }
}

TEST(BloomReferenceBloom, DarkPixelsFarFromBrightOnesAreUnchanged) {
  // Bloom has a finite footprint (at most a few taps per level, 3 levels here): pixels far from
  // the bright spot, whose own luma is below threshold - knee, must come out bit-identical.
  const CpuImage bg = dark_background(256, 256, 111);
  for (BloomFilter filter : kFilters) {
    for (bool half : {false, true}) {
      CpuImage in = bg;
      for (uint32_t y = 12; y < 15; ++y)
        for (uint32_t x = 12; x < 15; ++x) set_rgb(in, x, y, 20, 30, 10);
      BloomConfig config;
      config.filter = filter;
      config.iterations = 3;
      const DoubleImage out = bloom(in, config, half);
      size_t unchanged_far = 0;
      for (uint32_t y = 0; y < 256; ++y)
        for (uint32_t x = 0; x < 256; ++x) {
          if (x < 128 && y < 128) continue;
          for (size_t k = 0; k < 4; ++k)
            ASSERT_TRUE(same_bits(out.at(x, y)[k], double(in.at(x, y)[k])))
                << bloom_filter_name(filter) << " changed far pixel " << x << "," << y;
          ++unchanged_far;
        }
      EXPECT_EQ(unchanged_far, 256u * 256u - 128u * 128u);
      // ...while dark pixels near the spot did receive light, so the check above is not vacuous.
      EXPECT_GT(out.at(20, 20)[1], double(in.at(20, 20)[1])) << bloom_filter_name(filter);
    }
  }
}

TEST(BloomReferenceBloom, TinyAndThinImages) {
  struct Size {
    uint32_t w, h;
  };
  for (BloomFilter filter : kFilters) {
    for (const Size s : {Size{1, 1}, Size{3, 5}, Size{1, 57}, Size{57, 1}, Size{2, 2}, Size{2, 3}}) {
      const CpuImage in = random_hdr(s.w, s.h, 121);
      BloomConfig config;
      config.filter = filter;
      const DoubleImage out = bloom(in, config);
      ASSERT_EQ(out.width, s.w);
      ASSERT_EQ(out.height, s.h);
      double added = 0.0;
      for (size_t i = 0; i < in.rgba.size(); ++i) {
        ASSERT_TRUE(std::isfinite(out.rgba[i]));
        if (i % 4 == 3) {
          ASSERT_EQ(out.rgba[i], double(in.rgba[i]));
        } else {
          ASSERT_GE(out.rgba[i], double(in.rgba[i]));  // bloom only adds light
          added += out.rgba[i] - double(in.rgba[i]);
        }
      }
      EXPECT_GT(added, 0.0) << bloom_filter_name(filter) << " " << s.w << "x" << s.h;
    }
  }
}

TEST(BloomReferenceBloom, HalfIntermediatesStayCloseToDouble) {
  const CpuImage in = random_hdr(96, 64, 131);
  for (BloomFilter filter : kFilters) {
    BloomConfig config;
    config.filter = filter;
    const DoubleImage exact = bloom(in, config, false);
    const DoubleImage half = bloom(in, config, true);
    const double full = relative_l2(to_float(half), exact);
    EXPECT_LT(full, 5e-3) << bloom_filter_name(filter);
    // The scene dominates the output; compare the added light alone as well.
    DoubleImage added_exact = exact;
    DoubleImage added_half = half;
    for (size_t i = 0; i < in.rgba.size(); ++i) {
      added_exact.rgba[i] -= double(in.rgba[i]);
      added_half.rgba[i] -= double(in.rgba[i]);
    }
    const double bloom_only = relative_l2(to_float(added_half), added_exact);
    EXPECT_LT(bloom_only, 5e-3) << bloom_filter_name(filter);
    // fp16 storage really was applied (a mode that changed nothing would pass the bounds above).
    EXPECT_GT(bloom_only, 1e-6) << bloom_filter_name(filter);
  }
}

TEST(BloomReferenceBloom, RejectsInvalidInput) {
  BloomConfig config;
  EXPECT_THROW(bloom(CpuImage(), config), std::invalid_argument);
  CpuImage bad(4, 4);
  bad.rgba.pop_back();
  EXPECT_THROW(bloom(bad, config), std::invalid_argument);
  config.iterations = 0;
  EXPECT_THROW(bloom(CpuImage(4, 4), config), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// relative_l2

TEST(BloomReferenceRelativeL2, HandComputed) {
  DoubleImage ref;
  ref.width = 2;
  ref.height = 1;
  ref.rgba = {3, 4, 0, 1, 0, 0, 0, 1};
  CpuImage gpu(2, 1);
  gpu.rgba = {3, 4, 1, 0.25f, 0, 0, 0, 7};       // alpha differs and must not count
  EXPECT_DOUBLE_EQ(relative_l2(gpu, ref), 0.2);  // |(0,0,1)| / |(3,4,0)|
  gpu.rgba = {3, 4, 0, 9, 0, 0, 0, 9};
  EXPECT_EQ(relative_l2(gpu, ref), 0.0);
  gpu.rgba[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(relative_l2(gpu, ref) < 1.0);  // a NaN never passes a tolerance
  EXPECT_THROW(relative_l2(CpuImage(1, 2), ref), std::invalid_argument);
}

}  // namespace
}  // namespace glint::reference
