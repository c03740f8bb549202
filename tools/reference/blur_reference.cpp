// Float64 reference of docs/BLUR.md. Every stage is one function below, citing the section it
// implements. Positions, weights and sums are in double; the optional fp16 mode adds exactly the
// roundings of the GPU's RGBA16F intermediates.
//
// The separable convolutions are written in scatter order (each source texel adds its weighted
// value to the outputs that read it, zero texels skipped) instead of the kernels' gather order.
// The sums are the same, term for term (only the order of the float64 additions differs); the
// scatter order makes impulse tests cost what the impulse response costs, not what the image
// costs, which keeps the CPU tests of sigma 64 fast. tests/reference_blur_test.cpp checks it
// against a plain gather loop.
#include "reference/blur_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/half.h"

namespace glint::reference {
namespace {

DoubleImage make_image(uint32_t width, uint32_t height) {
  DoubleImage img;
  img.width = width;
  img.height = height;
  img.rgba.assign(size_t(width) * height * 4, 0.0);
  return img;
}

void validate(const CpuImage& input) {
  if (input.width == 0 || input.height == 0) throw std::invalid_argument("blur reference: empty input image");
  if (input.rgba.size() != size_t(input.width) * input.height * 4)
    throw std::invalid_argument("blur reference: input pixel buffer has " + std::to_string(input.rgba.size()) +
                                " floats, expected width * height * 4");
}

// fetch(img, i, j) of docs/BLUR.md "Notation": clamp-to-edge.
const double* fetch(const DoubleImage& img, int64_t i, int64_t j) {
  i = std::clamp<int64_t>(i, 0, int64_t(img.width) - 1);
  j = std::clamp<int64_t>(j, 0, int64_t(img.height) - 1);
  return img.at(uint32_t(i), uint32_t(j));
}

// bilinear(img, p) of docs/BLUR.md "Notation", all four channels, added to out with weight w.
void add_bilinear(const DoubleImage& img, double px, double py, double w, double out[4]) {
  const double x0 = std::floor(px), y0 = std::floor(py);
  const double fx = px - x0, fy = py - y0;
  const auto i0 = int64_t(x0), j0 = int64_t(y0);
  const double* a = fetch(img, i0, j0);
  const double* b = fetch(img, i0 + 1, j0);
  const double* c = fetch(img, i0, j0 + 1);
  const double* d = fetch(img, i0 + 1, j0 + 1);
  const double wa = (1 - fx) * (1 - fy), wb = fx * (1 - fy), wc = (1 - fx) * fy, wd = fx * fy;
  for (int k = 0; k < 4; ++k) out[k] += w * (wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k]);
}

// map(x, wd, ws) = (x + 0.5) ws / wd - 0.5 (docs/BLUR.md "Notation").
double map_coord(uint32_t x, uint32_t wd, uint32_t ws) { return (x + 0.5) * double(ws) / double(wd) - 0.5; }

// The RGBA16F store of an intermediate: the GPU computes in fp32 and stores fp16.
void store_half(DoubleImage& img) {
  for (double& v : img.rgba) v = detail::round_to_half(static_cast<float>(v));
}

// One direction of the clamped convolution out(x) = sum_{|t| <= R} w_|t| in(clamp(x + t)) with
// symmetric half taps w[0..R] (docs/BLUR.md "Fused level blur"), in scatter order: source texel i
// of a line of n texels is read by output x through every t with clamp(x + t) = i, i.e.
//   0 < i < n-1: t = i - x (|i - x| <= R);
//   i = 0:       t in [-R, -x]        (x <= R), weight C(-x)         with C(t) = sum_{u <= t} w_|u|;
//   i = n-1:     t in [n-1-x, R]      (x >= n-1-R), weight 1 - C(n-2-x);
//   n = 1:       every t, weight C(R).
DoubleImage convolve_axis(const DoubleImage& src, const std::vector<double>& half, bool vertical) {
  const auto r = int64_t(half.size()) - 1;
  // prefix[t + R + 1] = sum of w_|u| for u = -R .. t; prefix[0] = 0.
  std::vector<double> prefix(size_t(2 * r + 2), 0.0);
  for (int64_t t = -r; t <= r; ++t) prefix[size_t(t + r + 1)] = prefix[size_t(t + r)] + half[size_t(std::abs(t))];
  auto cumulative = [&](int64_t t) { return prefix[size_t(std::clamp<int64_t>(t, -r - 1, r) + r + 1)]; };
  const double total = prefix.back();

  DoubleImage dst = make_image(src.width, src.height);
  const int64_t n = vertical ? src.height : src.width;
  const uint32_t lines = vertical ? src.width : src.height;
  auto texel = [&](DoubleImage& img, uint32_t line, int64_t i) -> double* {
    return vertical ? img.at(line, uint32_t(i)) : img.at(uint32_t(i), line);
  };
  auto ctexel = [&](const DoubleImage& img, uint32_t line, int64_t i) -> const double* {
    return vertical ? img.at(line, uint32_t(i)) : img.at(uint32_t(i), line);
  };
  for (uint32_t line = 0; line < lines; ++line) {
    for (int64_t i = 0; i < n; ++i) {
      const double* v = ctexel(src, line, i);
      if (v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0 && v[3] == 0.0) continue;
      auto add = [&](int64_t x, double w) {
        double* o = texel(dst, line, x);
        for (int k = 0; k < 4; ++k) o[k] += w * v[k];
      };
      if (n == 1) {
        add(0, total);
      } else if (i == 0) {
        for (int64_t x = 0; x <= std::min(n - 1, r); ++x) add(x, cumulative(-x));
      } else if (i == n - 1) {
        for (int64_t x = std::max<int64_t>(0, n - 1 - r); x < n; ++x) add(x, total - cumulative(n - 2 - x));
      } else {
        for (int64_t x = std::max<int64_t>(0, i - r); x <= std::min(n - 1, i + r); ++x)
          add(x, half[size_t(std::abs(i - x))]);
      }
    }
  }
  return dst;
}

// Uniform cubic B-spline weights at fraction t for texels floor - 1 .. floor + 2 (docs/BLUR.md
// "pyramid").
void bspline_weights(double t, double w[4]) {
  w[0] = (1 - t) * (1 - t) * (1 - t) / 6.0;
  w[1] = (3 * t * t * t - 6 * t * t + 4) / 6.0;
  w[2] = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6.0;
  w[3] = t * t * t / 6.0;
}

DoubleImage separable_blur(const DoubleImage& src, const std::vector<double>& half, bool round_scratch = false) {
  if (half.size() == 1 && half[0] == 1.0) return src;  // sigma 0: no blur
  DoubleImage h = convolve_axis(src, half, /*vertical=*/false);
  if (round_scratch) store_half(h);
  return convolve_axis(h, half, /*vertical=*/true);
}

// Taps of the exact Gaussian (docs/BLUR.md "Error model and metrics"): |t| <= ceil(6 sigma).
std::vector<double> exact_half_taps(double sigma) {
  if (!(sigma > 0.0) || !std::isfinite(sigma)) throw std::invalid_argument("exact_gaussian: sigma must be > 0");
  const auto e = size_t(std::ceil(6.0 * sigma));
  std::vector<double> w(e + 1);
  double sum = 0.0;
  for (size_t t = 0; t <= e; ++t) {
    w[t] = std::exp(-double(t) * double(t) / (2.0 * sigma * sigma));
    sum += t == 0 ? w[t] : 2.0 * w[t];
  }
  for (double& v : w) v /= sum;
  return w;
}

// One direction of the linear-sampling variant (docs/BLUR.md "separable, linear sampling"). The
// fetch at x +- offset is a linear interpolation between the two texels around it, each address
// clamped to the edge (the sampler's CLAMP_TO_EDGE).
DoubleImage linear_pass(const DoubleImage& src, const std::vector<double>& half, int subtexel_bits, bool vertical) {
  struct Fetch {
    double offset, weight;
  };
  std::vector<Fetch> fetches;
  const size_t r = half.size() - 1;
  for (size_t t = 1; t <= r; t += 2) {
    if (t + 1 <= r) {
      const double w = half[t] + half[t + 1];
      fetches.push_back({(double(t) * half[t] + double(t + 1) * half[t + 1]) / w, w});
    } else {
      fetches.push_back({double(t), half[t]});  // a lone last tap at its integer offset
    }
  }
  const int64_t n = vertical ? src.height : src.width;
  DoubleImage dst = make_image(src.width, src.height);
  auto read = [&](uint32_t x, uint32_t y, double q, double w, double* out) {
    const double f0 = std::floor(q);
    double f = q - f0;
    if (subtexel_bits > 0) f = std::round(std::ldexp(f, subtexel_bits)) / std::ldexp(1.0, subtexel_bits);
    const auto i = int64_t(f0);
    const int64_t a = std::clamp<int64_t>(i, 0, n - 1), b = std::clamp<int64_t>(i + 1, 0, n - 1);
    const double* va = vertical ? src.at(x, uint32_t(a)) : src.at(uint32_t(a), y);
    const double* vb = vertical ? src.at(x, uint32_t(b)) : src.at(uint32_t(b), y);
    for (int k = 0; k < 4; ++k) out[k] += w * ((1 - f) * va[k] + f * vb[k]);
  };
  for (uint32_t y = 0; y < src.height; ++y) {
    for (uint32_t x = 0; x < src.width; ++x) {
      double* out = dst.at(x, y);
      const double* c = src.at(x, y);
      for (int k = 0; k < 4; ++k) out[k] = half[0] * c[k];
      const double centre = vertical ? y : x;
      for (const Fetch& f : fetches) {
        read(x, y, centre - f.offset, f.weight, out);
        read(x, y, centre + f.offset, f.weight, out);
      }
    }
  }
  return dst;
}

// A dual pass (docs/BLUR.md "dual"): out(x, y) = sum over taps of weight * bilinear(src, p + offset)
// at p = (map(x, wd, ws), map(y, hd, hs)).
struct Tap {
  double ax, ay, weight;
};

DoubleImage dual_pass(const DoubleImage& src, uint32_t wd, uint32_t hd, const std::vector<Tap>& taps) {
  DoubleImage dst = make_image(wd, hd);
  for (uint32_t y = 0; y < hd; ++y) {
    const double py = map_coord(y, hd, src.height);
    for (uint32_t x = 0; x < wd; ++x) {
      const double px = map_coord(x, wd, src.width);
      for (const Tap& t : taps) add_bilinear(src, px + t.ax, py + t.ay, t.weight, dst.at(x, y));
    }
  }
  return dst;
}

void check_sizes(uint32_t aw, uint32_t ah, size_t an, uint32_t bw, uint32_t bh, size_t bn, const char* what) {
  if (aw != bw || ah != bh || an != bn)
    throw std::invalid_argument(std::string(what) + ": image sizes differ (" + std::to_string(aw) + "x" +
                                std::to_string(ah) + " vs " + std::to_string(bw) + "x" + std::to_string(bh) + ")");
}

template <typename Value>
double relative_l2_impl(const std::vector<Value>& y, const std::vector<double>& ref) {
  double diff2 = 0.0, ref2 = 0.0;
  for (size_t i = 0; i < ref.size(); ++i) {
    const double d = double(y[i]) - ref[i];
    diff2 += d * d;
    ref2 += ref[i] * ref[i];
  }
  if (std::isnan(diff2)) return diff2;
  if (ref2 == 0.0) return diff2 == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::sqrt(diff2 / ref2);
}

template <typename Value>
double max_abs_impl(const std::vector<Value>& y, const std::vector<double>& ref) {
  double m = 0.0;
  for (size_t i = 0; i < ref.size(); ++i) {
    const double d = std::abs(double(y[i]) - ref[i]);
    if (std::isnan(d)) return d;
    m = std::max(m, d);
  }
  return m;
}

template <typename Image>
ImpulseStats impulse_stats(const Image& image, uint32_t cx, uint32_t cy, int channel) {
  if (channel < 0 || channel > 3) throw std::invalid_argument("impulse_sigma: channel must be 0..3");
  ImpulseStats s;
  double sx = 0, sy = 0;
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = 0; x < image.width; ++x) {
      const double v = image.at(x, y)[channel];
      s.sum += v;
      sx += v * (double(x) - cx);
      sy += v * (double(y) - cy);
    }
  s.shift_x = sx / s.sum;
  s.shift_y = sy / s.sum;
  double vx = 0, vy = 0;
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = 0; x < image.width; ++x) {
      const double v = image.at(x, y)[channel];
      const double dx = double(x) - cx - s.shift_x, dy = double(y) - cy - s.shift_y;
      vx += v * dx * dx;
      vy += v * dy * dy;
    }
  s.sigma_x = std::sqrt(vx / s.sum);
  s.sigma_y = std::sqrt(vy / s.sum);
  return s;
}

}  // namespace

