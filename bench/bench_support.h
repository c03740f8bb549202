// Shared benchmark helpers: one Context per process (GLINT_DEVICE picks it), inputs, medians.
#pragma once

#include <benchmark/benchmark.h>
#include <glint/glint.h>

#include <functional>
#include <vector>

#include "core/cpu_image.h"
#include "core/resources.h"
#include "reference/occlusion_reference.h"

namespace glint::bench {

const Context& context();
/// Sets ContextOptions::kernel_statistics for the context (glint_bench --kernel_stats); call before
/// the first context().
void set_kernel_statistics(bool on);
/// Random HDR RGBA: values in [0, 1.5) with 2% of pixels between 2 and 40.
CpuImage random_hdr(uint32_t width, uint32_t height, uint32_t stream);
double median_of(std::vector<double> values);

/// A device-local buffer of max(bytes, 16) bytes with `usage` | TRANSFER_DST, holding `data` (copied
/// through a staging buffer) when it is given.
detail::OwnedBuffer device_buffer(const Context& context, const void* data, VkDeviceSize bytes,
                                  VkBufferUsageFlags usage);
/// `b` as a glint::Buffer of its whole size with `usage` | TRANSFER_DST, last used by the upload
/// copy (after_copy) or not yet used.
Buffer buffer_view(const detail::OwnedBuffer& b, VkBufferUsageFlags usage, bool after_copy);
/// An RGBA16F source holding random_hdr(extent, stream) and an RGBA16F destination of the same
/// extent, both with the tools' usage (sampled, storage, transfer).
struct ImagePair {
  detail::OwnedImage src;
  detail::OwnedImage dst;
};
ImagePair rgba16f_pair(const Context& context, VkExtent2D extent, uint32_t stream);
/// A sampled D32 depth image holding `depth`.
detail::OwnedImage depth_image(const Context& context, const reference::DepthImage& depth);

/// Records `frames` calls of `record_frame` in one command buffer with a timestamp after each, runs
/// it, and returns the median GPU time of one frame in milliseconds. `profiler` needs frames + 1
/// marks of capacity.
double median_frame_ms(const Context& context, Profiler& profiler, int frames,
                       const std::function<void(VkCommandBuffer)>& record_frame);

/// Times `record_frame` once per benchmark iteration: the median of `frames` frames
/// (median_frame_ms()) as the iteration's manual time. Returns those medians in milliseconds.
std::vector<double> time_frames(benchmark::State& state, int frames,
                                const std::function<void(VkCommandBuffer)>& record_frame);

/// Records one frame with `record_frame` given a profiler (its own marks after each step, at most
/// `capacity` - 1 of them), runs it, and returns the time between consecutive marks. The marks
/// serialise the dispatches, so the stages add up to more than an unmarked frame.
std::vector<Profiler::Stage> stage_marks(const Context& context, uint32_t capacity,
                                         const std::function<void(VkCommandBuffer, Profiler*)>& record_frame);

}  // namespace glint::bench
