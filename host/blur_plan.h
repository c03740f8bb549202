// Planning of the blur family (docs/BLUR.md): Gaussian taps from sigma, level sizes, the
// variance bookkeeping of the pyramid, the parameters of each GaussianBlur method for a
// requested sigma, and the modelled error that `auto` uses. Pure float64 CPU code, no Vulkan.
#pragma once

#include <cstdint>
#include <vector>

namespace glint::blur_plan {

/// Truncation c (in sigmas) of the Gaussian taps (docs/BLUR.md "Gaussian taps from sigma"):
/// BlurPyramid (seed 003) cuts at 3 sigma, GaussianBlur at 4 sigma.
inline constexpr double kPyramidTruncation = 3.0;
inline constexpr double kGaussTruncation = 4.0;
/// The largest radius the fused level kernel takes (docs/BLUR.md "Fused level blur").
inline constexpr uint32_t kFusedMaxRadius = 12;

/// Normalized Gaussian taps w[0..R] (w[t] for offsets +-t), R = max(1, ceil(truncation sigma)).
/// sigma == 0 gives {1} (R = 0: identity). sigma >= 0 and finite, truncation > 0, else
/// std::invalid_argument.
std::vector<double> gaussian_half_taps(double sigma, double truncation);
/// The discrete variance sum_t w_t t^2 of those taps (texels^2).
double discrete_variance(double sigma, double truncation);
/// The sigma (texels) whose discrete variance is `variance` (inverse of discrete_variance),
/// found by bisection; 0 for variance <= 0.
double sigma_for_variance(double variance, double truncation);
/// The same at the BlurPyramid truncation, kPyramidTruncation (3 sigma).
std::vector<double> gaussian_half_taps(double sigma);
double discrete_variance(double sigma);
double sigma_for_variance(double variance);

/// max(1, n / 2).
inline uint32_t half_size(uint32_t n) { return n > 1 ? n / 2 : 1; }

/// Effective cumulative sigma (input pixels) of BlurPyramid level k = 1..levels along one axis of
/// `size` input pixels, with per-level sigmas in texels of each level (docs/BLUR.md; taps at
/// kPyramidTruncation).
std::vector<double> pyramid_effective_sigma(uint32_t size, const std::vector<double>& sigma_texels);

enum class Method : uint32_t { separable = 0, separable_linear = 1, pyramid = 2, dual = 3 };

/// The parameters of one method for one sigma (input pixels) at one image size.
struct Plan {
  Method method = Method::separable;
  double sigma_px = 0;          //!< requested sigma
  uint32_t radius = 0;          //!< separable: taps radius at full resolution; pyramid: of level k
  uint32_t levels = 0;          //!< pyramid / dual: k
  double level_sigma = 0;       //!< pyramid: sigma_k in texels of level k (taps at kGaussTruncation)
  double dual_offset = 1;       //!< dual: o
  double effective_sigma_px = 0;   //!< sigma of the method's impulse response (input pixels)
  double expected_relative_l2 = 0; //!< modelled error against the exact Gaussian (docs/BLUR.md)
  double cost = 0;              //!< relative cost estimate used by auto (full-resolution texel passes)
};

/// Plan of `method` for `sigma_px` on an image of `width x height`. For pyramid, the largest
/// level count whose modelled error is <= max_relative_l2 (at least 1 level).
Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2);

/// The cheapest plan among separable, pyramid and dual whose expected error is <= max_relative_l2
/// (separable always qualifies: it is the reference up to truncation at 4 sigma; if even it misses
/// a very small bound it is returned with its error).
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2);

}  // namespace glint::blur_plan