DoubleImage to_double(const CpuImage& input) {
  validate(input);
  DoubleImage out = make_image(input.width, input.height);
  std::copy(input.rgba.begin(), input.rgba.end(), out.rgba.begin());
  return out;
}

// docs/BLUR.md "Notation", Sanitize.
DoubleImage sanitize(const CpuImage& input, double max_value) {
  DoubleImage out = to_double(input);
  for (double& v : out.rgba) v = std::isnan(v) ? 0.0 : std::clamp(v, -max_value, max_value);
  return out;
}

// docs/BLUR.md "Area downsample". In integer units of 1/wd (as src/blur/shaders/blur.glsl): texel x
// covers [x ws, (x+1) ws), source texel i covers [i wd, (i+1) wd); the overlap over ws is the weight.
DoubleImage area_downsample(const DoubleImage& src, uint32_t wd, uint32_t hd) {
  if (wd == 0 || hd == 0 || wd > src.width || hd > src.height)
    throw std::invalid_argument("area_downsample: destination " + std::to_string(wd) + "x" + std::to_string(hd) +
                                " must be at least 1x1 and at most the source " + std::to_string(src.width) + "x" +
                                std::to_string(src.height));
  struct Weight {
    uint32_t index;
    double weight;
  };
  auto axis = [](uint32_t x, uint32_t nd, uint32_t ns) {
    std::vector<Weight> w;
    const uint64_t lo = uint64_t(x) * ns, hi = lo + ns;
    for (uint64_t i = lo / nd; i <= (hi - 1) / nd; ++i)
      w.push_back({uint32_t(i), double(std::min(hi, (i + 1) * nd) - std::max(lo, i * nd)) / double(ns)});
    return w;
  };
  DoubleImage dst = make_image(wd, hd);
  for (uint32_t y = 0; y < hd; ++y) {
    const std::vector<Weight> wy = axis(y, hd, src.height);
    for (uint32_t x = 0; x < wd; ++x) {
      const std::vector<Weight> wx = axis(x, wd, src.width);
      double* out = dst.at(x, y);
      for (const Weight& b : wy)
        for (const Weight& a : wx) {
          const double* s = src.at(a.index, b.index);
          for (int k = 0; k < 4; ++k) out[k] += a.weight * b.weight * s[k];
        }
    }
  }
  return dst;
}

