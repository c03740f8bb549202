// Measurements of the light an effect adds to an image, in float64: total energy, centroid,
// second moments and the radius that holds a given fraction of the energy. Used by the stability
// tests (tests/stability_test.cpp) and the program that draws docs/STABILITY.md
// (bench/stability/stability_report.cpp), so that the document and the tests measure the same way.
#pragma once

#include <cstdint>
#include <vector>

#include "core/cpu_image.h"

namespace glint::analysis {

/// A one-pixel light of `value` (in R, G and B; alpha 1) at the continuous position (x, y) in
/// texel-centre coordinates, on a background of `background`. A sub-pixel position splits the value
/// bilinearly over the 2x2 texels around it (weights (1-fx)(1-fy), fx(1-fy), ...), so the total
/// light is `value` wherever the point is; (x, y) must lie in [0, w-1] x [0, h-1].
CpuImage subpixel_point(uint32_t width, uint32_t height, double x, double y, float value, float background = 0.0f);

/// The light added by an effect: out - in, summed over R, G, B, per pixel (row-major).
std::vector<double> added_light(const CpuImage& out, const CpuImage& in);

struct LightStats {
  double energy = 0.0;        //!< sum of the added light
  double cx = 0.0, cy = 0.0;  //!< its centroid (texel-centre coordinates)
  double xx = 0.0, yy = 0.0;  //!< second moments about the centroid (px^2)
};
/// Energy, centroid and second moments of `added` (width x height). A zero energy gives zeros.
LightStats light_stats(const std::vector<double>& added, uint32_t width, uint32_t height);

/// The smallest radius r (px, Euclidean, about (cx, cy)) such that the added light within r holds
/// at least `fraction` of the energy. Negative added light counts as 0 (fp rounding only).
double radius_holding(const std::vector<double>& added, uint32_t width, uint32_t height, double cx, double cy,
                      double fraction);

/// Relative spread of a series: (max - min) / mean, and the largest step between neighbours
/// relative to the mean.
struct Variation {
  double spread = 0.0;
  double max_step = 0.0;
};
Variation relative_variation(const std::vector<double>& series);

}  // namespace glint::analysis
