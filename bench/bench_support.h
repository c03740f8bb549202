// Shared benchmark helpers: one Context per process (GLINT_DEVICE picks it), inputs, medians.
#pragma once

#include <glint/glint.h>

#include <vector>

#include "core/cpu_image.h"

namespace glint::bench {

const Context& context();
/// Random HDR RGBA: values in [0, 1.5) with 2% of pixels between 2 and 40.
CpuImage random_hdr(uint32_t width, uint32_t height, uint32_t seed);
double median_of(std::vector<double> values);

}  // namespace glint::bench