// docs/BLUR.md "pyramid", binomial downsample D.
DoubleImage binomial_downsample(const DoubleImage& src, uint32_t wd, uint32_t hd) {
  if (wd == 0 || hd == 0 || wd > src.width || hd > src.height)
    throw std::invalid_argument("binomial_downsample: destination " + std::to_string(wd) + "x" + std::to_string(hd) +
                                " must be at least 1x1 and at most the source " + std::to_string(src.width) + "x" +
                                std::to_string(src.height));
  const double ox = wd == src.width ? 0.0 : 0.375 * double(src.width) / wd;
  const double oy = hd == src.height ? 0.0 : 0.375 * double(src.height) / hd;
  DoubleImage dst = make_image(wd, hd);
  for (uint32_t y = 0; y < hd; ++y) {
    const double py = map_coord(y, hd, src.height);
    for (uint32_t x = 0; x < wd; ++x) {
      const double px = map_coord(x, wd, src.width);
      for (double sy : {-1.0, 1.0})
        for (double sx : {-1.0, 1.0}) add_bilinear(src, px + sx * ox, py + sy * oy, 0.25, dst.at(x, y));
    }
  }
  return dst;
}

// docs/BLUR.md "Fused level blur" (and B' of "pyramid" with the binomial downsample).
DoubleImage fused_level_blur(const DoubleImage& src, uint32_t wd, uint32_t hd, double sigma, double truncation,
                             bool binomial) {
  const bool same = wd == src.width && hd == src.height;
  const DoubleImage s = same ? src : binomial ? binomial_downsample(src, wd, hd) : area_downsample(src, wd, hd);
  return separable_blur(s, blur_plan::gaussian_half_taps(sigma, truncation));
}

