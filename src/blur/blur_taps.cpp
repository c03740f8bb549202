// Gaussian taps from sigma, their discrete variance and its inverse, and the BlurPyramid's
// cumulative sigma (docs/BLUR.md "Gaussian taps from sigma", "Blur pyramid").
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "blur/blur_plan.h"
#include "blur/blur_plan_internal.h"

namespace glint::blur_plan {
namespace detail {

uint32_t radius_of(double sigma, double truncation) {
  if (sigma <= 0.0) return 0;
  return std::max(1u, uint32_t(std::ceil(truncation * sigma)));
}

// floor(log2(min(width, height))), at least 1.
uint32_t max_levels(uint32_t width, uint32_t height) {
  uint32_t k = 0;
  for (uint32_t n = std::min(width, height); n >= 2; n /= 2) ++k;
  return std::max(1u, k);
}

}  // namespace detail

// docs/BLUR.md "Gaussian taps from sigma".
std::vector<double> gaussian_half_taps(double sigma, double truncation) {
  if (sigma == 0.0) return {1.0};
  if (!(sigma > 0.0) || !std::isfinite(sigma))
    throw std::invalid_argument("gaussian_half_taps: sigma must be finite and >= 0");
  if (!(truncation > 0.0) || !std::isfinite(truncation))
    throw std::invalid_argument("gaussian_half_taps: truncation must be finite and > 0");
  const uint32_t r = detail::radius_of(sigma, truncation);
  std::vector<double> w(r + 1);
  double sum = 0.0;
  for (uint32_t t = 0; t <= r; ++t) {
    w[t] = std::exp(-double(t) * t / (2.0 * sigma * sigma));
    sum += t == 0 ? w[t] : 2.0 * w[t];
  }
  for (double& v : w) v /= sum;
  return w;
}

double discrete_variance(double sigma, double truncation) {
  const std::vector<double> w = gaussian_half_taps(sigma, truncation);
  double v = 0.0;
  for (size_t t = 1; t < w.size(); ++t) v += 2.0 * w[t] * double(t) * double(t);
  return v;
}

// discrete_variance grows with sigma (with small upward jumps where the radius grows, as the new
// outer tap lies beyond one standard deviation), so bisection finds the smallest sigma whose
// variance reaches `variance`; at a jump that is the sigma at the jump.
double sigma_for_variance(double variance, double truncation) {
  if (!(variance > 0.0)) return 0.0;
  double lo = 0.0, hi = std::sqrt(variance) * 1.25 + 1.0;
  while (discrete_variance(hi, truncation) < variance) hi *= 2.0;
  for (int it = 0; it < 64 && hi - lo > 1e-13 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (discrete_variance(mid, truncation) < variance ? lo : hi) = mid;
  }
  return hi;
}

std::vector<double> gaussian_half_taps(double sigma) { return gaussian_half_taps(sigma, kPyramidTruncation); }
double discrete_variance(double sigma) { return discrete_variance(sigma, kPyramidTruncation); }
double sigma_for_variance(double variance) { return sigma_for_variance(variance, kPyramidTruncation); }

// docs/BLUR.md "Blur pyramid": var_k = var_(k-1) + s_(k-1)^2 (r^2 - 1) / 12 + s_k^2 var(sigma_k).
std::vector<double> pyramid_effective_sigma(uint32_t size, const std::vector<double>& sigma_texels) {
  if (size == 0) throw std::invalid_argument("pyramid_effective_sigma: size must be >= 1");
  std::vector<double> out;
  double var = 0.0;
  uint32_t w_prev = size;
  for (double sigma : sigma_texels) {
    const uint32_t w = half_size(w_prev);
    const double s_prev = double(size) / w_prev, s = double(size) / w, r = double(w_prev) / w;
    var += s_prev * s_prev * (r * r - 1.0) / 12.0 + s * s * discrete_variance(sigma);
    out.push_back(std::sqrt(var));
    w_prev = w;
  }
  return out;
}
}  // namespace glint::blur_plan
