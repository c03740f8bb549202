// PNG output for viewing HDR results: exposure, tonemap, sRGB encode, 8 bits (libpng).
#pragma once

#include <cstdint>
#include <string>

#include "core/cpu_image.h"

namespace glint::io {

/// The ACES filmic curve as fitted by Krzysztof Narkowicz ("ACES Filmic Tone Mapping Curve",
/// 2015): x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to [0, 1]. Applied per channel to
/// linear input; no 0.6 pre-scale is built in (use the exposure for that). NaN and negative
/// values give 0, +Inf gives 1.
float tonemap_aces_fitted(float linear);

/// The sRGB transfer function (IEC 61966-2-1) of a value in [0, 1], rounded to 8 bits.
uint8_t encode_srgb8(float value);

/// Writes `image` as an 8-bit sRGB PNG (RGB, no alpha) for viewing, replacing `path`.
///
/// Each channel becomes encode_srgb8(tonemap_aces_fitted(value * exposure)), so NaN becomes 0.
/// Alpha is dropped: HDR alpha is rarely meant as PNG transparency.
/// path: the file to write; its directory must exist. Failures throw Error(io_failure).
/// image: must be non-empty, with rgba.size() == width * height * 4 (else Error(invalid_argument)).
/// exposure: linear scale applied before the tonemap; finite and > 0 (else Error(invalid_argument)).
void write_png_tonemapped(const std::string& path, const CpuImage& image, float exposure = 1.0f);

}  // namespace glint::io
