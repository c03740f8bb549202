// Bloom's configuration: its checks, the names of its options and the level chain it builds
// (docs/BLOOM.md "Mip chain"). bloom.cpp records the passes.
#include <glint/bloom.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bloom/shaders/bloom_params.h"
#include "core/check.h"

namespace glint {

using detail::check_enum;
using detail::check_range;
using detail::concat;

void BloomConfig::validate() const {
  check_range("BloomConfig::threshold", threshold, 0.0, 65504.0);
  check_range("BloomConfig::soft_knee", soft_knee, 0.0, 1.0);
  check_range("BloomConfig::intensity", intensity, 0.0, 100.0);
  check_range("BloomConfig::iterations", iterations, 1, 8);
  check_range("BloomConfig::radius", radius, 0.25, 4.0);
  check_range("BloomConfig::max_brightness", max_brightness, 1e-3, 8000.0);
  check_enum("BloomConfig::filter", filter, GLINT_BLOOM_GAUSS9 + 1, "BloomFilter", "cod13, dual, gauss9");
  if (level0_height != 0 && (level0_height < 8 || level0_height > 16384)) {
    throw Error(ErrorCode::invalid_argument,
                concat("BloomConfig::level0_height = ", level0_height, " is out of range: accepted 0 or 8 to 16384"));
  }
  check_enum("BloomConfig::firefly_guard", firefly_guard, 3, "FireflyGuard", "off, karis, karis_smooth");
  check_enum("BloomConfig::precision", precision, 2, "Precision", "fp16, fp32");
}

const char* bloom_filter_name(BloomFilter filter) {
  switch (filter) {
    case BloomFilter::cod13:
      return "cod13";
    case BloomFilter::dual:
      return "dual";
    case BloomFilter::gauss9:
      return "gauss9";
  }
  return "?";
}

const char* firefly_guard_name(FireflyGuard guard) {
  switch (guard) {
    case FireflyGuard::off:
      return "off";
    case FireflyGuard::karis:
      return "karis";
    case FireflyGuard::karis_smooth:
      return "karis_smooth";
  }
  return "?";
}

namespace {

// docs/BLOOM.md "Mip chain": with level0_height > 0, halve while the half is still taller than the
// target, then one step to the target height, its width the input's aspect kept within [w/2, w] of
// the last image so that every step has a ratio of 1 to 2 (plus one texel) per axis.
struct FirstSteps {
  std::vector<LevelSize> pre;
  LevelSize level0;
};

FirstSteps first_steps(VkExtent2D input, uint32_t level0_height) {
  FirstSteps f;
  if (level0_height == 0) {
    f.level0 = {std::max(1u, input.width / 2), std::max(1u, input.height / 2)};
    return f;
  }
  const uint32_t h0 = std::min(level0_height, input.height);
  LevelSize cur{input.width, input.height};
  while (cur.height / 2 > h0) {
    cur = {std::max(1u, cur.width / 2), cur.height / 2};
    f.pre.push_back(cur);
  }
  const auto aspect_width = static_cast<uint32_t>(std::llround(double(input.width) * h0 / input.height));
  f.level0 = {std::clamp(aspect_width, std::max(1u, cur.width / 2), cur.width), h0};
  return f;
}

}  // namespace

std::vector<LevelSize> bloom_pre_levels(VkExtent2D input, uint32_t level0_height) {
  return first_steps(input, level0_height).pre;
}

std::vector<LevelSize> bloom_mip_chain(VkExtent2D input, uint32_t iterations, uint32_t level0_height) {
  std::vector<LevelSize> chain;
  LevelSize level = first_steps(input, level0_height).level0;
  chain.push_back(level);  // level 0 always exists, even when it is under 2 pixels
  while (chain.size() < iterations) {
    LevelSize next{std::max(1u, level.width / 2), std::max(1u, level.height / 2)};
    if (next.width < 2 || next.height < 2) break;
    chain.push_back(next);
    level = next;
  }
  return chain;
}

}  // namespace glint
