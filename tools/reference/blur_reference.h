// Float64 CPU reference of glint's blur family. It implements docs/BLUR.md step by step (the same
// contract as src/blur/shaders/blur_*.comp and src/blur/shaders/blur.glsl): what each kernel computes, and the
// exact Gaussian the methods are measured against. All four channels are filtered. CPU only: no
// Vulkan call is made here.
//
// Note on the metrics: bloom_reference.h declares relative_l2(const CpuImage&, const DoubleImage&)
// over RGB only (bloom leaves alpha alone). The blur metrics below cover RGBA and are named
// rgba_relative_l2 / rgba_max_abs so that a CpuImage argument never silently picks the RGB one.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "blur/blur_plan.h"
#include "core/cpu_image.h"
#include "reference/bloom_reference.h"  // DoubleImage

namespace glint::reference {

/// Sanitize clamp for RGBA16F and RGBA32F input (docs/BLUR.md "Notation").
inline constexpr double kBlurMaxValueFp16 = 65504.0;
inline constexpr double kBlurMaxValueFp32 = 1.0e37;

/// Converts `input` to doubles without any change (NaN and Inf kept).
DoubleImage to_double(const CpuImage& input);

/// docs/BLUR.md "Notation": NaN becomes 0 and each channel is clamped to [-max_value, max_value].
/// Throws std::invalid_argument for an empty image or a pixel buffer of the wrong size.
DoubleImage sanitize(const CpuImage& input, double max_value = kBlurMaxValueFp16);

/// docs/BLUR.md "Area downsample": destination texel x covers [x ws/wd, (x+1) ws/wd) of the
/// source; each source texel weighs its overlap / (ws/wd); 2-D weights are products. The identity
/// along an axis whose sizes match. wd <= ws and hd <= hs, both >= 1 (else std::invalid_argument).
DoubleImage area_downsample(const DoubleImage& src, uint32_t wd, uint32_t hd);

/// docs/BLUR.md "pyramid", the binomial downsample D: the mean of four bilinear reads at
/// map(x) + (+-0.375 r_x, +-0.375 r_y), r the reduction ratio per axis (0 offset along an axis whose
/// sizes match): [1 3 3 1] / 8 per axis on an exact 2:1 reduction. Sizes as area_downsample.
DoubleImage binomial_downsample(const DoubleImage& src, uint32_t wd, uint32_t hd);

/// docs/BLUR.md "Fused level blur" B(s, wd, hd, sigma): S = area_downsample(s, wd, hd), then the
/// separable Gaussian of `sigma` texels (taps blur_plan::gaussian_half_taps(sigma, truncation),
/// sigma 0 = no blur) with clamp-to-edge at the wd x hd grid, horizontal then vertical, no
/// rounding between. With `binomial`, D replaces the area downsample (the pyramid method's B').
DoubleImage fused_level_blur(const DoubleImage& src, uint32_t wd, uint32_t hd, double sigma,
                             double truncation = blur_plan::kPyramidTruncation, bool binomial = false);

/// docs/BLUR.md "Blur pyramid": L0 = sanitize(input), Lk = B(L(k-1), half, half, sigma_k) for
/// k = 1..3. With round_half, each level is rounded through fp16 as it is stored (the next level
/// reads the rounded one; the returned levels are the stored ones).
std::array<DoubleImage, 3> blur_pyramid(const CpuImage& input, const std::array<double, 3>& sigma_texels,
                                        bool round_half = false, double max_value = kBlurMaxValueFp16);

/// docs/BLUR.md "separable": B(sanitize(input), W, H, sigma_px), truncation 4. With round_half_scratch, the
/// horizontal pass is rounded through fp16 before the vertical one (the two-line-dispatch path
/// for radii above fused_max_radius stores it in a scratch image); the output is not rounded.
DoubleImage gaussian_separable(const CpuImage& input, double sigma_px, bool round_half_scratch = false,
                               double max_value = kBlurMaxValueFp16);

/// docs/BLUR.md "separable, linear sampling" (taps at truncation 4): per direction, the centre tap
/// plus the pairs
/// (t, t+1), t = 1, 3, 5, ..., each one linear fetch at offset (t w_t + (t+1) w_(t+1)) / (w_t + w_(t+1))
/// with weight w_t + w_(t+1), a lone last tap at its integer offset, clamp-to-edge addressing.
/// subtexel_bits = 0 computes the fetch weights exactly (then the result equals
/// gaussian_separable up to rounding); a positive value rounds each fetch's fractional position
/// to a multiple of 2^-subtexel_bits first, a model of the sampler's weight precision (8 on
/// NVIDIA), not a bit-exact one. round_half_scratch: as gaussian_separable.
DoubleImage gaussian_separable_linear(const CpuImage& input, double sigma_px, int subtexel_bits = 0,
                                      bool round_half_scratch = false, double max_value = kBlurMaxValueFp16);

/// docs/BLUR.md "pyramid" with plan.levels = k and plan.level_sigma, on the padded chain of
/// "Borders" (blur_plan::padding_of(plan, W, H)): P0 = sanitize(input) extended by clamp-to-edge to
/// the padded extent,
/// Pj = D(P(j-1)) for j < k, Pk = B'(P(k-1), sigma_k) (D, then the blur at truncation 4), output =
/// the uniform cubic B-spline of Pk at (map(x + pad_x, W', wk), map(y + pad_y, H', hk)). round_half
/// rounds P1..Pk (stored intermediates).
DoubleImage gaussian_pyramid(const CpuImage& input, const blur_plan::Plan& plan, bool round_half = false,
                             double max_value = kBlurMaxValueFp16);

/// docs/BLUR.md "dual" with plan.levels = k and plan.dual_offset = o, on the padded chain of
/// "Borders": D0 = sanitize(input) extended by clamp-to-edge to the padded extent,
/// Dj = down(D(j-1)) at half sizes, U_k = D_k, U_j = up(U_(j+1)) at the size of D_j, output the
/// input's extent of U_0.
/// round_half rounds D1..Dk and U1..U(k-1) (stored intermediates).
DoubleImage gaussian_dual(const CpuImage& input, const blur_plan::Plan& plan, bool round_half = false,
                          double max_value = kBlurMaxValueFp16);

/// docs/BLUR.md "Error model and metrics": the sampled Gaussian of sigma_px with taps to
/// |t| <= ceil(6 sigma), normalized, separable, clamp-to-edge, of sanitize(input).
DoubleImage exact_gaussian(const CpuImage& input, double sigma_px, double max_value = kBlurMaxValueFp16);

/// Relative L2 ||y - ref|| / ||ref|| over all texels and all four channels. 0 when both are zero,
/// +Inf when only ref is; NaN or Inf when y holds one. Throws std::invalid_argument on a size
/// mismatch.
double rgba_relative_l2(const DoubleImage& y, const DoubleImage& ref);
double rgba_relative_l2(const CpuImage& y, const DoubleImage& ref);
/// The same over the interior only: texels at least `margin` from every border (0 when the
/// interior is empty), for looking at where an error lies (the border band and the interior).
double rgba_relative_l2_interior(const DoubleImage& y, const DoubleImage& ref, uint32_t margin);
double rgba_relative_l2_interior(const CpuImage& y, const DoubleImage& ref, uint32_t margin);
/// Max |y - ref| over all texels and channels (NaN if y holds a NaN). Throws on a size mismatch.
double rgba_max_abs(const DoubleImage& y, const DoubleImage& ref);
double rgba_max_abs(const CpuImage& y, const DoubleImage& ref);

/// A w x h image, 0 everywhere except `value` in all four channels at (cx, cy).
CpuImage impulse_image(uint32_t w, uint32_t h, uint32_t cx, uint32_t cy, float value = 1.0f);

/// Moments of a blurred impulse in one channel: the sum, the centroid's shift from (cx, cy), and
/// per axis the square root of the second moment about the centroid (the measured sigma).
struct ImpulseStats {
  double sum = 0;
  double shift_x = 0, shift_y = 0;
  double sigma_x = 0, sigma_y = 0;
};
ImpulseStats impulse_sigma(const DoubleImage& image, uint32_t cx, uint32_t cy, int channel = 0);
ImpulseStats impulse_sigma(const CpuImage& image, uint32_t cx, uint32_t cy, int channel = 0);

}  // namespace glint::reference
