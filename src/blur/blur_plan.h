// Planning of the blur family (docs/BLUR.md): Gaussian taps from sigma, level sizes, the
// variance bookkeeping of the pyramid, the parameters of each GaussianBlur method for a
// requested sigma, the border padding of the pyramid and dual chains, the modelled error and the
// cost model that `auto` uses. Pure float64 CPU code, no Vulkan. Implemented by concern:
// blur_taps.cpp (taps and variances), blur_error_model.cpp (modelled and rounding error),
// blur_cost_model.cpp (work and cost), blur_border.cpp (padding), blur_plan.cpp (the plans).
#pragma once

#include <cstdint>
#include <vector>

namespace glint::blur_plan {

/// Truncation c (in sigmas) of the Gaussian taps (docs/BLUR.md "Gaussian taps from sigma"):
/// BlurPyramid cuts at 3 sigma, GaussianBlur at 4 sigma.
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

/// The border padding of a pyramid or dual chain (docs/BLUR.md "Borders"): the chain runs on a
/// virtual padded input of padded_width x padded_height (multiples of 2^levels, so every level is
/// an exact half) whose texel (u, v) is the input's texel (u - pad_x, v - pad_y) clamped to the
/// input, i.e. the clamp-to-edge extension at full resolution. The pads are large enough that no
/// output texel of the input's extent reads a clamped texel of levels 1..k, so the output equals
/// the chain on the infinite clamp-to-edge extension: the exact Gaussian's own border rule.
struct Padding {
  uint32_t pad_x = 0, pad_y = 0;                 //!< left / top pad (input pixels, multiples of 2^levels)
  uint32_t padded_width = 0, padded_height = 0;  //!< the virtual level-0 size
};

/// What a plan's dispatches do, the features of the cost model (docs/BLUR.md "Cost model").
struct Work {
  double dispatches = 0;   //!< dispatches (each followed by a barrier)
  double bytes = 0;        //!< image bytes read and written, 8 a texel (RGBA16F)
  double shared_taps = 0;  //!< texel-taps read from shared memory (fused and line kernels)
  double fetch_taps = 0;   //!< texel-taps fetched from images (binomial, B-spline, dual)
};

/// Microseconds per unit of Work on one device: estimate_us(w) = the dot product. The defaults
/// were fitted on an H100; GaussianBlur measures a device's own at first use (docs/BLUR.md "Cost
/// model").
struct CostModel {
  double us_per_dispatch = 3.0;
  double us_per_byte = 1.0 / 2.5e6;
  double us_per_shared_tap = 1.0 / 2.0e7;
  double us_per_fetch_tap = 1.0 / 2.0e7;
  double estimate_us(const Work& w) const {
    return us_per_dispatch * w.dispatches + us_per_byte * w.bytes + us_per_shared_tap * w.shared_taps +
           us_per_fetch_tap * w.fetch_taps;
  }
};

/// Fits a CostModel to measured runs (microseconds each) of the given work by least squares on the
/// relative residuals, every coefficient kept positive (a coefficient the fit drives below zero is
/// held at 1e-3 of its default, so no feature is ever free). Throws std::invalid_argument when
/// the sizes differ or fewer than 4 runs are given.
CostModel fit_cost_model(const std::vector<Work>& work, const std::vector<double>& measured_us);

/// The parameters of one method for one sigma (input pixels) at one image size.
struct Plan {
  Method method = Method::separable;
  double sigma_px = 0;     //!< requested sigma
  uint32_t radius = 0;     //!< separable: taps radius at full resolution; pyramid: of level k
  uint32_t levels = 0;     //!< pyramid / dual: k
  double level_sigma = 0;  //!< pyramid: sigma_k in texels of level k (taps at kGaussTruncation)
  double dual_offset = 1;  //!< dual: o
  /// pyramid: the last level's blur keeps its shared copies in fp32 although the levels are
  /// RGBA16F (one fp16 rounding fewer; twice the shared bytes): chosen only when the fp16 copies
  /// would miss the bound and these meet it.
  bool fp32_shared = false;
  double effective_sigma_px = 0;    //!< sigma of the method's impulse response (input pixels)
  double expected_relative_l2 = 0;  //!< modelled error against the exact Gaussian (docs/BLUR.md)
  Padding padding;                  //!< pyramid / dual: the padded chain (padding_of())
  Work work;                        //!< what the plan's dispatches do
  double cost = 0;                  //!< estimated microseconds (CostModel::estimate_us(work))
};

/// The border padding of a pyramid (levels, radius) or dual (levels, dual_offset) plan on an input
/// of width x height (zero pads, the input size, for separable). See Padding.
Padding padding_of(const Plan& plan, uint32_t width, uint32_t height);

/// How the GPU stores and samples what a plan computes, for the rounding part of the expected
/// error (docs/BLUR.md "Error model"). A unit is the largest relative error one store into that
/// format may make: 2^-10 for fp16 (Vulkan lets a device round toward zero, one ulp, as well as
/// to nearest), 2^-5 for B10G11R11's 5- and 6-bit mantissas, 2^-8 for E5B9G9R9, 0 for fp32 (a
/// float result stored as float is exact).
struct Storage {
  double level_unit = 0;        //!< intermediate images (GaussianBlurConfig::precision)
  double output_unit = 0;       //!< the caller's output format
  bool level_half = false;      //!< intermediates are RGBA16F: the fused kernel's shared copies are fp16
  bool output_half = false;     //!< the output is RGBA16F: so are the fused kernel's at full resolution
  uint32_t sub_texel_bits = 4;  //!< VkPhysicalDeviceLimits::subTexelPrecisionBits (linear sampling)
};

/// The unit of `Storage` for a store into a format of `mantissa_bits` explicit mantissa bits
/// (10 for fp16, 23 for fp32): 2^-mantissa_bits, one ulp relative, or 0 at 23 and above.
double store_unit(uint32_t mantissa_bits);

/// Bound on the relative L2 error that storage and fp32 arithmetic add to the plan's modelled
/// error, for non-negative images (all weights are non-negative, so an error of u relative in a
/// stored texel reaches each output at most as u times the output): the sum over the stores on
/// the path (levels, the fused kernel's fp16 shared copies, the output) of their units, the
/// linear sampler's weight quantization 2^-sub_texel_bits (twice per pass: it moves weight
/// between the two texels of a pair), and 2^-24 per fp32 multiply-add; times (1 + modelled
/// error), since the outputs are relative to the exact Gaussian.
double rounding_bound(const Plan& plan, const Storage& storage);

/// Plan of `method` for `sigma_px` on an image of `width x height`. For pyramid, the largest
/// level count whose modelled error is <= max_relative_l2 (at least 1 level).
Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2);

/// The cheapest plan among separable, pyramid and dual whose expected error is <= max_relative_l2
/// (separable always qualifies: it is the reference up to truncation at 4 sigma; if even it misses
/// a very small bound it is returned with its error). Costs by `model` (default: the H100's).
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2,
               const CostModel& model = CostModel{});

/// plan_method() and plan_auto() with the rounding of `storage` added to expected_relative_l2
/// (rounding_bound()), which is then what the bound is compared with: the error of what the
/// caller's output holds, not only of the algorithm.
Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2,
                 const Storage& storage);
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage& storage,
               const CostModel& model = CostModel{});

}  // namespace glint::blur_plan
