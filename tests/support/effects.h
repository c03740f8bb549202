// The effects that the robustness tests (stability_test.cpp, api_errors_test.cpp) loop over.
// A new image effect joins every table-driven robustness test by adding entries to image_effects()
// in effects.cpp: a name, a run function, its footprint (derived from its docs) and its reference.
#pragma once

#include <glint/bloom.h>
#include <glint/blur.h>

#include <functional>
#include <string>
#include <vector>

#include "core/cpu_image.h"
#include "reference/bloom_reference.h"

namespace glint::test {

/// One image-to-image effect with a fixed configuration, as the robustness tests see it.
struct ImageEffect {
  std::string name;  //!< "bloom cod13", ...
  /// Makes the effect, uploads `input` in `format`, records it into a fresh output of the same
  /// extent and format (poisoned with NaN) on the test context and reads the output back. Each
  /// call makes its own effect object and images, so views are never reused across calls.
  std::function<CpuImage(const CpuImage& input, VkFormat format)> run;
  /// The farthest (Chebyshev distance, px) that one input pixel can change an output pixel at
  /// this extent. Derived from the effect's documented taps, not measured.
  std::function<uint32_t(VkExtent2D extent)> footprint_px;
  /// The float64 reference of the whole output for `input`.
  std::function<reference::DoubleImage(const CpuImage& input)> reference;
  double tolerance = 1e-3;  //!< relative L2 against the reference with RGBA32F input and output
  /// The largest input value the effect may clamp to before fp16 intermediates: inputs above it
  /// must not overflow them. 0 if the effect keeps no fp16 intermediates.
  float clamp = 0.0f;
};

/// Every image effect in the tables: bloom with each filter (defaults otherwise) and the Gaussian
/// blur with each method. Flares draw from a light list, not an image: their
/// robustness cases live in flare_e2e_test.cpp and occlusion_test.cpp.
std::vector<ImageEffect> image_effects();

/// Bloom's footprint from docs/BLOOM.md (exposed for its own test of the derivation).
uint32_t bloom_footprint_px(VkExtent2D extent, const BloomConfig& config);

/// The Gaussian blur's footprint from docs/BLUR.md for the method and parameters `blur` chose.
uint32_t gauss_footprint_px(const BlurChoice& choice);

/// Runs one Bloom on the test context (fresh images; output poisoned with NaN).
CpuImage run_bloom_once(const BloomConfig& config, const CpuImage& input, VkFormat format);

}  // namespace glint::test
