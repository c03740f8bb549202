// A CPU-side RGBA float image: what io/ reads and writes, what tests and references compare.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace glint {

struct CpuImage {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<float> rgba;  //!< width * height * 4 floats, row-major, top row first

  CpuImage() = default;
  CpuImage(uint32_t w, uint32_t h, float fill = 0.0f) : width(w), height(h), rgba(size_t(w) * h * 4, fill) {}
  float* at(uint32_t x, uint32_t y) { return &rgba[(size_t(y) * width + x) * 4]; }
  const float* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

}  // namespace glint
