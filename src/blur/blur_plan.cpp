// Planning of the blur family (docs/BLUR.md): Gaussian taps from sigma ("Gaussian taps from
// sigma"), the pyramid's variance bookkeeping ("Blur pyramid"), the parameters of each
// GaussianBlur method ("Gaussian blur of any sigma") and the modelled error that `auto` uses
// ("Error model and metrics"). Pure float64 CPU code, no Vulkan; nothing is cached between calls.
//
// The error model simulates each method's impulse response in the interior of the image on a
// virtual exact 2:1 chain (a line or window whose length is a multiple of 2^k and large enough that
// no clamp is reached), so that planning costs the same at every image size. Images whose levels
// are not exact halves (odd sizes) differ from the model only by the small phase-dependent
// differences of the area filter; the image size limits the level count k (the level must be at
// least 1x1 without the max(1, .) of half()).
#include "blur/blur_plan.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <utility>

namespace glint::blur_plan {
namespace {

// Cost model (calibrated later on the H100): microseconds-like units.
constexpr double kBytesPerUs = 2.5e6;
constexpr double kUsPerDispatch = 3.0;
constexpr double kTapsPerUs = 2.0e7;
constexpr double kBytesPerTexel = 8.0;  // RGBA16F
// Dual offsets are searched in this range (docs/BLUR.md "dual").
constexpr double kDualMinOffset = 0.5;
constexpr double kDualMaxOffset = 2.0;
// Level sigmas the pyramid may use (docs/BLUR.md "pyramid"): at least 0.5, and at most 3, where
// the radius at kGaussTruncation reaches kFusedMaxRadius.
constexpr double kMinLevelSigma = 0.5;
constexpr double kMaxLevelSigma = 3.0;
// The binomial downsample's bilinear reads sit at +-0.375 r (docs/BLUR.md "pyramid").
constexpr double kBinomialOffset = 0.375;

uint32_t radius_of(double sigma, double truncation) {
  if (sigma <= 0.0) return 0;
  return std::max(1u, uint32_t(std::ceil(truncation * sigma)));
}

// Full symmetric taps w[-R..R] (index t + R) from half taps w[0..R].
std::vector<double> full_taps(const std::vector<double>& half) {
  const size_t r = half.size() - 1;
  std::vector<double> full(2 * r + 1);
  for (size_t t = 0; t <= r; ++t) full[r + t] = full[r - t] = half[t];
  return full;
}

// The exact Gaussian of docs/BLUR.md "Error model": sampled, taps to |t| <= ceil(6 sigma),
// normalized. Index t + E.
std::vector<double> exact_taps(double sigma) {
  const auto e = size_t(std::ceil(6.0 * sigma));
  std::vector<double> g(2 * e + 1);
  double sum = 0.0;
  for (size_t i = 0; i < g.size(); ++i) {
    const double t = double(i) - double(e);
    g[i] = std::exp(-t * t / (2.0 * sigma * sigma));
    sum += g[i];
  }
  for (double& v : g) v /= sum;
  return g;
}

// ---------------------------------------------------------------------------------------------
// 1-D operators on a line of doubles (clamp-to-edge), the building blocks of the simulations.

// Linear interpolation at continuous texel-centre position p with clamped reads (docs/BLUR.md
// "Notation", bilinear along one axis).
double lerp_at(const std::vector<double>& s, double p) {
  const double f = std::floor(p);
  const double w = p - f;
  const auto n = int64_t(s.size());
  const auto i = int64_t(f);
  const double a = s[size_t(std::clamp<int64_t>(i, 0, n - 1))];
  const double b = s[size_t(std::clamp<int64_t>(i + 1, 0, n - 1))];
  return (1.0 - w) * a + w * b;
}

double map_position(uint32_t x, uint32_t wd, uint32_t ws) { return (x + 0.5) * double(ws) / double(wd) - 0.5; }

// Clamped convolution with symmetric half taps (docs/BLUR.md "Fused level blur", one axis).
std::vector<double> blur_1d(const std::vector<double>& s, const std::vector<double>& half) {
  const auto n = int64_t(s.size());
  const auto r = int64_t(half.size()) - 1;
  std::vector<double> d(s.size(), 0.0);
  for (int64_t x = 0; x < n; ++x) {
    double sum = 0.0;
    for (int64_t t = -r; t <= r; ++t)
      sum += half[size_t(std::abs(t))] * s[size_t(std::clamp<int64_t>(x + t, 0, n - 1))];
    d[size_t(x)] = sum;
  }
  return d;
}

// Centroid and variance of a non-negative 1-D response.
struct Moments {
  double sum = 0, mean = 0, variance = 0;
};

Moments moments(const std::vector<double>& v) {
  Moments m;
  double s1 = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    m.sum += v[i];
    s1 += v[i] * double(i);
  }
  m.mean = s1 / m.sum;
  for (size_t i = 0; i < v.size(); ++i) m.variance += v[i] * (double(i) - m.mean) * (double(i) - m.mean);
  m.variance /= m.sum;
  return m;
}

// Impulse positions of the error model: `centre` plus offsets 0, 1/4, 1/2, 3/4 of the level
// spacing 2^k, rounded down to whole texels and deduplicated (docs/BLUR.md "Error model": worst
// over impulse positions modulo the level spacing).
std::vector<uint32_t> impulse_offsets(uint32_t levels) {
  const uint32_t spacing = 1u << levels;
  std::vector<uint32_t> offsets;
  for (uint32_t m = 0; m < 4; ++m) {
    const uint32_t d = m * spacing / 4;
    if (std::find(offsets.begin(), offsets.end(), d) == offsets.end()) offsets.push_back(d);
  }
  return offsets;
}

// 1-D statistics of one response y against the exact Gaussian g centred at the same impulse:
// ||y||^2, <y, g>, ||g||^2. They give the 2-D error of a separable operator exactly:
// ||kx (x) ky - g (x) g||^2 = |kx|^2 |ky|^2 - 2 <kx,g> <ky,g> + |g|^4.
struct LineStats {
  double yy = 0, yg = 0, gg = 0;
};

LineStats line_stats(const std::vector<double>& y, uint32_t impulse, const std::vector<double>& g) {
  LineStats s;
  const auto e = int64_t(g.size() / 2);
  for (double v : y) s.yy += v * v;
  for (int64_t t = -e; t <= e; ++t) {
    const int64_t i = int64_t(impulse) + t;
    const double gv = g[size_t(t + e)];
    s.gg += gv * gv;
    if (i >= 0 && i < int64_t(y.size())) s.yg += y[size_t(i)] * gv;
  }
  return s;
}

// Worst 2-D relative L2 of a separable operator over all pairs of 1-D impulse phases.
double separable_error(const std::vector<LineStats>& phases) {
  double worst = 0.0;
  for (const LineStats& a : phases) {
    for (const LineStats& b : phases) {
      const double gg = a.gg * b.gg;  // ||g (x) g||^2, the same for every phase
      const double d2 = a.yy * b.yy - 2.0 * a.yg * b.yg + gg;
      worst = std::max(worst, std::sqrt(std::max(0.0, d2) / gg));
    }
  }
  return worst;
}

// Number of levels whose sizes are still at least 1x1 without the max(1, .) of half():
// floor(log2(min(width, height))), at least 1.
uint32_t max_levels(uint32_t width, uint32_t height) {
  uint32_t k = 0;
  for (uint32_t n = std::min(width, height); n >= 2; n /= 2) ++k;
  return std::max(1u, k);
}

// A line of the virtual exact 2:1 chain for k levels that holds `extent` texels: a multiple of
// 2^k, and the impulse centre (a multiple of 2^k) in the middle.
uint32_t virtual_length(uint32_t levels, double extent) {
  const uint32_t spacing = 1u << levels;
  const auto blocks = uint32_t(std::ceil(extent / spacing)) + 2;
  return spacing * (blocks + (blocks & 1u));  // even block count: the centre block boundary is mid-line
}

// ---------------------------------------------------------------------------------------------
// Separable (docs/BLUR.md "separable").

double separable_model_error(double sigma) {
  const std::vector<double> k = full_taps(gaussian_half_taps(sigma, kGaussTruncation));
  const std::vector<double> g = exact_taps(sigma);
  // Shift-invariant: one phase, k centred in a line holding g.
  std::vector<double> y(g.size(), 0.0);
  const size_t e = g.size() / 2, r = k.size() / 2;
  for (size_t i = 0; i < k.size(); ++i) y[e - r + i] = k[i];
  return separable_error({line_stats(y, uint32_t(e), g)});
}

// ---------------------------------------------------------------------------------------------
// Pyramid (docs/BLUR.md "pyramid"): binomial downsample D k times (the last one fused with the
// level blur, B'), the level blur of sigma_k at kGaussTruncation, and the cubic B-spline up.

// The variance (input pixels^2) along an axis of `size` input pixels of the pyramid with `levels`
// levels whose level blur has discrete variance level_var (texels^2 of level k):
// var_down + var_up + s^2 level_var, var_down = sum_(j<k) 0.75 s_j^2 (the binomial's variance in
// texels of its source level j, s_j = size / w_j: 2^j on an exact chain), var_up = s^2 / 3 (the
// B-spline's), s = size / w_k. Also gives s^2. docs/BLUR.md writes var_up = s^2 / 3 - 1/6, by
// analogy with the tent's (s^2 - 1) / 6, but the B-spline magnified by s and sampled at the
// output texels has discrete variance s^2 / 3 exactly (at s = 2, 4, 8; the -1/6 of the tent comes
// from its kinks at the samples), and with -1/6 the measured sigma comes out 2 % high at sigma 2.
double pyramid_axis_variance(uint32_t size, uint32_t levels, double level_var, double* s2_out = nullptr) {
  double var_down = 0.0;
  uint32_t w = size;
  for (uint32_t j = 0; j < levels; ++j) {
    const double s_j = double(size) / w;
    var_down += 0.75 * s_j * s_j;
    w = half_size(w);
  }
  const double s = double(size) / w;
  if (s2_out) *s2_out = s * s;
  return var_down + s * s / 3.0 + s * s * level_var;
}

// The level variance (texels^2 of level k) that makes the variances along an axis add to
// sigma^2: s^2 var(sigma_k) = sigma^2 - var_down - var_up (may be <= 0).
double pyramid_level_variance(double sigma, uint32_t size, uint32_t levels) {
  double s2 = 1.0;
  const double fixed = pyramid_axis_variance(size, levels, 0.0, &s2);
  return (sigma * sigma - fixed) / s2;
}

// Binomial downsample D along one axis: the mean of two linear reads at map(x) +- 0.375 r,
// r = ws / wd (the identity when the sizes match).
std::vector<double> binomial_down_1d(const std::vector<double>& s, uint32_t wd) {
  const auto ws = uint32_t(s.size());
  if (ws == wd) return s;
  const double offset = kBinomialOffset * double(ws) / double(wd);
  std::vector<double> d(wd);
  for (uint32_t x = 0; x < wd; ++x) {
    const double p = map_position(x, wd, ws);
    d[x] = 0.5 * (lerp_at(s, p - offset) + lerp_at(s, p + offset));
  }
  return d;
}

// Uniform cubic B-spline of `s` at continuous position p (docs/BLUR.md "pyramid"): texels
// floor(p) - 1 .. floor(p) + 2, clamped.
double bspline_at(const std::vector<double>& s, double p) {
  const double f = std::floor(p);
  const double t = p - f;
  const double w[4] = {(1 - t) * (1 - t) * (1 - t) / 6.0, (3 * t * t * t - 6 * t * t + 4) / 6.0,
                       (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6.0, t * t * t / 6.0};
  const auto n = int64_t(s.size());
  double sum = 0.0;
  for (int64_t a = 0; a < 4; ++a) sum += w[a] * s[size_t(std::clamp<int64_t>(int64_t(f) - 1 + a, 0, n - 1))];
  return sum;
}

// Worst 2-D error of the impulse responses of the pyramid with `levels` levels and level sigma
// `level_sigma` on the virtual 2:1 chain, against the exact Gaussian of `sigma`.
double pyramid_model_error(double sigma, uint32_t levels, double level_sigma) {
  const std::vector<double> g = exact_taps(sigma);
  const std::vector<double> taps = gaussian_half_taps(level_sigma, kGaussTruncation);
  const double spacing = double(1u << levels);
  const uint32_t n =
      virtual_length(levels, 2.0 * (6.0 * sigma + (radius_of(level_sigma, kGaussTruncation) + 8) * spacing));
  const uint32_t centre = n / 2;
  std::vector<LineStats> phases;
  for (uint32_t d : impulse_offsets(levels)) {
    std::vector<double> v(n, 0.0);
    v[centre + d] = 1.0;
    for (uint32_t j = 1; j <= levels; ++j) v = binomial_down_1d(v, half_size(uint32_t(v.size())));
    v = blur_1d(v, taps);
    std::vector<double> y(n);
    for (uint32_t x = 0; x < n; ++x) y[x] = bspline_at(v, map_position(x, n, uint32_t(v.size())));
    phases.push_back(line_stats(y, centre + d, g));
  }
  return separable_error(phases);
}

// ---------------------------------------------------------------------------------------------
// Dual (docs/BLUR.md "dual"). The x-marginal of the 2-D down tap set (centre 4/8, four diagonals
// (+-o, +-o) 1/8 each) is 1/2 at 0 and 1/4 at +-o; of the up tap set (edges (+-o, 0), (0, +-o)
// 1/12 each, diagonals (+-o/2, +-o/2) 2/12 each) it is 2/12 at 0, 1/12 at +-o and 4/12 at +-o/2.
// Each is applied with linear interpolation at map() + offset, so the interpolation's own spread
// and the map() phase of each level are part of the simulation.

struct Tap1d {
  double offset, weight;
};

// One 1-D dual pass (down or up marginal) from `s` (kLanes impulse responses interleaved) to wd
// texels: sum over taps of weight * linear(s, map(x) + offset), clamped reads.
constexpr size_t kLanes = 4;  // impulse phases simulated together

std::vector<double> apply_1d(const std::vector<double>& s, uint32_t wd, const std::vector<Tap1d>& taps) {
  const auto ws = int64_t(s.size() / kLanes);
  std::vector<double> d(size_t(wd) * kLanes, 0.0);
  for (const Tap1d& t : taps) {
    for (uint32_t x = 0; x < wd; ++x) {
      const double p = map_position(x, wd, uint32_t(ws)) + t.offset;
      const double fl = std::floor(p);
      const double f = p - fl;
      const auto i = int64_t(fl);
      const double* a = &s[size_t(std::clamp<int64_t>(i, 0, ws - 1)) * kLanes];
      const double* b = &s[size_t(std::clamp<int64_t>(i + 1, 0, ws - 1)) * kLanes];
      double* out = &d[size_t(x) * kLanes];
      for (size_t l = 0; l < kLanes; ++l) out[l] += t.weight * (a[l] + f * (b[l] - a[l]));
    }
  }
  return d;
}

// Variance (input pixels^2) of the x-marginal chain of dual(k, o), averaged over the impulse
// phases of impulse_offsets(k). (Checked against the 2-D simulation: the phase-averaged variance
// of the marginal chain equals that of the 2-D response along x.)
double dual_marginal_variance(uint32_t levels, double o) {
  const std::vector<Tap1d> down = {{0.0, 0.5}, {-o, 0.25}, {o, 0.25}};
  const std::vector<Tap1d> up = {
      {0.0, 2.0 / 12}, {-o, 1.0 / 12}, {o, 1.0 / 12}, {-0.5 * o, 4.0 / 12}, {0.5 * o, 4.0 / 12}};
  // Support: the down chain keeps an impulse within o + 1 <= 3 texels of level k; each up pass
  // maps a support of rho texels to 2 (rho + o + 1), so the response stays within about 9 * 2^k
  // input pixels of the impulse: 24 blocks of 2^k hold it with margin.
  const uint32_t n = virtual_length(levels, 24.0 * double(1u << levels));
  const std::vector<uint32_t> offsets = impulse_offsets(levels);
  std::vector<std::vector<double>> chain;
  chain.emplace_back(size_t(n) * kLanes, 0.0);
  for (size_t l = 0; l < kLanes; ++l) chain[0][size_t(n / 2 + offsets[l % offsets.size()]) * kLanes + l] = 1.0;
  for (uint32_t j = 1; j <= levels; ++j) {
    const auto ws = uint32_t(chain.back().size() / kLanes);
    chain.push_back(apply_1d(chain.back(), half_size(ws), down));
  }
  std::vector<double> u = chain.back();
  for (uint32_t j = levels; j-- > 0;) u = apply_1d(u, uint32_t(chain[j].size() / kLanes), up);
  double variance = 0.0;
  for (size_t l = 0; l < kLanes; ++l) {
    std::vector<double> lane(n);
    for (uint32_t x = 0; x < n; ++x) lane[x] = u[size_t(x) * kLanes + l];
    variance += moments(lane).variance / double(kLanes);
  }
  return variance;
}

// A scalar 2-D image for the dual's 2-D error model.
struct Grid {
  uint32_t w = 0, h = 0;
  std::vector<double> v;
};

struct Tap2d {
  double ax, ay, weight;
};

// Bilinear indices and weights along one axis for one tap offset, per destination texel.
struct AxisLerp {
  std::vector<uint32_t> i0, i1;
  std::vector<double> f;
};

AxisLerp axis_lerp(uint32_t nd, uint32_t ns, double offset) {
  AxisLerp a;
  a.i0.resize(nd);
  a.i1.resize(nd);
  a.f.resize(nd);
  for (uint32_t x = 0; x < nd; ++x) {
    const double p = map_position(x, nd, ns) + offset;
    const double fl = std::floor(p);
    const auto i = int64_t(fl);
    a.f[x] = p - fl;
    a.i0[x] = uint32_t(std::clamp<int64_t>(i, 0, int64_t(ns) - 1));
    a.i1[x] = uint32_t(std::clamp<int64_t>(i + 1, 0, int64_t(ns) - 1));
  }
  return a;
}

// One dual pass (docs/BLUR.md "dual": down or up) from `s` to a wd x hd grid: the sum over taps of
// weight * bilinear(s, map(x) + ax, map(y) + ay), clamped reads. Rows outer, taps inner, so an
// output row stays in cache.
Grid dual_pass(const Grid& s, uint32_t wd, uint32_t hd, const std::vector<Tap2d>& taps) {
  std::vector<AxisLerp> ax, ay;
  for (const Tap2d& t : taps) {
    ax.push_back(axis_lerp(wd, s.w, t.ax));
    ay.push_back(axis_lerp(hd, s.h, t.ay));
  }
  Grid d{wd, hd, std::vector<double>(size_t(wd) * hd, 0.0)};
  for (uint32_t y = 0; y < hd; ++y) {
    double* out = &d.v[size_t(y) * wd];
    for (size_t t = 0; t < taps.size(); ++t) {
      const double* r0 = &s.v[size_t(ay[t].i0[y]) * s.w];
      const double* r1 = &s.v[size_t(ay[t].i1[y]) * s.w];
      const double fy = ay[t].f[y], w = taps[t].weight;
      const uint32_t* i0 = ax[t].i0.data();
      const uint32_t* i1 = ax[t].i1.data();
      const double* fx = ax[t].f.data();
      for (uint32_t x = 0; x < wd; ++x) {
        const double top = r0[i0[x]] + fx[x] * (r0[i1[x]] - r0[i0[x]]);
        const double bottom = r1[i0[x]] + fx[x] * (r1[i1[x]] - r1[i0[x]]);
        out[x] += w * (top + fy * (bottom - top));
      }
    }
  }
  return d;
}

// Above this level count the 2-D error is modelled on the scaled problem (see dual_model_error).
constexpr uint32_t kDualModelLevels = 4;

// The 2-D error of dual(k, o) against the exact Gaussian of sigma: the impulse response on a
// virtual exact 2:1 window of about 8 sigma + 32 texels against the separable exact Gaussian
// (outer product), worst relative L2 over impulse positions on the diagonal (c + d, c + d),
// d = 0, 1/4, 1/2, 3/4 of 2^k (the Gaussian beyond 4 sigma + 16 adds nothing measurable).
// The dual filter is not separable (diagonal taps), hence 2-D. For k > 4 the problem is scaled
// down by 2^(k-4) (dual(4, o) against the Gaussian of sigma / 2^(k-4)): the finest levels of a
// deep chain add only pixel-scale detail, and the error decreases slowly with k at a fixed o
// (6.9e-2 at k = 4, 6.8e-2 at k = 6 for o near 1), so the scaled model is slightly pessimistic and
// keeps planning under a few milliseconds.
double dual_model_error(double sigma, uint32_t levels, double o) {
  if (levels > kDualModelLevels) {
    sigma = std::ldexp(sigma, -int(levels - kDualModelLevels));
    levels = kDualModelLevels;
  }
  const std::vector<Tap2d> down = {{0, 0, 0.5}, {-o, -o, 0.125}, {o, -o, 0.125}, {-o, o, 0.125}, {o, o, 0.125}};
  const double h = 0.5 * o;
  const std::vector<Tap2d> up = {{-o, 0, 1.0 / 12},  {o, 0, 1.0 / 12},  {0, -o, 1.0 / 12}, {0, o, 1.0 / 12},
                                 {-h, -h, 2.0 / 12}, {h, -h, 2.0 / 12}, {-h, h, 2.0 / 12}, {h, h, 2.0 / 12}};
  const std::vector<double> g = exact_taps(sigma);
  const auto e = int64_t(g.size() / 2);
  const uint32_t n = virtual_length(levels, 8.0 * sigma + 32.0);
  double worst = 0.0;
  for (uint32_t d : impulse_offsets(levels)) {
    const uint32_t c = n / 2 + d;
    std::vector<Grid> chain;
    chain.push_back(Grid{n, n, std::vector<double>(size_t(n) * n, 0.0)});
    chain[0].v[size_t(c) * n + c] = 1.0;
    for (uint32_t j = 1; j <= levels; ++j)
      chain.push_back(dual_pass(chain.back(), half_size(chain.back().w), half_size(chain.back().h), down));
    Grid u = chain.back();
    for (uint32_t j = levels; j-- > 0;) u = dual_pass(u, chain[j].w, chain[j].h, up);
    double diff2 = 0.0, gg = 0.0;
    for (uint32_t y = 0; y < n; ++y) {
      const int64_t ty = int64_t(y) - int64_t(c);
      const double gy = std::abs(ty) <= e ? g[size_t(ty + e)] : 0.0;
      for (uint32_t x = 0; x < n; ++x) {
        const int64_t tx = int64_t(x) - int64_t(c);
        const double gv = std::abs(tx) <= e ? gy * g[size_t(tx + e)] : 0.0;
        const double v = u.v[size_t(y) * n + x];
        diff2 += (v - gv) * (v - gv);
        gg += gv * gv;
      }
    }
    worst = std::max(worst, std::sqrt(diff2 / gg));
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// Cost (calibrated later on the H100): bytes / 2.5e6 + 3 * dispatches + texel_taps / 2e7, with
// 8 bytes per RGBA16F texel read or written, each image read once and written once.

double cost_of(double bytes, uint32_t dispatches, double texel_taps) {
  return bytes / kBytesPerUs + kUsPerDispatch * dispatches + texel_taps / kTapsPerUs;
}

double texels(uint32_t w, uint32_t h) { return double(w) * double(h); }

double separable_cost(uint32_t radius, uint32_t width, uint32_t height, bool linear) {
  const double full = texels(width, height);
  const double taps = 2.0 * (2.0 * radius + 1.0);
  if (linear)  // two passes, each output fetches R + 1 bilinear pairs per direction
    return cost_of(4.0 * kBytesPerTexel * full, 2, full * 2.0 * (radius + 1.0));
  if (radius > kFusedMaxRadius)  // two line passes through a scratch image
    return cost_of(4.0 * kBytesPerTexel * full, 2, full * taps);
  return cost_of(2.0 * kBytesPerTexel * full, 1, full * taps);
}

// Pyramid: D reads four bilinear texels (16 taps) per output at levels 1..k (level k's D is fused
// into the blur's load); the B-spline up reads 16 texels per output.
double pyramid_cost(uint32_t levels, uint32_t level_radius, uint32_t width, uint32_t height) {
  const double full = texels(width, height);
  double bytes = 2.0 * kBytesPerTexel * full;  // input read, output written
  double taps = 16.0 * full;                   // cubic B-spline upsample
  uint32_t w = width, h = height;
  for (uint32_t j = 1; j <= levels; ++j) {
    w = half_size(w);
    h = half_size(h);
    bytes += 2.0 * kBytesPerTexel * texels(w, h);  // written once, read once
    taps += texels(w, h) * (16.0 + (j == levels ? 2.0 * (2.0 * level_radius + 1.0) : 0.0));
  }
  return cost_of(bytes, levels + 1, taps);
}

double dual_cost(uint32_t levels, uint32_t width, uint32_t height) {
  const double full = texels(width, height);
  double bytes = 2.0 * kBytesPerTexel * full;
  double taps = full * 8.0 * 4.0;  // the last up pass writes the output
  uint32_t w = width, h = height;
  for (uint32_t j = 1; j <= levels; ++j) {
    w = half_size(w);
    h = half_size(h);
    const double level = texels(w, h);
    bytes += 2.0 * kBytesPerTexel * level * (j < levels ? 2.0 : 1.0);  // D_j and, below k, U_j
    taps += level * 5.0 * 4.0 + (j < levels ? level * 8.0 * 4.0 : 0.0);
  }
  return cost_of(bytes, 2 * levels, taps);
}

void check_request(double sigma_px, uint32_t width, uint32_t height) {
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px)) throw std::invalid_argument("blur_plan: sigma_px must be > 0");
  if (width == 0 || height == 0) throw std::invalid_argument("blur_plan: empty image size");
}

Plan plan_separable(Method method, double sigma_px, uint32_t width, uint32_t height) {
  Plan p;
  p.method = method;
  p.sigma_px = sigma_px;
  p.radius = radius_of(sigma_px, kGaussTruncation);
  p.effective_sigma_px = std::sqrt(discrete_variance(sigma_px, kGaussTruncation));
  // separable_linear: the same taps in exact arithmetic; the sampler's sub-texel weight rounding
  // is not modelled (docs/BLUR.md "separable, linear sampling": measured, not predicted).
  p.expected_relative_l2 = separable_model_error(sigma_px);
  p.cost = separable_cost(p.radius, width, height, method == Method::separable_linear);
  return p;
}

// docs/BLUR.md "pyramid": the largest k whose modelled error meets the bound with
// 0.5 <= sigma_k <= 3. Without any, the smallest error among the k with sigma_k in range; with no
// k in range (tiny sigma, or an image too small for a large one), the k whose sigma_k is nearest
// the range, sigma_k clamped into it (the error model then shows what that costs).
Plan plan_pyramid(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage* storage) {
  Plan best;
  bool have = false, best_meets = false, best_in_range = false;
  double best_distance = std::numeric_limits<double>::infinity();
  const uint32_t k_max = max_levels(width, height);
  for (uint32_t k = 1; k <= k_max; ++k) {
    // One level sigma for both axes: the mean of the two axes' required level variances (they are
    // equal on exact 2:1 chains).
    const double needed_var =
        0.5 * (pyramid_level_variance(sigma_px, width, k) + pyramid_level_variance(sigma_px, height, k));
    const double wanted = sigma_for_variance(needed_var, kGaussTruncation);
    const bool in_range = wanted >= kMinLevelSigma && wanted <= kMaxLevelSigma;
    const double distance =
        in_range ? 0.0 : (wanted < kMinLevelSigma ? kMinLevelSigma - wanted : wanted - kMaxLevelSigma);
    if (!in_range && (best_in_range || distance >= best_distance)) {
      if (wanted < kMinLevelSigma) break;  // sigma_k only shrinks with k
      continue;
    }
    const double level_sigma = std::clamp(wanted, kMinLevelSigma, kMaxLevelSigma);
    const double error = pyramid_model_error(sigma_px, k, level_sigma);
    Plan p;
    p.method = Method::pyramid;
    p.sigma_px = sigma_px;
    p.levels = k;
    p.level_sigma = level_sigma;
    p.radius = radius_of(level_sigma, kGaussTruncation);
    // The variance bookkeeping (sigma itself unless sigma_k is clamped), the mean of the two axes.
    // It equals the variance of the modelled impulse responses about the impulse averaged over all
    // positions (checked to 1e-4 for k <= 4); a single impulse measured about its own centroid may
    // show a little less, as the downsample moves centroids.
    const double level_var = discrete_variance(level_sigma, kGaussTruncation);
    p.effective_sigma_px =
        std::sqrt(0.5 * (pyramid_axis_variance(width, k, level_var) + pyramid_axis_variance(height, k, level_var)));
    p.expected_relative_l2 = error;
    if (storage) p.expected_relative_l2 += rounding_bound(p, *storage);
    const double error_total = p.expected_relative_l2;
    p.cost = pyramid_cost(k, p.radius, width, height);
    const bool meets = in_range && error_total <= max_relative_l2;
    if (!have || meets || (!best_meets && in_range && (!best_in_range || error < best.expected_relative_l2)) ||
        (!best_in_range && !in_range && distance < best_distance)) {
      best = p;
      best_meets = meets;
      best_in_range = in_range;
      best_distance = distance;
      have = true;
    }
    if (wanted < kMinLevelSigma) break;
  }
  return best;
}

// Solves sigma(k, o) = sigma_px for o in [a, b] (sigma(k, a) <= sigma_px <= sigma(k, b)) by the
// Illinois variant of regula falsi on the variance, which is close to quadratic in o.
double solve_dual_offset(uint32_t levels, double sigma_px, double a, double fa, double b, double fb) {
  const double target = sigma_px * sigma_px;
  fa -= target;
  fb -= target;
  int side = 0;
  for (int it = 0; it < 40 && b - a > 1e-9; ++it) {
    const double c = std::clamp((a * fb - b * fa) / (fb - fa), a, b);
    const double fc = dual_marginal_variance(levels, c) - target;
    if (fc == 0.0) return c;
    if ((fc < 0.0) == (fa < 0.0)) {
      a = c;
      fa = fc;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = c;
      fb = fc;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return std::abs(fa) < std::abs(fb) ? a : b;
}

// docs/BLUR.md "dual": the k whose range [sigma(k, 0.5), sigma(k, 2)] holds sigma_px. Ranges
// grow about 2x per level and span 3x, so one or two k hold any sigma above sigma(1, 0.5) ~ 0.96.
// The doc asks for the o closest to 1; the 2-D model shows the error is not symmetric in o
// (about 0.3 at o = 0.7 but 0.2 at o = 1.8, 0.05 at o = 1), so of the holding k the one with the
// smaller modelled error is taken, which is the o closest to 1 whenever o is within [0.85, 1.3].
// Below every range: k = 1 and o = 0.5 (the smallest dual blur); above every range allowed by the
// image size: the largest k with o = 2.
Plan plan_dual(double sigma_px, uint32_t width, uint32_t height) {
  const uint32_t k_max = max_levels(width, height);
  Plan p;
  p.method = Method::dual;
  p.sigma_px = sigma_px;
  p.levels = 1;
  p.dual_offset = kDualMinOffset;
  bool have = false;
  for (uint32_t k = 1; k <= k_max; ++k) {
    const double var_lo = dual_marginal_variance(k, kDualMinOffset);
    if (std::sqrt(var_lo) > sigma_px) break;  // later ranges start higher still
    const double var_hi = dual_marginal_variance(k, kDualMaxOffset);
    if (std::sqrt(var_hi) < sigma_px) {  // above this range: the largest blur so far
      p.levels = k;
      p.dual_offset = kDualMaxOffset;
      continue;
    }
    const double o = solve_dual_offset(k, sigma_px, kDualMinOffset, var_lo, kDualMaxOffset, var_hi);
    const double error = dual_model_error(sigma_px, k, o);
    if (!have || error < p.expected_relative_l2) {
      p.levels = k;
      p.dual_offset = o;
      p.expected_relative_l2 = error;
      have = true;
    }
  }
  if (!have) p.expected_relative_l2 = dual_model_error(sigma_px, p.levels, p.dual_offset);
  p.effective_sigma_px = std::sqrt(dual_marginal_variance(p.levels, p.dual_offset));
  p.cost = dual_cost(p.levels, width, height);
  return p;
}

}  // namespace

// docs/BLUR.md "Gaussian taps from sigma".
std::vector<double> gaussian_half_taps(double sigma, double truncation) {
  if (sigma == 0.0) return {1.0};
  if (!(sigma > 0.0) || !std::isfinite(sigma))
    throw std::invalid_argument("gaussian_half_taps: sigma must be finite and >= 0");
  if (!(truncation > 0.0) || !std::isfinite(truncation))
    throw std::invalid_argument("gaussian_half_taps: truncation must be finite and > 0");
  const uint32_t r = radius_of(sigma, truncation);
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

namespace {

Plan plan_with(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2,
               const Storage* storage) {
  check_request(sigma_px, width, height);
  Plan p;
  switch (method) {
    case Method::separable:
    case Method::separable_linear:
      p = plan_separable(method, sigma_px, width, height);
      break;
    case Method::pyramid:
      return plan_pyramid(sigma_px, width, height, max_relative_l2, storage);  // adds the rounding itself
    case Method::dual:
      p = plan_dual(sigma_px, width, height);
      break;
    default:
      throw std::invalid_argument("plan_method: unknown method");
  }
  if (storage) p.expected_relative_l2 += rounding_bound(p, *storage);
  return p;
}

// The cheapest of separable, pyramid and dual whose expected error is <= max_relative_l2.
// Separable always qualifies (the fallback): if even its error misses a very small bound, it is
// returned with that error in expected_relative_l2.
Plan auto_with(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage* storage) {
  check_request(sigma_px, width, height);
  Plan best = plan_with(Method::separable, sigma_px, width, height, max_relative_l2, storage);
  for (Method m : {Method::pyramid, Method::dual}) {
    const Plan p = plan_with(m, sigma_px, width, height, max_relative_l2, storage);
    if (p.expected_relative_l2 <= max_relative_l2 && p.cost < best.cost) best = p;
  }
  return best;
}

}  // namespace

double store_unit(uint32_t mantissa_bits) { return mantissa_bits >= 23 ? 0.0 : std::ldexp(1.0, -int(mantissa_bits)); }

// docs/BLUR.md "Error model": the stores and multiply-adds on each method's path (src/blur/blur.cpp
// GaussianBlur::Impl::make() records the same steps).
double rounding_bound(const Plan& plan, const Storage& st) {
  const double half = store_unit(10);
  const double arith = std::ldexp(1.0, -24);
  const double line_taps = 2.0 * (2.0 * plan.radius + 1.0);  // both passes of a separable blur
  double u = 0.0;
  switch (plan.method) {
    case Method::separable:
      if (plan.radius <= kFusedMaxRadius)  // fused: shared copies in fp16 when the output is RGBA16F
        u = st.output_unit + (st.output_half ? 2.0 * half : 0.0) + arith * line_taps;
      else  // two line passes through a scratch image
        u = st.level_unit + st.output_unit + arith * line_taps;
      break;
    case Method::separable_linear:
      u = st.level_unit + st.output_unit + 2.0 * 2.0 * std::ldexp(1.0, -int(st.sub_texel_bits)) +
          arith * 2.0 * (plan.radius + 2.0);
      break;
    case Method::pyramid:  // k levels, the fused kernel's copies at the last, the B-spline output
      u = plan.levels * st.level_unit + (st.level_half ? 2.0 * half : 0.0) + st.output_unit +
          arith * (16.0 * plan.levels + line_taps + 16.0);
      break;
    case Method::dual:  // k down, k - 1 up into levels, the last up into the output
      u = (2.0 * plan.levels - 1.0) * st.level_unit + st.output_unit + arith * 52.0 * plan.levels;
      break;
  }
  return u * (1.0 + plan.expected_relative_l2);
}

Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2) {
  return plan_with(method, sigma_px, width, height, max_relative_l2, nullptr);
}
Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2,
                 const Storage& storage) {
  return plan_with(method, sigma_px, width, height, max_relative_l2, &storage);
}
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2) {
  return auto_with(sigma_px, width, height, max_relative_l2, nullptr);
}
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage& storage) {
  return auto_with(sigma_px, width, height, max_relative_l2, &storage);
}

}  // namespace glint::blur_plan
