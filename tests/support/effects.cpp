#include "support/effects.h"

#include <algorithm>
#include <cmath>

#include "bloom/shaders/bloom_params.h"
#include "reference/blur_reference.h"
#include "support/gpu_test.h"

namespace glint::test {

CpuImage run_bloom_once(const BloomConfig& config, const CpuImage& input, VkFormat format) {
  auto in = make_image(input, format);
  auto out = make_poisoned({input.width, input.height}, format);
  Bloom bloom(context(), config);
  context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
  return detail::download(context(), out.state);
}

// docs/BLOOM.md, per axis, in full-resolution pixels, with T(k) = W / w(k) the size of a level-k
// texel (T(-1) = 1) and distances measured between texel centres in texel-centre coordinates:
// - Down(k-1 -> k) reads source texels within D of the mapped position p, which is the centre of
//   the destination texel: cod13 taps reach +-2 and bilinear adds 1 (D = 3); dual +-1 + 1 (D = 2);
//   gauss9's area average reaches ratio/2 + 1/2 with ratio = w(k-1) / w(k). In pixels: D * T(k-1).
// - gauss9 then blurs level k with taps at up to 4 * radius texels, read linearly: (4 radius + 1) T(k).
// - Up(k+1 -> k) and the composite read the smaller image at p + radius * offset with bilinear
//   taps: cod13 and dual offsets reach 1 (radius + 1 texels), gauss9 only bilinear(p) (1 texel):
//   R * T(k+1), and R * T(0) for the composite.
// A change at the input reaches level N-1 through every downsample and comes back to the output
// through every upsample, so the footprint is the sum of all of these; +1 px for fp rounding of p.
uint32_t bloom_footprint_px(VkExtent2D extent, const BloomConfig& config) {
  // level0_height's pre-levels only add their downsample reach (no blur, no upsample).
  const auto pre = bloom_pre_levels(extent, config.level0_height);
  const auto chain = bloom_mip_chain(extent, config.iterations, config.level0_height);
  double worst = 0.0;
  for (int axis = 0; axis < 2; ++axis) {
    const double full = axis == 0 ? extent.width : extent.height;
    double prev_size = full, prev_texel = 1.0, reach = 0.0;
    // karis_smooth filters the source with an 11-tap binomial before the first downsample.
    if (config.firefly_guard == FireflyGuard::karis_smooth) reach += GLINT_BLOOM_SMOOTH_RADIUS;
    auto down_reach = [&](const LevelSize& l) {
      const double size = axis == 0 ? l.width : l.height;
      const double ratio = prev_size / size;
      double down = 3.0;
      if (config.filter == BloomFilter::dual) down = 2.0;
      if (config.filter == BloomFilter::gauss9) down = ratio / 2.0 + 0.5;
      reach += down * prev_texel;
      prev_size = size;
      prev_texel = full / size;
    };
    for (const LevelSize& l : pre) down_reach(l);
    for (const LevelSize& l : chain) {
      const double size = axis == 0 ? l.width : l.height;
      const double texel = full / size;
      down_reach(l);
      if (config.filter == BloomFilter::gauss9) reach += (4.0 * config.radius + 1.0) * texel;
      const double up = config.filter == BloomFilter::gauss9 ? 1.0 : config.radius + 1.0;
      reach += up * texel;
    }
    worst = std::max(worst, reach);
  }
  return static_cast<uint32_t>(std::ceil(worst)) + 1;
}

// docs/BLUR.md, in input pixels, per method (+1 px for fp rounding of mapped positions):
// - separable: the taps reach R = radius pixels.
// - pyramid with k levels: each binomial downsample j reads source texels within 1.75 texels of
//   level j-1 of the destination texel's centre (bilinear taps at +-0.75 around it), i.e. 2 texels
//   of 2^(j-1) px; the level blur reaches ceil(4 sigma_k) texels of 2^k px; the cubic B-spline
//   reads 2 texels of 2^k px on each side.
// - dual with k levels and offset o: a downsample reads bilinear taps at +-o around the mapped
//   centre (o + 1.5 texels of its source level), an upsample at +-o (o + 1.5 texels of its
//   smaller source level); a change travels down every level and back up.
uint32_t gauss_footprint_px(const BlurChoice& c) {
  double reach = 0.0;
  if (c.method == BlurMethod::separable) {
    reach = c.radius;
  } else if (c.method == BlurMethod::pyramid) {
    const double s = std::ldexp(1.0, static_cast<int>(c.levels));
    reach = 2.0 * (s - 1.0) + (std::ceil(4.0 * c.level_sigma) + 2.0) * s;
  } else {
    for (uint32_t j = 1; j <= c.levels; ++j) {
      reach +=
          (c.dual_offset + 1.5) * (std::ldexp(1.0, static_cast<int>(j) - 1) + std::ldexp(1.0, static_cast<int>(j)));
    }
  }
  return static_cast<uint32_t>(std::ceil(reach)) + 1;
}

namespace {

CpuImage run_gauss_once(const GaussianBlurConfig& config, const CpuImage& input, VkFormat format) {
  auto in = make_image(input, format);
  auto out = make_poisoned({input.width, input.height}, format);
  GaussianBlur blur(context(), config);
  context().run_once([&](VkCommandBuffer cmd) { blur.record(cmd, in.state, out.state); });
  return detail::download(context(), out.state);
}

// The plan a GaussianBlur makes for `extent`, without recording anything.
BlurChoice plan_for(const GaussianBlurConfig& config, VkExtent2D extent) {
  GaussianBlur blur(context(), config);
  blur.prepare(extent);
  return blur.choice();
}

}  // namespace

std::vector<ImageEffect> image_effects() {
  std::vector<ImageEffect> effects;
  const std::pair<const char*, BloomFilter> filters[] = {
      {"bloom cod13", BloomFilter::cod13}, {"bloom dual", BloomFilter::dual}, {"bloom gauss9", BloomFilter::gauss9}};
  for (const auto& [name, filter] : filters) {
    BloomConfig config;
    config.filter = filter;
    config.precision = Precision::fp32;  // the reference tolerance of bloom_test for fp32 levels
    ImageEffect e;
    e.name = name;
    e.run = [config](const CpuImage& input, VkFormat format) { return run_bloom_once(config, input, format); };
    e.footprint_px = [config](VkExtent2D extent) { return bloom_footprint_px(extent, config); };
    e.reference = [config](const CpuImage& input) { return reference::bloom(input, config); };
    e.tolerance = 1e-3;
    e.clamp = config.max_brightness;
    effects.push_back(std::move(e));
  }
  const std::tuple<const char*, BlurMethod, float> blurs[] = {{"gauss separable sigma 2", BlurMethod::separable, 2.0f},
                                                              {"gauss pyramid sigma 8", BlurMethod::pyramid, 8.0f},
                                                              {"gauss dual sigma 6", BlurMethod::dual, 6.0f}};
  for (const auto& [name, method, sigma] : blurs) {
    GaussianBlurConfig config;
    config.method = method;
    config.sigma_px = sigma;
    config.precision = Precision::fp32;
    ImageEffect e;
    e.name = name;
    e.run = [config](const CpuImage& input, VkFormat format) { return run_gauss_once(config, input, format); };
    e.footprint_px = [config](VkExtent2D extent) { return gauss_footprint_px(plan_for(config, extent)); };
    e.reference = [config](const CpuImage& input) {
      const BlurChoice c = plan_for(config, {input.width, input.height});
      blur_plan::Plan p;
      p.sigma_px = config.sigma_px;
      p.radius = c.radius;
      p.levels = c.levels;
      p.level_sigma = c.level_sigma;
      p.dual_offset = c.dual_offset;
      if (c.method == BlurMethod::pyramid) {
        p.method = blur_plan::Method::pyramid;
        return reference::gaussian_pyramid(input, p, false, reference::kBlurMaxValueFp32);
      }
      if (c.method == BlurMethod::dual) {
        p.method = blur_plan::Method::dual;
        return reference::gaussian_dual(input, p, false, reference::kBlurMaxValueFp32);
      }
      return reference::gaussian_separable(input, config.sigma_px, false, reference::kBlurMaxValueFp32);
    };
    // fp32 storage: fp32 arithmetic plus positions near 16384 carry ulp(x) ~ 1e-3 texel (blur_test).
    e.tolerance = 2e-3;
    e.clamp = 0.0f;  // no fp16 intermediates in these entries
    effects.push_back(std::move(e));
  }
  return effects;
}

}  // namespace glint::test