// docs/BLUR.md "Blur pyramid".
std::array<DoubleImage, 3> blur_pyramid(const CpuImage& input, const std::array<double, 3>& sigma_texels,
                                        bool round_half, double max_value) {
  std::array<DoubleImage, 3> levels;
  DoubleImage prev = sanitize(input, max_value);
  for (size_t k = 0; k < 3; ++k) {
    levels[k] =
        fused_level_blur(prev, blur_plan::half_size(prev.width), blur_plan::half_size(prev.height), sigma_texels[k]);
    if (round_half) store_half(levels[k]);
    prev = levels[k];
  }
  return levels;
}

// docs/BLUR.md "separable".
DoubleImage gaussian_separable(const CpuImage& input, double sigma_px, bool round_half_scratch, double max_value) {
  if (!(sigma_px > 0.0)) throw std::invalid_argument("gaussian_separable: sigma_px must be > 0");
  return separable_blur(sanitize(input, max_value),
                        blur_plan::gaussian_half_taps(sigma_px, blur_plan::kGaussTruncation), round_half_scratch);
}

// docs/BLUR.md "separable, linear sampling".
DoubleImage gaussian_separable_linear(const CpuImage& input, double sigma_px, int subtexel_bits,
                                      bool round_half_scratch, double max_value) {
  if (!(sigma_px > 0.0)) throw std::invalid_argument("gaussian_separable_linear: sigma_px must be > 0");
  const std::vector<double> half = blur_plan::gaussian_half_taps(sigma_px, blur_plan::kGaussTruncation);
  DoubleImage h = linear_pass(sanitize(input, max_value), half, subtexel_bits, /*vertical=*/false);
  if (round_half_scratch) store_half(h);
  return linear_pass(h, half, subtexel_bits, /*vertical=*/true);
}

