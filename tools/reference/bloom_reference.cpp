// Float64 reference of docs/BLOOM.md. Every stage is one function below, in the order of the doc;
// each cites the section it implements. Positions, weights and sums are computed in double, so the
// only deviation from exact arithmetic is double rounding; the optional fp16 mode adds exactly the
// roundings the GPU's RGBA16F storage makes, which lets tests separate storage error from kernel
// bugs.
#include "reference/bloom_reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/half.h"

namespace glint::reference {
namespace {

// ---------------------------------------------------------------------------------------------
// Notation (docs/BLOOM.md "Notation")

DoubleImage make_level(uint32_t width, uint32_t height) {
  DoubleImage img;
  img.width = width;
  img.height = height;
  img.rgba.assign(size_t(width) * height * 4, 0.0);
  // The GPU stores vec4(c, 1.0) in every intermediate image; keep the same alpha.
  for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 1.0;
  return img;
}

// fetch(img, i, j): clamp-to-edge ("fetch ... clamps i to [0, w-1] and j to [0, h-1]").
const double* fetch(const DoubleImage& img, int64_t i, int64_t j) {
  i = std::clamp<int64_t>(i, 0, int64_t(img.width) - 1);
  j = std::clamp<int64_t>(j, 0, int64_t(img.height) - 1);
  return img.at(uint32_t(i), uint32_t(j));
}

// bilinear(img, p): i0 = floor(px), fx = px - i0 (same for y), four clamped fetches weighted
// (1-fx)(1-fy), fx(1-fy), (1-fx)fy, fx fy. All-zero neighbourhoods give exactly 0, which the
// "unchanged far from bright pixels" property relies on.
void bilinear(const DoubleImage& img, double px, double py, double out[3]) {
  const double x0 = std::floor(px);
  const double y0 = std::floor(py);
  const double fx = px - x0;
  const double fy = py - y0;
  const auto i0 = int64_t(x0);
  const auto j0 = int64_t(y0);
  const double* a = fetch(img, i0, j0);
  const double* b = fetch(img, i0 + 1, j0);
  const double* c = fetch(img, i0, j0 + 1);
  const double* d = fetch(img, i0 + 1, j0 + 1);
  const double wa = (1 - fx) * (1 - fy), wb = fx * (1 - fy), wc = (1 - fx) * fy, wd = fx * fy;
  for (int k = 0; k < 3; ++k) out[k] = wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k];
}

// Mapping from destination texel x (of dst texels) to the source position with the same
// normalized UV: p = (x + 0.5) * ws / wd - 0.5.
double map_coord(uint32_t x, uint32_t dst, uint32_t src) { return (x + 0.5) * double(src) / double(dst) - 0.5; }

// The dual filter's map (docs/BLOOM.md "Notation"): between n and floor(n / 2) texels the exact
// ratio 2 (or 1/2), the grids aligned at texel 0; any other pair of sizes (level0_height's first
// step) the same-UV map.
double dual_map(uint32_t x, uint32_t dst, uint32_t src) {
  if (src > 1 && dst == src / 2) return 2.0 * x + 0.5;
  if (dst > 1 && src == dst / 2) return (x + 0.5) * 0.5 - 0.5;
  return map_coord(x, dst, src);
}

double level_map(BloomFilter filter, uint32_t x, uint32_t dst, uint32_t src) {
  return filter == BloomFilter::dual ? dual_map(x, dst, src) : map_coord(x, dst, src);
}

double luma3(const double c[3]) { return luma(c[0], c[1], c[2]); }

// The RGBA16F store: round each colour channel to fp16 (the GPU computes in fp32 and then stores,
// hence the cast to float first). Alpha is always 1, which fp16 holds exactly.
void store_half(DoubleImage& img) {
  for (size_t i = 0; i < img.rgba.size(); i += 4)
    for (size_t k = 0; k < 3; ++k) img.rgba[i + k] = detail::round_to_half(static_cast<float>(img.rgba[i + k]));
}

void validate(const CpuImage& input, const BloomConfig& config) {
  if (input.width == 0 || input.height == 0) throw std::invalid_argument("bloom reference: empty input image");
  if (input.rgba.size() != size_t(input.width) * input.height * 4)
    throw std::invalid_argument("bloom reference: input pixel buffer has " + std::to_string(input.rgba.size()) +
                                " floats, expected width * height * 4");
  if (config.iterations == 0) throw std::invalid_argument("bloom reference: iterations must be at least 1");
  switch (config.filter) {
    case BloomFilter::cod13:
    case BloomFilter::dual:
    case BloomFilter::gauss9:
      break;
    default:
      throw std::invalid_argument("bloom reference: unknown filter");
  }
}

// ---------------------------------------------------------------------------------------------
// Mip chain (docs/BLOOM.md "Mip chain"). An own copy on purpose: the reference must not share
// code with the driver it checks (bloom_mip_chain in src/bloom/bloom.cpp).

// level0_height > 0: "halve (floor) while half the height is still above the target; then one
// step to the target height H0 = min(level0_height, input height), width round(W * H0 / H) kept
// within [max(1, w/2), w] of the image before it". Returns those pre-levels; *level0 gets level 0.
std::vector<LevelSize> pre_level_sizes(uint32_t width, uint32_t height, uint32_t level0_height, LevelSize* level0) {
  std::vector<LevelSize> pre;
  if (level0_height == 0) {
    *level0 = {std::max(1u, width / 2), std::max(1u, height / 2)};
    return pre;
  }
  const uint32_t target = std::min(level0_height, height);
  uint32_t w = width, h = height;
  while (h / 2 > target) {
    w = std::max(1u, w / 2);
    h /= 2;
    pre.push_back({w, h});
  }
  const double aspect_width = std::round(double(width) * target / double(height));
  const double lo = std::max(1u, w / 2), hi = w;
  *level0 = {static_cast<uint32_t>(std::clamp(aspect_width, lo, hi)), target};
  return pre;
}

std::vector<LevelSize> level_sizes(uint32_t width, uint32_t height, uint32_t iterations, uint32_t level0_height) {
  std::vector<LevelSize> chain;
  LevelSize level0;
  pre_level_sizes(width, height, level0_height, &level0);
  uint32_t w = 0, h = 0;
  for (uint32_t k = 0; k < iterations; ++k) {
    // Level 0 as above; level k is max(1, w(k-1)/2) x max(1, h(k-1)/2), integer floor division.
    w = k == 0 ? level0.width : std::max(1u, w / 2);
    h = k == 0 ? level0.height : std::max(1u, h / 2);
    // N is reduced so that every level is at least 2 on each side, but level 0 always exists
    // (a 3x5 input gets one 1x2 level). Sizes never grow, so the first small level ends the chain.
    const bool big_enough = w >= 2 && h >= 2;
    if (k == 0 || big_enough) chain.push_back({w, h});
    if (!big_enough) break;
  }
  return chain;
}

// ---------------------------------------------------------------------------------------------
// Prefilter (docs/BLOOM.md "Prefilter"), applied to every full-resolution texel once: the GPU
// recomputes it per fetch inside the first downsample, which gives the same values.

DoubleImage prefiltered_image(const CpuImage& input, const BloomConfig& config) {
  DoubleImage p = make_level(input.width, input.height);
  for (uint32_t y = 0; y < input.height; ++y) {
    for (uint32_t x = 0; x < input.width; ++x) {
      const float* src = input.at(x, y);
      const double c[3] = {src[0], src[1], src[2]};
      prefilter(config, c, p.at(x, y));
    }
  }
  return p;
}

// ---------------------------------------------------------------------------------------------
// Downsample (docs/BLOOM.md "Downsample" and "Karis guard").

// Accumulates the weighted "boxes" of one destination texel. With the Karis guard a box of mean
// m and weight w counts with w / (1 + luma(m)); the result is sum(w' m) / sum(w'), so without the
// guard it is the plain normalized weighted mean.
class BoxAverage {
 public:
  explicit BoxAverage(bool karis) : karis_(karis) {}
  void add(const double mean[3], double weight) {
    const double w = karis_ ? weight / (1.0 + luma3(mean)) : weight;
    for (int k = 0; k < 3; ++k) sum_[k] += w * mean[k];
    weight_sum_ += w;
  }
  void result(double out[3]) const {
    for (int k = 0; k < 3; ++k) out[k] = sum_[k] / weight_sum_;
  }

