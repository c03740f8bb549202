// Border padding of the pyramid and dual chains (docs/BLUR.md "Borders"). The exact Gaussian
// clamps at full resolution: out(x) = sum_t g_t in(clamp(x + t)), the Gaussian of the input's
// clamp-to-edge extension. A chain that clamps at its coarse levels' borders instead is a
// different operator near the borders (a relative L2 error of 7e-2 over a natural 512x512 image
// at sigma 50, against 5e-3 in the interior). So the chain runs on a virtual padded input whose
// texel u is the input's clamp(u - pad): the extension at full resolution, never stored (the first
// dispatch reads the input at clamped coordinates). The pads are chosen so that no output texel of
// the input's extent reads a clamped texel of any stored level: those outputs are then exactly the
// shift-invariant chain on the infinite extension, which is what the error model simulates. The
// padded sizes are multiples of 2^k, so every level is an exact half.
#include <cmath>
#include <cstdint>

#include "blur/blur_plan.h"
#include "blur/blur_plan_internal.h"

namespace glint::blur_plan {
namespace detail {
namespace {

int64_t floor_i(double v) { return int64_t(std::floor(v)); }

// Whether texels a..b of a stored level of w texels are read unclamped, with one texel of slack
// on each side (the GPU computes the positions in fp32).
bool inside(int64_t a, int64_t b, int64_t w) { return a >= 1 && b <= w - 2; }

// The pyramid along one axis: the output texels pad .. pad + n - 1 of the padded extent `padded`
// (virtual full resolution). The B-spline reads level k at floor(q) - 1 .. floor(q) + 2 with
// q = map(x) = (x + 0.5) / 2^k - 0.5; the fused blur reads R more on each side; the binomial D at
// level j reads level j - 1 at 2i + 0.5 +- 0.75, i.e. texels 2i - 1 .. 2i + 2. Level 0 is the
// virtual extension and needs no check.
bool pyramid_axis_fits(uint32_t levels, uint32_t radius, uint32_t n, uint32_t pad, uint32_t padded) {
  const double s = std::ldexp(1.0, int(levels));
  int64_t a = floor_i((pad + 0.5) / s - 0.5) - 1 - int64_t(radius);
  int64_t b = floor_i((pad + n - 1 + 0.5) / s - 0.5) + 2 + int64_t(radius);
  int64_t w = int64_t(padded >> levels);
  for (uint32_t j = levels; j >= 1; --j) {
    if (!inside(a, b, w)) return false;
    a = 2 * a - 1;
    b = 2 * b + 2;
    w *= 2;
  }
  return true;
}

// The dual along one axis: the up passes U_j = up(U_(j+1)) read level j + 1 bilinearly at
// map(x) +- o, i.e. floor((x + 0.5) / 2 - 0.5 - o) .. floor((x + 0.5) / 2 - 0.5 + o) + 1; the
// down passes D_j read level j - 1 at 2i + 0.5 +- o the same way.
bool dual_axis_fits(uint32_t levels, double o, uint32_t n, uint32_t pad, uint32_t padded) {
  int64_t a = pad, b = int64_t(pad) + n - 1;
  int64_t w = padded;
  for (uint32_t j = 0; j < levels; ++j) {
    a = floor_i((a + 0.5) / 2.0 - 0.5 - o);
    b = floor_i((b + 0.5) / 2.0 - 0.5 + o) + 1;
    w /= 2;
    if (!inside(a, b, w)) return false;
  }
  for (uint32_t j = levels; j >= 2; --j) {
    a = floor_i(2.0 * a + 0.5 - o);
    b = floor_i(2.0 * b + 0.5 + o) + 1;
    w *= 2;
    if (!inside(a, b, w)) return false;
  }
  return true;
}

// The smallest pad m 2^k (and the padded size, the next multiple of 2^k of n + 2 pad) that fits.
template <typename Fits>
void pad_axis(uint32_t levels, uint32_t n, Fits fits, uint32_t& pad, uint32_t& padded) {
  const uint32_t spacing = 1u << levels;
  for (uint32_t m = 1;; ++m) {
    pad = m * spacing;
    padded = (n + 2 * pad + spacing - 1) / spacing * spacing;
    if (fits(pad, padded)) return;
  }
}

}  // namespace

Padding pyramid_padding(uint32_t levels, uint32_t level_radius, uint32_t width, uint32_t height) {
  Padding p;
  auto fits = [&](uint32_t n) {
    return [=](uint32_t pad, uint32_t padded) { return pyramid_axis_fits(levels, level_radius, n, pad, padded); };
  };
  pad_axis(levels, width, fits(width), p.pad_x, p.padded_width);
  pad_axis(levels, height, fits(height), p.pad_y, p.padded_height);
  return p;
}

Padding dual_padding(uint32_t levels, double offset, uint32_t width, uint32_t height) {
  Padding p;
  auto fits = [&](uint32_t n) {
    return [=](uint32_t pad, uint32_t padded) { return dual_axis_fits(levels, offset, n, pad, padded); };
  };
  pad_axis(levels, width, fits(width), p.pad_x, p.padded_width);
  pad_axis(levels, height, fits(height), p.pad_y, p.padded_height);
  return p;
}

}  // namespace detail

Padding padding_of(const Plan& plan, uint32_t width, uint32_t height) {
  switch (plan.method) {
    case Method::pyramid:
      return detail::pyramid_padding(plan.levels, plan.radius, width, height);
    case Method::dual:
      return detail::dual_padding(plan.levels, plan.dual_offset, width, height);
    default:
      return Padding{0, 0, width, height};
  }
}

}  // namespace glint::blur_plan
