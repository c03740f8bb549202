// Float64 CPU reference of glint's bloom. It implements docs/BLOOM.md step by step (the same
// contract as src/bloom/shaders/bloom_*.comp and src/bloom/shaders/bloom.glsl), with plain loops and no
// shortcuts, so that GPU tests can measure how far the kernels are from the exact algorithm.
// CPU only: no Vulkan call is made here.
#pragma once

#include <glint/bloom.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/cpu_image.h"

namespace glint::reference {

/// An RGBA image of doubles: width * height * 4 values, row-major, top row first.
struct DoubleImage {
  uint32_t width = 0, height = 0;
  std::vector<double> rgba;

  double* at(uint32_t x, uint32_t y) { return &rgba[(size_t(y) * width + x) * 4]; }
  const double* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

/// Full bloom of `input` (its float values are taken as exact) into an output of the same size:
/// out.rgb = in.rgb + intensity / N * Up(A0), out.a = in.a (docs/BLOOM.md "Composite"). With
/// intensity == 0 the output is the input unchanged.
/// If `round_intermediates_to_half` is true, every stored intermediate (a level after each
/// downsample, after each gauss9 blur pass, and after each accumulate) is rounded through fp16 as
/// the GPU's RGBA16F storage does; otherwise all intermediates stay double. The output itself is
/// never rounded.
/// Throws std::invalid_argument for an empty input, a pixel buffer of the wrong size, or
/// config.iterations == 0.
DoubleImage bloom(const CpuImage& input, const BloomConfig& config, bool round_intermediates_to_half = false);

// The individual stages, exposed for tests.

/// Rec. 709 luma (docs/BLOOM.md "Notation").
double luma(double r, double g, double b);

/// Sanitize (NaN and negatives to 0, clamp to 65504) and soft threshold
/// (docs/BLOOM.md "Prefilter"). `in_rgb` and `out_rgb` may alias.
void prefilter(const BloomConfig& config, const double in_rgb[3], double out_rgb[3]);

/// The pyramid levels 0 .. N-1 after the downsample (and, for gauss9, the 9-tap blur), before
/// accumulation; N follows the mip-chain clamp (docs/BLOOM.md "Mip chain"). Alpha of every level
/// is 1 (what the GPU stores). See bloom() for round_half. Throws as bloom() does.
std::vector<DoubleImage> downsampled_levels(const CpuImage& input, const BloomConfig& config, bool round_half = false);

/// The filter's upsample `Up` of `small` to a `width` x `height` image (docs/BLOOM.md "Upsample
/// and accumulate"; also the one the composite uses). Alpha of the result is 1. Not rounded.
DoubleImage upsample(const DoubleImage& small, uint32_t width, uint32_t height, BloomFilter filter, double radius);

/// Relative L2 error over the RGB channels: ||gpu - ref|| / ||ref||. 0 when both are zero,
/// +Inf when only the reference is zero; NaN or +Inf when `gpu` holds a NaN or Inf (so any
/// `< tolerance` check fails). Throws std::invalid_argument when the sizes differ.
double relative_l2(const CpuImage& gpu, const DoubleImage& ref);

}  // namespace glint::reference