namespace {

// docs/BLUR.md "Borders": the padded level 0 of a pyramid or dual chain, whose texel (u, v) is
// src's texel (u - pad_x, v - pad_y) clamped (the clamp-to-edge extension at full resolution).
DoubleImage pad_clamped(const DoubleImage& src, const blur_plan::Padding& pad) {
  DoubleImage dst = make_image(pad.padded_width, pad.padded_height);
  for (uint32_t v = 0; v < dst.height; ++v)
    for (uint32_t u = 0; u < dst.width; ++u) {
      const double* t = fetch(src, int64_t(u) - pad.pad_x, int64_t(v) - pad.pad_y);
      std::copy(t, t + 4, dst.at(u, v));
    }
  return dst;
}

// The input's extent of a padded chain's full-resolution output.
DoubleImage crop(const DoubleImage& src, const blur_plan::Padding& pad, uint32_t width, uint32_t height) {
  DoubleImage dst = make_image(width, height);
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const double* t = src.at(x + pad.pad_x, y + pad.pad_y);
      std::copy(t, t + 4, dst.at(x, y));
    }
  return dst;
}

}  // namespace

// docs/BLUR.md "pyramid", on the padded chain of "Borders".
DoubleImage gaussian_pyramid(const CpuImage& input, const blur_plan::Plan& plan, bool round_half, double max_value) {
  if (plan.levels == 0) throw std::invalid_argument("gaussian_pyramid: plan.levels must be >= 1");
  const blur_plan::Padding pad = blur_plan::padding_of(plan, input.width, input.height);
  DoubleImage level = pad_clamped(sanitize(input, max_value), pad);
  for (uint32_t j = 1; j <= plan.levels; ++j) {
    const uint32_t w = blur_plan::half_size(level.width), h = blur_plan::half_size(level.height);
    level = j < plan.levels ? binomial_downsample(level, w, h)
                            : fused_level_blur(level, w, h, plan.level_sigma, blur_plan::kGaussTruncation, true);
    if (round_half) store_half(level);
  }
  // Cubic B-spline at (map(x + pad_x, W', wk), map(y + pad_y, H', hk)): texels floor - 1 .. floor + 2
  // per axis, clamped; only the input's extent of the padded output.
  DoubleImage out = make_image(input.width, input.height);
  for (uint32_t y = 0; y < out.height; ++y) {
    const double py = map_coord(y + pad.pad_y, pad.padded_height, level.height);
    const double fy = std::floor(py);
    double wy[4];
    bspline_weights(py - fy, wy);
    for (uint32_t x = 0; x < out.width; ++x) {
      const double px = map_coord(x + pad.pad_x, pad.padded_width, level.width);
      const double fx = std::floor(px);
      double wx[4];
      bspline_weights(px - fx, wx);
      double* o = out.at(x, y);
      for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
          const double* v = fetch(level, int64_t(fx) - 1 + a, int64_t(fy) - 1 + b);
          for (int k = 0; k < 4; ++k) o[k] += wx[a] * wy[b] * v[k];
        }
    }
  }
  return out;
}

