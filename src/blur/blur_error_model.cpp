// The modelled error of each GaussianBlur method (docs/BLUR.md "Error model and metrics"): each
// method's impulse response simulated in float64 on a virtual exact 2:1 chain (a line or window
// whose length is a multiple of 2^k and large enough that no clamp is reached), against the exact
// Gaussian, so that planning costs the same at every image size. The pyramid and dual chains run
// padded (blur_border.cpp) so that at every output texel of the image they are this shift-invariant
// chain, applied to the clamp-to-edge extension of the input: the model holds over the whole
// image, borders included. Also the rounding bound of every store on each method's path.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <utility>

#include "blur/blur_plan.h"
#include "blur/blur_plan_internal.h"

namespace glint::blur_plan {
namespace detail {
namespace {

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

// A line of the virtual exact 2:1 chain for k levels that holds `extent` texels: a multiple of
// 2^k, and the impulse centre (a multiple of 2^k) in the middle.
uint32_t virtual_length(uint32_t levels, double extent) {
  const uint32_t spacing = 1u << levels;
  const auto blocks = uint32_t(std::ceil(extent / spacing)) + 2;
  return spacing * (blocks + (blocks & 1u));  // even block count: the centre block boundary is mid-line
}

}  // namespace

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
double pyramid_axis_variance(uint32_t size, uint32_t levels, double level_var, double* s2_out) {
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

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

namespace {
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

}  // namespace

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

}  // namespace detail

double store_unit(uint32_t mantissa_bits) { return mantissa_bits >= 23 ? 0.0 : std::ldexp(1.0, -int(mantissa_bits)); }

// docs/BLUR.md "Error model": the stores and multiply-adds on each method's path (src/blur/gaussian_blur.cpp
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
    case Method::pyramid:
      // k levels, the last one's blur (a store of its own), one shared copy of that blur, the
      // B-spline output. The blur reads the stored level, which its first shared copy (fp16 where
      // the levels are) holds exactly; only its second copy, the horizontal pass's sums, rounds.
      u = (plan.levels + 1.0) * st.level_unit + (st.level_half && !plan.fp32_shared ? half : 0.0) + st.output_unit +
          arith * (16.0 * plan.levels + line_taps + 16.0);
      break;
    case Method::dual:  // k down, k - 1 up into levels, the last up into the output
      u = (2.0 * plan.levels - 1.0) * st.level_unit + st.output_unit + arith * 52.0 * plan.levels;
      break;
  }
  return u * (1.0 + plan.expected_relative_l2);
}

}  // namespace glint::blur_plan
