// The cost model of `auto` (docs/BLUR.md "Cost model"): what each method's dispatches do, as the
// features of a linear model in microseconds whose coefficients are a device's (CostModel), and
// the fit of those coefficients to measured runs.
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "blur/blur_plan.h"
#include "blur/blur_plan_internal.h"

namespace glint::blur_plan {
namespace detail {
namespace {

constexpr double kBytesPerTexel = 8.0;  // RGBA16F

double texels(uint32_t w, uint32_t h) { return double(w) * double(h); }

}  // namespace

// Fused (R <= kFusedMaxRadius): one dispatch, input read and output written once, 2 (2R + 1) taps
// from shared memory per output. Line: two dispatches through a scratch image. Linear sampling:
// two dispatches, R + 1 bilinear fetches per output and direction.
Work separable_work(uint32_t radius, uint32_t width, uint32_t height, bool linear) {
  const double full = texels(width, height);
  Work w;
  if (linear) {
    w.dispatches = 2;
    w.bytes = 4.0 * kBytesPerTexel * full;
    w.fetch_taps = full * 2.0 * (radius + 1.0);
    return w;
  }
  w.dispatches = radius > kFusedMaxRadius ? 2 : 1;
  w.bytes = (radius > kFusedMaxRadius ? 4.0 : 2.0) * kBytesPerTexel * full;
  w.shared_taps = full * 2.0 * (2.0 * radius + 1.0);
  return w;
}

// Pyramid on the padded chain: every D and the B-spline up counted as the 16 texel-taps of their
// direct forms (four bilinear reads; 4x4 texels) per output, level k's blur taps from shared
// memory. The kernels now do less (the downsamples and the upsample run separably, walking bands:
// shaders/blur_down_stream.comp and blur_upsample_stream.comp), but with features describing the
// tiled forms before them (4.6 fetches and 13 shared taps per D output, 8 shared taps per upsampled
// one) the fit of the calibration's twelve runs ranked the dual above a faster pyramid on lavapipe
// at 10 of the 40 BM_BlurAutoVsBest points (worst 1.87x); these proxies kept it at 1
// (docs/PERF.md). The first D reads the padded extent of the input (clamped reads).
Work pyramid_work(uint32_t levels, uint32_t level_radius, uint32_t width, uint32_t height, const Padding& padding,
                  bool fp32_shared) {
  Work w;
  w.dispatches = levels + 2.0;  // k downsamples, the last level's blur, the upsample
  w.bytes = kBytesPerTexel * (texels(padding.padded_width, padding.padded_height) + texels(width, height));
  w.fetch_taps = 16.0 * texels(width, height);
  uint32_t lw = padding.padded_width, lh = padding.padded_height;
  for (uint32_t j = 1; j <= levels; ++j) {
    lw = half_size(lw);
    lh = half_size(lh);
    w.bytes += 2.0 * kBytesPerTexel * texels(lw, lh);  // written once, read once
    w.fetch_taps += 16.0 * texels(lw, lh);
    if (j == levels) {  // its blur at the same size: written once, read once
      w.bytes += 2.0 * kBytesPerTexel * texels(lw, lh);
      w.shared_taps += texels(lw, lh) * 2.0 * (2.0 * level_radius + 1.0) * (fp32_shared ? 2.0 : 1.0);
    }
  }
  return w;
}

// Dual on the padded chain: k down passes (5 bilinear reads, 20 taps, per output), k up passes
// (8 bilinear reads, 32 taps), the last one into the output.
Work dual_work(uint32_t levels, uint32_t width, uint32_t height, const Padding& padding) {
  Work w;
  w.dispatches = 2.0 * levels;
  w.bytes = kBytesPerTexel * (texels(padding.padded_width, padding.padded_height) + texels(width, height));
  w.fetch_taps = 32.0 * texels(width, height);
  uint32_t lw = padding.padded_width, lh = padding.padded_height;
  for (uint32_t j = 1; j <= levels; ++j) {
    lw = half_size(lw);
    lh = half_size(lh);
    const double level = texels(lw, lh);
    w.bytes += 2.0 * kBytesPerTexel * level * (j < levels ? 2.0 : 1.0);  // D_j and, below k, U_j
    w.fetch_taps += 20.0 * level + (j < levels ? 32.0 * level : 0.0);
  }
  return w;
}

}  // namespace detail

// Least squares on relative residuals (every run counts alike, whatever its length) by the normal
// equations over the free coefficients; a coefficient that comes out below its floor is held there
// and the rest refitted (an active-set loop, at most 4 rounds).
CostModel fit_cost_model(const std::vector<Work>& work, const std::vector<double>& measured_us) {
  if (work.size() != measured_us.size() || work.size() < 4)
    throw std::invalid_argument("fit_cost_model: needs as many measurements as work items, at least 4");
  const CostModel defaults;
  const std::array<double, 4> floor = {1e-3 * defaults.us_per_dispatch, 1e-3 * defaults.us_per_byte,
                                       1e-3 * defaults.us_per_shared_tap, 1e-3 * defaults.us_per_fetch_tap};
  auto features = [](const Work& w) {
    return std::array<double, 4>{w.dispatches, w.bytes, w.shared_taps, w.fetch_taps};
  };
  std::array<bool, 4> fixed{};
  std::array<double, 4> c = floor;
  for (int round = 0; round < 4; ++round) {
    // Columns are scaled by the defaults so the system is well conditioned.
    const std::array<double, 4> scale = {defaults.us_per_dispatch, defaults.us_per_byte, defaults.us_per_shared_tap,
                                         defaults.us_per_fetch_tap};
    double a[4][5] = {};
    for (size_t i = 0; i < work.size(); ++i) {
      if (!(measured_us[i] > 0.0) || !std::isfinite(measured_us[i]))
        throw std::invalid_argument("fit_cost_model: measurements must be positive and finite");
      const std::array<double, 4> x = features(work[i]);
      double rhs = 1.0;  // t_i / t_i
      std::array<double, 4> row{};
      for (int j = 0; j < 4; ++j) {
        if (fixed[size_t(j)])
          rhs -= c[size_t(j)] * x[size_t(j)] / measured_us[i];
        else
          row[size_t(j)] = x[size_t(j)] * scale[size_t(j)] / measured_us[i];
      }
      for (int r = 0; r < 4; ++r) {
        for (int s = 0; s < 4; ++s) a[r][s] += row[size_t(r)] * row[size_t(s)];
        a[r][4] += row[size_t(r)] * rhs;
      }
    }
    for (int j = 0; j < 4; ++j)
      if (fixed[size_t(j)] || a[j][j] == 0.0) {  // no information: keep the floor
        for (int s = 0; s < 5; ++s) a[j][s] = 0.0;
        a[j][j] = 1.0;
        a[j][4] = fixed[size_t(j)] ? 0.0 : floor[size_t(j)] / scale[size_t(j)];
        for (int r = 0; r < 4; ++r)
          if (r != j) a[r][j] = 0.0;
      }
    // Gaussian elimination with partial pivoting.
    for (int col = 0; col < 4; ++col) {
      int piv = col;
      for (int r = col + 1; r < 4; ++r)
        if (std::abs(a[r][col]) > std::abs(a[piv][col])) piv = r;
      for (int s = 0; s < 5; ++s) std::swap(a[col][s], a[piv][s]);
      for (int r = 0; r < 4; ++r) {
        if (r == col || a[col][col] == 0.0) continue;
        const double f = a[r][col] / a[col][col];
        for (int s = col; s < 5; ++s) a[r][s] -= f * a[col][s];
      }
    }
    int worst = -1;
    for (int j = 0; j < 4; ++j) {
      if (fixed[size_t(j)]) continue;
      const double v = a[j][j] != 0.0 ? a[j][4] / a[j][j] * scale[size_t(j)] : floor[size_t(j)];
      c[size_t(j)] = v;
      if (v < floor[size_t(j)] && (worst < 0 || v / floor[size_t(j)] < c[size_t(worst)] / floor[size_t(worst)]))
        worst = j;
    }
    if (worst < 0) break;
    fixed[size_t(worst)] = true;
    c[size_t(worst)] = floor[size_t(worst)];
  }
  for (int j = 0; j < 4; ++j) c[size_t(j)] = std::max(c[size_t(j)], floor[size_t(j)]);
  CostModel m;
  m.us_per_dispatch = c[0];
  m.us_per_byte = c[1];
  m.us_per_shared_tap = c[2];
  m.us_per_fetch_tap = c[3];
  return m;
}

}  // namespace glint::blur_plan