 private:
  bool karis_;
  std::array<double, 3> sum_{};
  double weight_sum_ = 0.0;
};

// cod13 (Jimenez 2014): 9 taps at p + {-2,0,2}^2, 4 taps at p + {-1,1}^2. The centre box (the
// four inner taps) weighs 0.5; the four 2x2 groups of the outer grid that share the centre tap
// weigh 0.125 each.
void down_cod13(const DoubleImage& src, double px, double py, bool karis, double out[3]) {
  double g[3][3][3];  // g[row b][column a] at offset (2a - 2, 2b - 2)
  for (int b = 0; b < 3; ++b)
    for (int a = 0; a < 3; ++a) bilinear(src, px + 2 * a - 2, py + 2 * b - 2, g[b][a]);
  double inner[4][3];
  bilinear(src, px - 1, py - 1, inner[0]);
  bilinear(src, px + 1, py - 1, inner[1]);
  bilinear(src, px - 1, py + 1, inner[2]);
  bilinear(src, px + 1, py + 1, inner[3]);

  BoxAverage avg(karis);
  double m[3];
  for (int k = 0; k < 3; ++k) m[k] = 0.25 * (inner[0][k] + inner[1][k] + inner[2][k] + inner[3][k]);
  avg.add(m, 0.5);
  // Corner boxes: top-left, top-right, bottom-left, bottom-right 2x2 groups; each contains g[1][1].
  for (int by = 0; by < 2; ++by) {
    for (int bx = 0; bx < 2; ++bx) {
      for (int k = 0; k < 3; ++k)
        m[k] = 0.25 * (g[by][bx][k] + g[by][bx + 1][k] + g[by + 1][bx][k] + g[by + 1][bx + 1][k]);
      avg.add(m, 0.125);
    }
  }
  avg.result(out);
}

// dual (Bjørge 2015): (4 bilinear(p) + sum of bilinear(p + (+-1, +-1))) / 8, as five boxes: the
// centre with weight 0.5 and each diagonal tap with 0.125 (which matters only for Karis).
void down_dual(const DoubleImage& src, double px, double py, bool karis, double out[3]) {
  BoxAverage avg(karis);
  double m[3];
  bilinear(src, px, py, m);
  avg.add(m, 0.5);
  static constexpr double kDiag[4][2] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
  for (const auto& o : kDiag) {
    bilinear(src, px + o[0], py + o[1], m);
    avg.add(m, 0.125);
  }
  avg.result(out);
}

// The source texels along one axis that overlap destination texel x, with the overlap lengths:
// texel x covers [x * ws/wd, (x+1) * ws/wd) in texel-edge coordinates. For the mip chain the
// ratio ws/wd is at most 3 (3 -> 1), so at most 4 texels overlap.
struct AxisTaps {
  std::array<int64_t, 4> index{};
  std::array<double, 4> weight{};
  int count = 0;
};

AxisTaps area_taps(uint32_t x, uint32_t dst, uint32_t src) {
  // x * ws is an exact integer in double, so lo and hi are correctly rounded and hi of the last
  // texel is exactly ws (no sliver of a texel past the edge).
  const double lo = double(x) * src / dst;
  const double hi = double(x + 1) * src / dst;
  AxisTaps taps;
  const auto first = int64_t(std::floor(lo));
  const auto last = int64_t(std::ceil(hi)) - 1;
  for (int64_t i = first; i <= last; ++i) {
    if (taps.count == int(taps.index.size())) throw std::logic_error("bloom reference: area downsample ratio above 3");
    const double overlap = std::min(double(i + 1), hi) - std::max(double(i), lo);
    if (overlap <= 0.0) continue;
    taps.index[size_t(taps.count)] = i;
    taps.weight[size_t(taps.count)] = overlap;
    ++taps.count;
  }
  return taps;
}

// gauss9 area (box) average: every source texel weighted by the product of its x and y overlaps,
// divided by the total. Each texel is one Karis "box".
void down_area(const DoubleImage& src, const AxisTaps& tx, const AxisTaps& ty, bool karis, double out[3]) {
  BoxAverage avg(karis);
  for (int j = 0; j < ty.count; ++j)
    for (int i = 0; i < tx.count; ++i)
      avg.add(fetch(src, tx.index[size_t(i)], ty.index[size_t(j)]), tx.weight[size_t(i)] * ty.weight[size_t(j)]);
  avg.result(out);
}

DoubleImage downsample(const DoubleImage& src, LevelSize size, BloomFilter filter, bool karis) {
  DoubleImage dst = make_level(size.width, size.height);
  if (filter == BloomFilter::gauss9) {
    std::vector<AxisTaps> columns(size.width);
    for (uint32_t x = 0; x < size.width; ++x) columns[x] = area_taps(x, size.width, src.width);
    for (uint32_t y = 0; y < size.height; ++y) {
      const AxisTaps rows = area_taps(y, size.height, src.height);
      for (uint32_t x = 0; x < size.width; ++x) down_area(src, columns[x], rows, karis, dst.at(x, y));
    }
    return dst;
  }
  for (uint32_t y = 0; y < size.height; ++y) {
    const double py = level_map(filter, y, size.height, src.height);
    for (uint32_t x = 0; x < size.width; ++x) {
      const double px = level_map(filter, x, size.width, src.width);
      if (filter == BloomFilter::cod13)
        down_cod13(src, px, py, karis, dst.at(x, y));
      else
        down_dual(src, px, py, karis, dst.at(x, y));
    }
  }
  return dst;
}

// One direction of the separable 9-tap Gaussian (docs/BLOOM.md, gauss9: binomial row 12 without
// its two outer taps a side, renormalised): tap t at offset
// t * radius texels, read by 1-D linear interpolation with clamp to edge. The weights sum to 1.
constexpr std::array<double, 5> kGauss9 = {0.2270270270, 0.1945945946, 0.1216216216, 0.0540540541, 0.0162162162};

DoubleImage gauss9_blur_pass(const DoubleImage& src, double radius, bool vertical) {
  DoubleImage dst = make_level(src.width, src.height);
  // Linear interpolation along the blur axis at continuous texel-centre coordinate q.
  auto linear_along = [&](uint32_t x, uint32_t y, double q, double out[3]) {
    const double f = std::floor(q);
    const double w = q - f;
    const auto i = int64_t(f);
    const double* a = vertical ? fetch(src, x, i) : fetch(src, i, y);
    const double* b = vertical ? fetch(src, x, i + 1) : fetch(src, i + 1, y);
    for (int k = 0; k < 3; ++k) out[k] = (1 - w) * a[k] + w * b[k];
  };
  for (uint32_t y = 0; y < src.height; ++y) {
    for (uint32_t x = 0; x < src.width; ++x) {
      const double centre = vertical ? y : x;
      double* out = dst.at(x, y);
      const double* c = src.at(x, y);
      for (int k = 0; k < 3; ++k) out[k] = kGauss9[0] * c[k];
      for (size_t t = 1; t < kGauss9.size(); ++t) {
        const double offset = double(t) * radius;
        double plus[3], minus[3];
        linear_along(x, y, centre + offset, plus);
        linear_along(x, y, centre - offset, minus);
        for (int k = 0; k < 3; ++k) out[k] += kGauss9[t] * (plus[k] + minus[k]);
      }
    }
  }
  return dst;
}

// ---------------------------------------------------------------------------------------------
// Upsample (docs/BLOOM.md "Upsample and accumulate"): the filter's Up at mapped position p of
// `small`. Every filter's weights sum to 1, so a uniform level stays uniform.

void upsample_at(const DoubleImage& small, double px, double py, BloomFilter filter, double radius, double out[3]) {
  double s[3];
  switch (filter) {
    case BloomFilter::gauss9:
      // The width comes from the per-level Gaussian; Up is a plain bilinear.
      bilinear(small, px, py, out);
      return;
    case BloomFilter::dual: {
      // (sum of the 4 edge taps at radius (+-1,0),(0,+-1) + 2 * sum of the 4 diagonal taps at
      // radius (+-0.5,+-0.5)) / 12.
      static constexpr double kEdges[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
      static constexpr double kDiagonals[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {-0.5, 0.5}, {0.5, 0.5}};
      double acc[3] = {0, 0, 0};
      for (const auto& o : kEdges) {
        bilinear(small, px + radius * o[0], py + radius * o[1], s);
        for (int k = 0; k < 3; ++k) acc[k] += s[k];
      }
      for (const auto& o : kDiagonals) {
        bilinear(small, px + radius * o[0], py + radius * o[1], s);
        for (int k = 0; k < 3; ++k) acc[k] += 2.0 * s[k];
      }
      for (int k = 0; k < 3; ++k) out[k] = acc[k] / 12.0;
      return;
    }
    case BloomFilter::cod13:
    default: {
      // 3x3 tent: sum over a, b in {-1,0,1} of t(a) t(b) bilinear(p + radius (a, b)), t = (1,2,1)/4.
      static constexpr double kTent[3] = {0.25, 0.5, 0.25};
      double acc[3] = {0, 0, 0};
      for (int b = 0; b < 3; ++b) {
        for (int a = 0; a < 3; ++a) {
          bilinear(small, px + radius * (a - 1), py + radius * (b - 1), s);
          const double w = kTent[a] * kTent[b];
          for (int k = 0; k < 3; ++k) acc[k] += w * s[k];
        }
      }
      for (int k = 0; k < 3; ++k) out[k] = acc[k];
      return;
    }
  }
}

// docs/BLOOM.md "Karis guard", karis_smooth: P filtered by the 11-tap binomial C(10, k) / 1024
// horizontally, then vertically, reading clamp-to-edge (the GPU keeps it in shared memory, never
// stored, so it is never rounded).
DoubleImage binomial_smoothed(const DoubleImage& p) {
  constexpr int kRadius = 5;
  double weight[2 * kRadius + 1];
  for (int m = 0; m <= 2 * kRadius; ++m) {
    double c = 1.0;  // C(10, m)
    for (int i = 1; i <= m; ++i) c = c * (2 * kRadius - i + 1) / i;
    weight[m] = c / 1024.0;
  }
  DoubleImage rows = make_level(p.width, p.height), out = make_level(p.width, p.height);
  for (uint32_t y = 0; y < p.height; ++y)
    for (uint32_t x = 0; x < p.width; ++x)
      for (int m = -kRadius; m <= kRadius; ++m) {
        const double* s = fetch(p, int64_t(x) + m, y);
        for (int k = 0; k < 3; ++k) rows.at(x, y)[k] += weight[m + kRadius] * s[k];
      }
  for (uint32_t y = 0; y < p.height; ++y)
    for (uint32_t x = 0; x < p.width; ++x)
      for (int m = -kRadius; m <= kRadius; ++m) {
        const double* s = fetch(rows, x, int64_t(y) + m);
        for (int k = 0; k < 3; ++k) out.at(x, y)[k] += weight[m + kRadius] * s[k];
      }
  return out;
}

}  // namespace

// -------------------------------------------------------------------------------------------------
// Public stages

// Rec. 709 luma (docs/BLOOM.md "Notation").
double luma(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

// docs/BLOOM.md "Prefilter".
void prefilter(const BloomConfig& config, const double in_rgb[3], double out_rgb[3]) {
  // 1. Sanitize: NaN and negatives become 0, then clamp to 65504 (+Inf and 1e9 included).
  //    max_brightness clamps level 0 instead (downsampled_levels).
  constexpr double kSourceMax = 65504.0;
  double c[3];
  for (int k = 0; k < 3; ++k) {
    const double v = in_rgb[k];
    c[k] = (std::isnan(v) || v < 0.0) ? 0.0 : std::min(v, kSourceMax);
  }
  // 2. Soft threshold: knee = threshold * soft_knee; soft = clamp(l - t + knee, 0, 2 knee);
  //    contribution = soft^2 / (4 knee + 1e-4); factor = max(l - t, contribution) / max(l, 1e-4).
  //    l <= t - knee makes soft and contribution 0 and l - t <= 0, so the factor is exactly 0.
  const double threshold = config.threshold;
  const double knee = threshold * double(config.soft_knee);
  const double l = luma3(c);
  const double soft = std::clamp(l - threshold + knee, 0.0, 2.0 * knee);
  const double contribution = soft * soft / (4.0 * knee + 1e-4);
  const double factor = std::max(l - threshold, contribution) / std::max(l, 1e-4);
  for (int k = 0; k < 3; ++k) out_rgb[k] = c[k] * factor;
}

// docs/BLOOM.md "Mip chain" and "Downsample": level 0 = Down(P) (Karis per firefly_guard),
// level k = Down(level k-1); for gauss9 each level is then blurred horizontally, stored, blurred
// vertically, stored, and that blurred level is what the next downsample reads.
std::vector<DoubleImage> downsampled_levels(const CpuImage& input, const BloomConfig& config, bool round_half) {
  validate(input, config);
  const std::vector<LevelSize> chain = level_sizes(input.width, input.height, config.iterations, config.level0_height);
  LevelSize level0_size;
  const std::vector<LevelSize> pre = pre_level_sizes(input.width, input.height, config.level0_height, &level0_size);
  if (level0_size.width != chain[0].width || level0_size.height != chain[0].height)
    throw std::logic_error("bloom reference: level 0 size mismatch");
  const double radius = config.radius;

  std::vector<DoubleImage> levels;
  levels.reserve(chain.size());
  {
    // Level 0 reads the prefiltered full-resolution image P, which is not stored on the GPU
    // (the prefilter is fused into the first downsample), so it is never rounded.
    // The first step goes to the first pre-level (level0_height) or to level 0.
    const DoubleImage p = prefiltered_image(input, config);
    const LevelSize first = pre.empty() ? chain[0] : pre[0];
    DoubleImage step = config.firefly_guard == FireflyGuard::karis_smooth
                           ? downsample(binomial_smoothed(p), first, config.filter, true)
                           : downsample(p, first, config.filter, config.firefly_guard == FireflyGuard::karis);
    // Its result is clamped per channel to max_brightness before it is stored.
    for (size_t i = 0; i < step.rgba.size(); i += 4)
      for (size_t k = 0; k < 3; ++k) step.rgba[i + k] = std::min(step.rgba[i + k], double(config.max_brightness));
    // Pre-levels: plain downsamples (no guard, no gauss9 blur), each stored.
    for (size_t k = 0; k < pre.size(); ++k) {
      if (round_half) store_half(step);
      step = downsample(step, k + 1 < pre.size() ? pre[k + 1] : chain[0], config.filter, false);
    }
    levels.push_back(std::move(step));
  }
  for (size_t k = 0; k < chain.size(); ++k) {
    if (k > 0) levels.push_back(downsample(levels[k - 1], chain[k], config.filter, false));
    DoubleImage& level = levels[k];
    if (round_half) store_half(level);
    if (config.filter == BloomFilter::gauss9) {
      level = gauss9_blur_pass(level, radius, /*vertical=*/false);
      if (round_half) store_half(level);  // the horizontal pass is stored before the vertical reads it
      level = gauss9_blur_pass(level, radius, /*vertical=*/true);
      if (round_half) store_half(level);
    }
  }
  return levels;
}

DoubleImage upsample(const DoubleImage& small, uint32_t width, uint32_t height, BloomFilter filter, double radius) {
  DoubleImage dst = make_level(width, height);
  for (uint32_t y = 0; y < height; ++y) {
    const double py = level_map(filter, y, height, small.height);
    for (uint32_t x = 0; x < width; ++x)
      upsample_at(small, level_map(filter, x, width, small.width), py, filter, radius, dst.at(x, y));
  }
  return dst;
}

// docs/BLOOM.md "Upsample and accumulate" and "Composite".
constexpr double kFloatMax = std::numeric_limits<float>::max();

DoubleImage bloom(const CpuImage& input, const BloomConfig& config, bool round_intermediates_to_half) {
  validate(input, config);
  DoubleImage out;
  out.width = input.width;
  out.height = input.height;
  out.rgba.assign(input.rgba.begin(), input.rgba.end());
  // "With intensity == 0 no bloom kernel runs: the output is a copy of the input."
  if (config.intensity == 0.0f) return out;

  std::vector<DoubleImage> levels = downsampled_levels(input, config, round_intermediates_to_half);
  const size_t n = levels.size();
  const double radius = config.radius;

  // A(N-1) = level N-1; A(k) = level k + Up(A(k+1)), accumulated in place in level k (as the
  // GPU's bloom_up does), then stored.
  for (size_t k = n - 1; k-- > 0;) {
    DoubleImage& level = levels[k];
    const DoubleImage& smaller = levels[k + 1];
    for (uint32_t y = 0; y < level.height; ++y) {
      const double py = level_map(config.filter, y, level.height, smaller.height);
      for (uint32_t x = 0; x < level.width; ++x) {
        double up[3];
        upsample_at(smaller, level_map(config.filter, x, level.width, smaller.width), py, config.filter, radius, up);
        double* own = level.at(x, y);
        for (int c = 0; c < 3; ++c) own[c] += up[c];
      }
    }
    if (round_intermediates_to_half) store_half(level);
  }

  // out = scene + (intensity / N) * Up(A(0)), RGB only; alpha stays the scene's. Fused with the
  // last upsample like bloom_composite.comp, so no full-resolution bloom image is held. A NaN scene
  // channel counts as 0 and the result is clamped to +-FLT_MAX (the RGBA32F output's rule; an
  // RGBA16F output clamps to +-65504, which the GPU does when it stores).
  for (double& v : out.rgba)
    if (std::isnan(v)) v = 0.0;
  const DoubleImage& a0 = levels[0];
  const double scale = double(config.intensity) / double(n);
  for (uint32_t y = 0; y < out.height; ++y) {
    const double py = level_map(config.filter, y, out.height, a0.height);
    for (uint32_t x = 0; x < out.width; ++x) {
      double up[3];
      upsample_at(a0, level_map(config.filter, x, out.width, a0.width), py, config.filter, radius, up);
      double* o = out.at(x, y);
      for (int c = 0; c < 3; ++c) o[c] += scale * up[c];
      for (int c = 0; c < 4; ++c) o[c] = std::clamp(o[c], -kFloatMax, kFloatMax);
    }
  }
  return out;
}

double relative_l2(const CpuImage& gpu, const DoubleImage& ref) {
  if (gpu.width != ref.width || gpu.height != ref.height || gpu.rgba.size() != ref.rgba.size())
    throw std::invalid_argument("relative_l2: image sizes differ (" + std::to_string(gpu.width) + "x" +
                                std::to_string(gpu.height) + " vs " + std::to_string(ref.width) + "x" +
                                std::to_string(ref.height) + ")");
  double diff2 = 0.0, ref2 = 0.0;
  for (size_t i = 0; i < ref.rgba.size(); i += 4) {
    for (size_t k = 0; k < 3; ++k) {
      const double d = double(gpu.rgba[i + k]) - ref.rgba[i + k];
      diff2 += d * d;
      ref2 += ref.rgba[i + k] * ref.rgba[i + k];
    }
  }
  if (ref2 == 0.0) return diff2 == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::sqrt(diff2 / ref2);
}

}  // namespace glint::reference