// docs/BLUR.md "dual": down = (4 bilinear(p) + sum over (+-o, +-o) of bilinear(p + offset)) / 8;
// up = (sum over (+-o, 0), (0, +-o) + 2 sum over (+-o/2, +-o/2)) / 12; gather only.
DoubleImage gaussian_dual(const CpuImage& input, const blur_plan::Plan& plan, bool round_half, double max_value) {
  if (plan.levels == 0) throw std::invalid_argument("gaussian_dual: plan.levels must be >= 1");
  const double o = plan.dual_offset, h = 0.5 * o;
  const std::vector<Tap> down = {{0, 0, 0.5}, {-o, -o, 0.125}, {o, -o, 0.125}, {-o, o, 0.125}, {o, o, 0.125}};
  const std::vector<Tap> up = {{-o, 0, 1.0 / 12},  {o, 0, 1.0 / 12},  {0, -o, 1.0 / 12}, {0, o, 1.0 / 12},
                               {-h, -h, 2.0 / 12}, {h, -h, 2.0 / 12}, {-h, h, 2.0 / 12}, {h, h, 2.0 / 12}};
  const blur_plan::Padding pad = blur_plan::padding_of(plan, input.width, input.height);
  std::vector<DoubleImage> d;
  d.push_back(pad_clamped(sanitize(input, max_value), pad));
  for (uint32_t j = 1; j <= plan.levels; ++j) {
    const DoubleImage& prev = d.back();
    d.push_back(dual_pass(prev, blur_plan::half_size(prev.width), blur_plan::half_size(prev.height), down));
    if (round_half) store_half(d.back());
  }
  DoubleImage u = d.back();
  for (uint32_t j = plan.levels; j-- > 0;) {
    u = dual_pass(u, d[j].width, d[j].height, up);
    if (round_half && j > 0) store_half(u);
  }
  return crop(u, pad, input.width, input.height);
}

