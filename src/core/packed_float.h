// VK_FORMAT_B10G11R11_UFLOAT_PACK32 conversion, for uploads and readbacks of that format (tools
// and tests): red in bits 0-10 and green in bits 11-21 as unsigned 11-bit floats (5-bit exponent,
// bias 15, 6-bit mantissa), blue in bits 22-31 as an unsigned 10-bit float (5-bit mantissa). The
// Vulkan spec ("Unsigned 11-Bit Floating-Point Numbers", "Unsigned 10-Bit ...") defines them:
// denormals below 2^-14, exponent 31 for Inf and NaN, no sign. Converting, negative values and -Inf
// become 0, finite values above the largest finite value ((2 - 2^-M) * 2^15 with M mantissa bits:
// 65024 for 11-bit, 64512 for 10-bit) become it, and the rest round to nearest even here (the spec
// also lets a device round toward zero, which tests allow for).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace glint::detail {

/// The largest finite unsigned float with `mantissa_bits` (6: 65024, 5: 64512).
inline double ufloat_max(int mantissa_bits) { return (2.0 - std::ldexp(1.0, -mantissa_bits)) * 32768.0; }

/// `value` as an unsigned float with a 5-bit exponent and `mantissa_bits` (6 or 5) bits.
inline uint32_t float_to_ufloat(float value, int mantissa_bits) {
  const int m = mantissa_bits;
  if (std::isnan(value)) return (31u << m) | 1u;
  if (!(value > 0.0f)) return 0;  // negative, -Inf and 0
  if (std::isinf(value)) return 31u << m;
  const double x = std::min(double(value), ufloat_max(m));
  int e = std::ilogb(x);
  if (e < -14) {  // denormal: x = mantissa * 2^(-14 - m); a mantissa of 2^m carries into exponent 1
    return static_cast<uint32_t>(std::nearbyint(std::ldexp(x, 14 + m)));
  }
  auto mant = static_cast<uint32_t>(std::nearbyint(std::ldexp(x, m - e))) - (1u << m);  // round half even
  if (mant == (1u << m)) {  // rounded up to the next power of two
    mant = 0;
    ++e;
  }
  return (uint32_t(e + 15) << m) | mant;
}

inline float ufloat_to_float(uint32_t bits, int mantissa_bits) {
  const int m = mantissa_bits;
  const uint32_t e = bits >> m;
  const uint32_t mant = bits & ((1u << m) - 1);
  if (e == 0) return static_cast<float>(std::ldexp(double(mant), -14 - m));
  if (e == 31) return mant ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  return static_cast<float>(std::ldexp(double((1u << m) | mant), int(e) - 15 - m));
}

inline uint32_t pack_b10g11r11(float r, float g, float b) {
  return float_to_ufloat(r, 6) | (float_to_ufloat(g, 6) << 11) | (float_to_ufloat(b, 5) << 22);
}

/// r, g, b of a packed texel (alpha reads as 1 from this format).
inline void unpack_b10g11r11(uint32_t texel, float rgb[3]) {
  rgb[0] = ufloat_to_float(texel & 0x7ffu, 6);
  rgb[1] = ufloat_to_float((texel >> 11) & 0x7ffu, 6);
  rgb[2] = ufloat_to_float(texel >> 22, 5);
}

}  // namespace glint::detail
