// Shared benchmark helpers: one Context per process (GLINT_DEVICE picks it), inputs, medians.
#pragma once

#include <glint/glint.h>

#include <functional>
#include <vector>

#include "core/cpu_image.h"

namespace glint::bench {

const Context& context();
/// Random HDR RGBA: values in [0, 1.5) with 2% of pixels between 2 and 40.
CpuImage random_hdr(uint32_t width, uint32_t height, uint32_t stream);
double median_of(std::vector<double> values);

/// Records `frames` calls of `record_frame` in one command buffer with a timestamp after each, runs
/// it, and returns the median GPU time of one frame in milliseconds. `profiler` needs frames + 1
/// marks of capacity.
double median_frame_ms(const Context& context, Profiler& profiler, int frames,
                       const std::function<void(VkCommandBuffer)>& record_frame);

}  // namespace glint::bench
