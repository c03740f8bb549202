// Internals of the blur planner shared by its files (blur_plan.h lists them): constants of the
// methods, the modelled errors and variances the planner searches over, and the work of each
// method. Not part of the library's interface.
#pragma once

#include <cstdint>
#include <vector>

#include "blur/blur_plan.h"

namespace glint::blur_plan::detail {

// Dual offsets are searched in this range (docs/BLUR.md "dual").
inline constexpr double kDualMinOffset = 0.5;
inline constexpr double kDualMaxOffset = 2.0;
// Level sigmas the pyramid may use (docs/BLUR.md "pyramid"): at least 0.5, and at most 3, where
// the radius at kGaussTruncation reaches kFusedMaxRadius.
inline constexpr double kMinLevelSigma = 0.5;
inline constexpr double kMaxLevelSigma = 3.0;
// The binomial downsample's bilinear reads sit at +-0.375 r (docs/BLUR.md "pyramid").
inline constexpr double kBinomialOffset = 0.375;

/// max(1, ceil(truncation sigma)), 0 for sigma <= 0.
uint32_t radius_of(double sigma, double truncation);
/// floor(log2(min(width, height))), at least 1: the levels whose sizes are still at least 1x1
/// without the max(1, .) of half().
uint32_t max_levels(uint32_t width, uint32_t height);

// blur_error_model.cpp: the modelled (interior, shift-invariant) errors and variances.
double separable_model_error(double sigma);
/// Variance (input pixels^2) along an axis of `size` of the pyramid with `levels` levels whose
/// level blur has discrete variance level_var (texels^2 of level k); s2_out receives s^2.
double pyramid_axis_variance(uint32_t size, uint32_t levels, double level_var, double* s2_out = nullptr);
/// The level variance (texels^2 of level k) that makes the variances along an axis add to sigma^2.
double pyramid_level_variance(double sigma, uint32_t size, uint32_t levels);
double pyramid_model_error(double sigma, uint32_t levels, double level_sigma);
double dual_marginal_variance(uint32_t levels, double o);
double dual_model_error(double sigma, uint32_t levels, double o);

// blur_cost_model.cpp: what each method's dispatches do (level sizes from `padding` where the
// chain is padded).
Work separable_work(uint32_t radius, uint32_t width, uint32_t height, bool linear);
// fp32_shared: the last level's shared copies are fp32, each tap twice the shared bytes of an fp16
// one (counted twice).
Work pyramid_work(uint32_t levels, uint32_t level_radius, uint32_t width, uint32_t height, const Padding& padding,
                  bool fp32_shared = false);
Work dual_work(uint32_t levels, uint32_t width, uint32_t height, const Padding& padding);

// blur_border.cpp: the padding of a pyramid (levels, level radius) or dual (levels, offset) chain.
Padding pyramid_padding(uint32_t levels, uint32_t level_radius, uint32_t width, uint32_t height);
Padding dual_padding(uint32_t levels, double offset, uint32_t width, uint32_t height);

}  // namespace glint::blur_plan::detail
