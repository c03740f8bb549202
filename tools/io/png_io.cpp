// PNG writing through libpng's simplified API (png_image_write_to_file, libpng 1.6), which reports
// errors as a return value and a message instead of longjmp, so no setjmp crosses C++ frames. For an
// 8-bit non-linear format it writes the sRGB chunk.
#include "io/png_io.h"

#include <glint/glint.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "io/exr_io.h"

namespace glint::io {

float tonemap_aces_fitted(float linear) {
  if (std::isnan(linear) || linear <= 0.0f) return 0.0f;
  if (std::isinf(linear)) return 1.0f;
  // Narkowicz 2015; the rational function tends to 2.51 / 2.43 > 1, hence the clamp.
  const float x = linear;
  const float y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
  return std::clamp(y, 0.0f, 1.0f);
}

uint8_t encode_srgb8(float value) {
  if (!(value > 0.0f)) return 0;  // also NaN
  if (value >= 1.0f) return 255;
  // IEC 61966-2-1 sRGB OETF.
  const float s = value <= 0.0031308f ? 12.92f * value : 1.055f * std::pow(value, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(std::clamp(s, 0.0f, 1.0f) * 255.0f));
}

void write_png_tonemapped(const std::string& path, const CpuImage& image, float exposure) {
  if (!std::isfinite(exposure) || !(exposure > 0.0f)) {
    char text[160];
    std::snprintf(text, sizeof text, ": exposure = %g is out of range: accepted finite and > 0", double(exposure));
    throw Error(ErrorCode::invalid_argument, path + text);
  }
  check_writable_image(path, image);
  if (std::filesystem::is_directory(path)) throw Error(ErrorCode::io_failure, path + ": is a directory");

  const size_t pixels = size_t(image.width) * image.height;
  std::vector<uint8_t> rgb(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = encode_srgb8(tonemap_aces_fitted(image.rgba[i * 4 + c] * exposure));
  }

  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = image.width;
  png.height = image.height;
  png.format = PNG_FORMAT_RGB;
  const int ok = png_image_write_to_file(&png, path.c_str(), 0, rgb.data(), 0, nullptr);
  const std::string message = png.message;
  png_image_free(&png);
  if (!ok) {
    throw Error(ErrorCode::io_failure, path + ": cannot write PNG: " + (message.empty() ? "libpng error" : message));
  }
}

}  // namespace glint::io
