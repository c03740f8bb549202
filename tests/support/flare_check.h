// Checks shared by the flare tests (flare_test.cpp, flare_robustness_test.cpp): the element atlas
// as the GPU made it, the device's filtering precision, and the comparison of a drawn image with
// the float64 composite (tools/reference/flare_reference.h) within docs/FLARE.md's tolerance.
#pragma once

#include <glint/flare.h>

#include <cstddef>
#include <string>

#include "core/cpu_image.h"
#include "reference/flare_reference.h"

namespace glint::test {

/// Every level of `flare`'s atlas as the GPU made it (exact fp16 values as double); leaves the
/// atlas where the LensFlare keeps it.
reference::FlareAtlas read_flare_atlas(const LensFlare& flare);

/// The sub-texel and mipmap precision every conformant Vulkan device guarantees (4 and 4 bits),
/// which the flare tolerances are derived from.
reference::SamplerPrecision flare_sampler_precision();

struct FlareDeviation {
  double worst_ratio = 0;  // max |gpu - ref| / tolerance
  size_t outside = 0;
  std::string first;
};

/// Per channel: |gpu - ref| <= bound + (2 count + 1) * u * |ref| + 1e-7, with u the store rounding
/// of `format` (2^-10 for RGBA16F, 2^-23 for RGBA32F). The raster path rounds twice per blend (the
/// fragment output converted to the attachment format, then the sum); the gather sums in fp32 and
/// rounds once. Each rounding is at most u times the running sum, which for non-negative
/// additions is at most the final value.
FlareDeviation compare_flare(const CpuImage& gpu, const reference::FlareComposite& ref, VkFormat format);

}  // namespace glint::test
