// The plans of GaussianBlur's methods for a requested sigma (docs/BLUR.md "Gaussian blur of any
// sigma"): the level count and level sigma of the pyramid, the level count and offset of the dual,
// and `auto`, the cheapest plan by a device's CostModel whose expected error meets the bound. The
// pyramid and dual run on padded chains (blur_border.cpp) whose levels are exact halves, so their
// variance bookkeeping is that of an exact 2:1 chain at every image size.
#include "blur/blur_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "blur/blur_plan_internal.h"

namespace glint::blur_plan {

using namespace detail;

namespace {

void check_request(double sigma_px, uint32_t width, uint32_t height) {
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px)) throw std::invalid_argument("blur_plan: sigma_px must be > 0");
  if (width == 0 || height == 0) throw std::invalid_argument("blur_plan: empty image size");
}

// The level count the pyramid and dual may use: their chains run on the padded extent, which is
// at least the input plus the Gaussian's reach on each side, so a small image may still take the
// levels a large sigma needs.
uint32_t chain_levels(double sigma_px, uint32_t width, uint32_t height) {
  const auto reach = uint32_t(std::min(1.0e6, std::ceil(8.0 * sigma_px)));
  return max_levels(width + reach, height + reach);
}

Plan plan_separable(Method method, double sigma_px, uint32_t width, uint32_t height, const CostModel& model) {
  Plan p;
  p.method = method;
  p.sigma_px = sigma_px;
  p.radius = radius_of(sigma_px, kGaussTruncation);
  p.effective_sigma_px = std::sqrt(discrete_variance(sigma_px, kGaussTruncation));
  // separable_linear: the same taps in exact arithmetic; the sampler's sub-texel weight rounding
  // is not modelled (docs/BLUR.md "separable, linear sampling": measured, not predicted).
  p.expected_relative_l2 = separable_model_error(sigma_px);
  p.padding = padding_of(p, width, height);
  p.work = separable_work(p.radius, width, height, method == Method::separable_linear);
  p.cost = model.estimate_us(p.work);
  return p;
}

// docs/BLUR.md "pyramid": the largest k whose modelled error meets the bound with
// 0.5 <= sigma_k <= 3. Without any, the smallest error among the k with sigma_k in range; with no
// k in range (tiny sigma, or an image too small for a large one), the k whose sigma_k is nearest
// the range, sigma_k clamped into it (the error model then shows what that costs).
Plan plan_pyramid(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage* storage,
                  const CostModel& model) {
  Plan best;
  bool have = false, best_meets = false, best_in_range = false;
  double best_distance = std::numeric_limits<double>::infinity();
  const uint32_t k_max = chain_levels(sigma_px, width, height);
  for (uint32_t k = 1; k <= k_max; ++k) {
    // The padded chain is an exact 2:1 chain along both axes (one of 2^k texels stands for it).
    const double needed_var = pyramid_level_variance(sigma_px, 1u << k, k);
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
    p.effective_sigma_px = std::sqrt(pyramid_axis_variance(1u << k, k, level_var));
    p.expected_relative_l2 = error;
    if (storage) {
      p.expected_relative_l2 += rounding_bound(p, *storage);
      // fp16 levels: where the last level's fp16 shared copies would break the bound, keep them
      // in fp32 (the level is at most a quarter of the input's texels; its shared bytes double).
      if (storage->level_half && p.expected_relative_l2 > max_relative_l2) {
        p.fp32_shared = true;
        p.expected_relative_l2 = error + rounding_bound(p, *storage);
      }
    }
    const double error_total = p.expected_relative_l2;
    p.padding = padding_of(p, width, height);
    p.work = pyramid_work(k, p.radius, width, height, p.padding, p.fp32_shared);
    p.cost = model.estimate_us(p.work);
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
Plan plan_dual(double sigma_px, uint32_t width, uint32_t height, const CostModel& model) {
  const uint32_t k_max = chain_levels(sigma_px, width, height);
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
  p.padding = padding_of(p, width, height);
  p.work = dual_work(p.levels, width, height, p.padding);
  p.cost = model.estimate_us(p.work);
  return p;
}

Plan plan_with(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2,
               const Storage* storage, const CostModel& model) {
  check_request(sigma_px, width, height);
  Plan p;
  switch (method) {
    case Method::separable:
    case Method::separable_linear:
      p = plan_separable(method, sigma_px, width, height, model);
      break;
    case Method::pyramid:
      return plan_pyramid(sigma_px, width, height, max_relative_l2, storage, model);  // adds the rounding itself
    case Method::dual:
      p = plan_dual(sigma_px, width, height, model);
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
Plan auto_with(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage* storage,
               const CostModel& model) {
  check_request(sigma_px, width, height);
  Plan best = plan_with(Method::separable, sigma_px, width, height, max_relative_l2, storage, model);
  for (Method m : {Method::pyramid, Method::dual}) {
    const Plan p = plan_with(m, sigma_px, width, height, max_relative_l2, storage, model);
    if (p.expected_relative_l2 <= max_relative_l2 && p.cost < best.cost) best = p;
  }
  return best;
}

}  // namespace

Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2) {
  return plan_with(method, sigma_px, width, height, max_relative_l2, nullptr, CostModel{});
}
Plan plan_method(Method method, double sigma_px, uint32_t width, uint32_t height, double max_relative_l2,
                 const Storage& storage) {
  return plan_with(method, sigma_px, width, height, max_relative_l2, &storage, CostModel{});
}
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const CostModel& model) {
  return auto_with(sigma_px, width, height, max_relative_l2, nullptr, model);
}
Plan plan_auto(double sigma_px, uint32_t width, uint32_t height, double max_relative_l2, const Storage& storage,
               const CostModel& model) {
  return auto_with(sigma_px, width, height, max_relative_l2, &storage, model);
}

}  // namespace glint::blur_plan
