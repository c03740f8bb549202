// QUERIES.csv, the input of `glint lod`: one LodQuery per data row, read strictly and within fixed
// bounds. The parser is a pure function of the text (no file, no Vulkan), so that a fuzz target
// (fuzz/fuzz_csv.cpp) can call it directly.
//
// Format (docs/LOD.md, "QUERIES.csv"):
//   - Lines end with LF or CRLF. Spaces and tabs around a field are ignored. A line that is empty
//     (after trimming) or whose first character is '#' is skipped.
//   - Optional header: the first non-skipped line is a header when none of its fields is a number
//     (e.g. "dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y"); it must have 8 fields. A first line
//     with any numeric field is a data row and is checked like every other (a row of tiny numbers
//     such as 1e-45 is data, not a header).
//   - Data rows: exactly 8 decimal numbers dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y.
//     Derivatives: finite and within float range. tex_w: 1 to the atlas width; tex_h: 1 to the
//     atlas height; off_x: 0 to atlas width - tex_w; off_y: 0 to atlas height - tex_h (the tile
//     lies inside the atlas). NaN, Inf, zero or negative tile sizes are rejected, never mapped to
//     level 0. Numbers that underflow a float read as the nearest float (0 or a subnormal).
//   - Bounds: at most kMaxLodCsvBytes bytes, kMaxLodCsvLineBytes bytes per line and kMaxLodQueries
//     data rows; no NUL bytes.
// Every error names the line (1-based) and, for a field, its number and name and the accepted
// range.
#pragma once

#include <glint/lod.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace glint::io {

/// The largest QUERIES.csv read (256 MiB: kMaxLodQueries rows of up to 64 bytes each).
inline constexpr uint64_t kMaxLodCsvBytes = uint64_t(256) << 20;
/// The longest line accepted, in bytes without the line end (8 numbers of up to 100 characters).
inline constexpr size_t kMaxLodCsvLineBytes = 1024;
/// The most data rows: LodBatch's per-call limit.
inline constexpr size_t kMaxLodQueries = 4'194'240;

/// A parsed QUERIES.csv.
struct LodCsv {
  std::string header;             //!< the header line as written (trimmed), empty when none
  std::vector<std::string> rows;  //!< each data row as written (trimmed), for the output
  std::vector<uint32_t> lines;    //!< the 1-based line number of each data row
  std::vector<LodQuery> queries;  //!< one per data row
};

/// Parses the text of a QUERIES.csv for an atlas of atlas_width x atlas_height texels (the ranges
/// of tex_* and off_* depend on it).
/// Throws Error(invalid_argument) with a one-line message "line N: ..." naming the field and the
/// accepted range; throws nothing else (std::bad_alloc aside).
LodCsv parse_lod_csv(std::string_view text, uint32_t atlas_width, uint32_t atlas_height);

/// Reads `path` (any readable file, pipes and devices included) in chunks, stopping at the first
/// line longer than kMaxLodCsvLineBytes or at kMaxLodCsvBytes, and parses it. Errors name the path:
/// Error(io_failure) when it cannot be read, Error(invalid_argument) for its content or size.
/// max_bytes: the size cap (tests pass a smaller one).
LodCsv load_lod_csv(const std::string& path, uint32_t atlas_width, uint32_t atlas_height,
                    uint64_t max_bytes = kMaxLodCsvBytes);

}  // namespace glint::io