// docs/BLUR.md "Error model and metrics".
DoubleImage exact_gaussian(const CpuImage& input, double sigma_px, double max_value) {
  return separable_blur(sanitize(input, max_value), exact_half_taps(sigma_px));
}

double rgba_relative_l2(const DoubleImage& y, const DoubleImage& ref) {
  check_sizes(y.width, y.height, y.rgba.size(), ref.width, ref.height, ref.rgba.size(), "rgba_relative_l2");
  return relative_l2_impl(y.rgba, ref.rgba);
}

double rgba_relative_l2(const CpuImage& y, const DoubleImage& ref) {
  check_sizes(y.width, y.height, y.rgba.size(), ref.width, ref.height, ref.rgba.size(), "rgba_relative_l2");
  return relative_l2_impl(y.rgba, ref.rgba);
}

template <typename Image>
double relative_l2_interior_impl(const Image& y, const DoubleImage& ref, uint32_t margin) {
  check_sizes(y.width, y.height, y.rgba.size(), ref.width, ref.height, ref.rgba.size(), "rgba_relative_l2_interior");
  double diff2 = 0.0, ref2 = 0.0;
  for (uint32_t j = margin; j + margin < ref.height; ++j)
    for (uint32_t i = margin; i + margin < ref.width; ++i)
      for (int k = 0; k < 4; ++k) {
        const double r = ref.at(i, j)[k], d = double(y.at(i, j)[k]) - r;
        diff2 += d * d;
        ref2 += r * r;
      }
  if (std::isnan(diff2)) return diff2;
  if (ref2 == 0.0) return diff2 == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::sqrt(diff2 / ref2);
}

double rgba_relative_l2_interior(const DoubleImage& y, const DoubleImage& ref, uint32_t margin) {
  return relative_l2_interior_impl(y, ref, margin);
}

double rgba_relative_l2_interior(const CpuImage& y, const DoubleImage& ref, uint32_t margin) {
  return relative_l2_interior_impl(y, ref, margin);
}

double rgba_max_abs(const DoubleImage& y, const DoubleImage& ref) {
  check_sizes(y.width, y.height, y.rgba.size(), ref.width, ref.height, ref.rgba.size(), "rgba_max_abs");
  return max_abs_impl(y.rgba, ref.rgba);
}

double rgba_max_abs(const CpuImage& y, const DoubleImage& ref) {
  check_sizes(y.width, y.height, y.rgba.size(), ref.width, ref.height, ref.rgba.size(), "rgba_max_abs");
  return max_abs_impl(y.rgba, ref.rgba);
}

CpuImage impulse_image(uint32_t w, uint32_t h, uint32_t cx, uint32_t cy, float value) {
  if (cx >= w || cy >= h) throw std::invalid_argument("impulse_image: (cx, cy) outside the image");
  CpuImage img(w, h, 0.0f);
  for (int k = 0; k < 4; ++k) img.at(cx, cy)[k] = value;
  return img;
}

ImpulseStats impulse_sigma(const DoubleImage& image, uint32_t cx, uint32_t cy, int channel) {
  return impulse_stats(image, cx, cy, channel);
}

ImpulseStats impulse_sigma(const CpuImage& image, uint32_t cx, uint32_t cy, int channel) {
  return impulse_stats(image, cx, cy, channel);
}

}  // namespace glint::reference
