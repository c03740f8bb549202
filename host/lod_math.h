// The C++ twin of kernels/common/lod.glsl: the same source (kernels/common/lod_impl.h) compiled
// as C++, so host code and tests compute exactly what the GPU kernels compute (up to the
// device's log2 and sqrt precision).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "lod.h"

namespace glint::lod_math {

// The GLSL built-ins lod_impl.h uses, for float.
inline float sqrt(float x) { return std::sqrt(x); }
inline float log2(float x) { return std::log2(x); }
inline float floor(float x) { return std::floor(x); }
inline float min(float a, float b) { return std::min(a, b); }
inline float max(float a, float b) { return std::max(a, b); }
inline float clamp(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }
inline uint32_t floatBitsToUint(float x) { return std::bit_cast<uint32_t>(x); }

#define GLINT_LOD_FN inline
#include "lod_impl.h"
#undef GLINT_LOD_FN

}  // namespace glint::lod_math
