// OpenEXR reading and writing for the CLI, tests and benchmarks (OpenEXR 3.1).
//
// Every failure throws glint::Error(ErrorCode::io_failure, "<path>: <what is wrong>"), including
// the exceptions OpenEXR itself throws, which are caught and re-thrown with the path in front.
// Nothing here crashes on a missing, empty, foreign, truncated or corrupt file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/cpu_image.h"

namespace glint::io {

/// The largest image the readers accept: 16384 on a side and 2^28 pixels in all (a 4 GiB
/// CpuImage). Larger data windows are rejected before anything is allocated.
inline constexpr uint32_t kMaxImageDimension = 16384;
inline constexpr uint64_t kMaxImagePixels = uint64_t(1) << 28;

/// Reads the colour of an OpenEXR file as RGBA float.
///
/// The image is the file's data window (the display window is ignored), top row first. Channels:
/// R, G and B when any of them is present (a missing one reads as 0); else a channel named Y, or
/// the only channel of a one-channel file (Z, Y, anything), goes to R = G = B. A is read when
/// present, else alpha is 1; a file whose only channel is A gives R = G = B = A. Half, float and uint channels are all
/// converted to float. Scanline and tiled single-part files are read (the first part of a multi-part file); deep files
/// are not. path: the file to read.
CpuImage read_exr(const std::string& path);

/// The size of an OpenEXR file's data window, from its header alone (no pixel is read), checked
/// against the limits above: for refusing work that cannot fit before the pixels are decoded.
struct ExrExtent {
  uint32_t width = 0;
  uint32_t height = 0;
};
ExrExtent read_exr_extent(const std::string& path);

/// One channel of an OpenEXR file.
struct ExrChannel {
  uint32_t width = 0;
  uint32_t height = 0;
  std::string name;           //!< the channel that was read
  std::vector<float> values;  //!< width * height floats, row-major, top row first
};

/// Reads one channel of an OpenEXR file as float (for depth and other non-colour data).
///
/// Reads the channel called `preferred_name` when the file has it, else the file's first channel
/// in OpenEXR's (alphabetical) order; ExrChannel::name says which. The channel must not be
/// subsampled.
/// path: the file to read.
/// preferred_name: may be empty, which means "the first channel".
ExrChannel read_exr_channel(const std::string& path, const std::string& preferred_name);

/// Writes `image` as an RGBA half-float OpenEXR file (ZIP compression), replacing `path`.
///
/// Values beyond the half range (+-65504) become +-Inf; NaN stays NaN.
/// path: the file to write; its directory must exist.
/// image: must be non-empty, with rgba.size() == width * height * 4 (else Error(invalid_argument)).
void write_exr_half(const std::string& path, const CpuImage& image);

/// Writes `image` as an RGBA 32-bit float OpenEXR file (ZIP compression), replacing `path`;
/// read_exr() reads it back bit for bit (no rounding, unlike write_exr_half()).
/// path: the file to write; its directory must exist.
/// image: as for write_exr_half().
void write_exr_float(const std::string& path, const CpuImage& image);

/// Writes one float channel called `name` (e.g. "Z" for depth) as a 32-bit float OpenEXR file (ZIP
/// compression), replacing `path`; read_exr_channel() reads it back bit for bit.
/// path: the file to write; its directory must exist.
/// values: width * height floats, row-major, top row first (else Error(invalid_argument)).
void write_exr_channel(const std::string& path, const std::string& name, uint32_t width, uint32_t height,
                       const std::vector<float>& values);

/// Throws Error naming `path` unless `image` can be written: non-empty, its pixel buffer
/// width * height * 4 floats, and within the size limits above. Shared by the EXR and PNG writers.
void check_writable_image(const std::string& path, const CpuImage& image);

}  // namespace glint::io
