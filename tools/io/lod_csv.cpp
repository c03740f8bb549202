// QUERIES.csv reading: bounded streaming read, then a strict line-by-line parse (lod_csv.h).
#include "io/lod_csv.h"

#include <glint/glint.h>

#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace glint::io {
namespace {

constexpr const char* kFieldNames[8] = {"dudx", "dvdx", "dudy", "dvdy", "tex_w", "tex_h", "off_x", "off_y"};

[[noreturn]] void bad_line(size_t line, const std::string& what) {
  throw Error(ErrorCode::invalid_argument, "line " + std::to_string(line) + ": " + what);
}

// Text from the file in a one-line message: at most 40 characters, non-printable bytes as '?'.
std::string quoted(std::string_view s) {
  std::string out = "'";
  for (size_t i = 0; i < s.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += (c >= 0x20 && c < 0x7F) ? static_cast<char>(c) : '?';
  }
  if (s.size() > 40) out += "...";
  return out + "'";
}

std::string number_text(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// A decimal number (std::from_chars' general format: digits, '.', exponent, also "inf" and "nan"),
// with an optional leading '+'. Returns false when `field` is not a number at all. A number beyond
// double's range reads as +-Inf (rejected later as out of range); one that underflows reads as the
// nearest double (0 or subnormal), the value strtod gives.
bool parse_number(std::string_view field, double& out) {
  std::string_view s = field;
  if (!s.empty() && s.front() == '+') {
    s.remove_prefix(1);
    if (!s.empty() && s.front() == '-') return false;  // "+-1"
  }
  if (s.empty()) return false;
  double v = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (r.ptr != s.data() + s.size()) return false;
  if (r.ec == std::errc::invalid_argument) return false;
  if (r.ec == std::errc::result_out_of_range) {
    const std::string copy(s);  // NUL-terminated; the syntax is already known to be a number
    v = std::strtod(copy.c_str(), nullptr);
  }
  out = v;
  return true;
}

// Splits `line` at commas into at most 9 fields (a ninth means "too many"); returns the count.
size_t split_fields(std::string_view line, std::string_view (&fields)[9]) {
  size_t n = 0;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    const std::string_view f =
        line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    fields[n++] = trim(f);
    if (comma == std::string_view::npos || n == 9) return n;
    start = comma + 1;
  }
}

std::string field_name(size_t i) { return "field " + std::to_string(i + 1) + " (" + kFieldNames[i] + ")"; }

}  // namespace

LodCsv parse_lod_csv(std::string_view text, uint32_t atlas_width, uint32_t atlas_height) {
  if (text.size() > kMaxLodCsvBytes) {
    throw Error(ErrorCode::invalid_argument, std::to_string(text.size()) + " bytes; QUERIES.csv is limited to " +
                                                 std::to_string(kMaxLodCsvBytes) + " bytes");
  }
  const float atlas_w = static_cast<float>(atlas_width);
  const float atlas_h = static_cast<float>(atlas_height);
  LodCsv csv;
  bool first_content = true;
  size_t line_no = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    ++line_no;
    const size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.size() > kMaxLodCsvLineBytes) {
      bad_line(line_no, "longer than " + std::to_string(kMaxLodCsvLineBytes) + " bytes (the limit per line)");
    }
    if (line.find('\0') != std::string_view::npos) bad_line(line_no, "contains a NUL byte; QUERIES.csv is text");
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;

    std::string_view fields[9];
    const size_t count = split_fields(line, fields);
    double v[8] = {};
    bool numeric[9] = {};
    size_t numbers = 0;
    for (size_t i = 0; i < count; ++i) {
      double unused = 0.0;
      numeric[i] = parse_number(fields[i], i < 8 ? v[i] : unused);
      numbers += numeric[i] ? 1 : 0;
    }
    if (first_content) {
      first_content = false;
      if (numbers == 0) {  // every field a name: the header
        if (count != 8) {
          bad_line(line_no, "header has " + std::string(count > 8 ? "more than 8" : std::to_string(count)) +
                                " fields; expected 8 names (dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y)");
        }
        csv.header = std::string(line);
        continue;
      }
    }
    if (count != 8) {
      bad_line(line_no, "has " + std::string(count > 8 ? "more than 8" : std::to_string(count)) +
                            " fields; expected 8 numbers dudx,dvdx,dudy,dvdy,tex_w,tex_h,off_x,off_y");
    }
    for (size_t i = 0; i < 8; ++i) {
      if (!numeric[i]) bad_line(line_no, field_name(i) + " " + quoted(fields[i]) + " is not a number");
    }
    LodQuery q;
    float* const out[8] = {&q.dudx, &q.dvdx, &q.dudy, &q.dvdy, &q.tex_w, &q.tex_h, &q.off_x, &q.off_y};
    for (size_t i = 0; i < 8; ++i) {
      if (!std::isfinite(v[i]) || std::fabs(v[i]) > double(FLT_MAX)) {
        bad_line(line_no, field_name(i) + " = " + number_text(v[i]) +
                              " is out of range; accepted finite numbers within float range");
      }
      *out[i] = static_cast<float>(v[i]);
    }
    // The tile: at least 1x1 texel and inside the atlas, tested in float as the kernel tests it
    // (include/glint/gpu/lod_impl.h, glint_lod_valid), so that every accepted row is a valid query.
    const auto check = [&](size_t i, float value, bool ok, const std::string& accepted) {
      if (!ok) bad_line(line_no, field_name(i) + " = " + number_text(value) + " is out of range; accepted " + accepted);
    };
    check(4, q.tex_w, q.tex_w >= 1.0f && q.tex_w <= atlas_w,
          "1 to " + std::to_string(atlas_width) + " (the atlas width)");
    check(5, q.tex_h, q.tex_h >= 1.0f && q.tex_h <= atlas_h,
          "1 to " + std::to_string(atlas_height) + " (the atlas height)");
    check(6, q.off_x, q.off_x >= 0.0f && q.off_x + q.tex_w <= atlas_w,
          "0 to atlas width - tex_w = " + number_text(double(atlas_w - q.tex_w)) +
              " (the tile must lie inside the atlas)");
    check(7, q.off_y, q.off_y >= 0.0f && q.off_y + q.tex_h <= atlas_h,
          "0 to atlas height - tex_h = " + number_text(double(atlas_h - q.tex_h)) +
              " (the tile must lie inside the atlas)");
    if (csv.queries.size() >= kMaxLodQueries) {
      bad_line(line_no, "more than " + std::to_string(kMaxLodQueries) + " queries (LodBatch's limit per call)");
    }
    csv.rows.emplace_back(line);
    csv.lines.push_back(static_cast<uint32_t>(line_no));
    csv.queries.push_back(q);
  }
  return csv;
}

LodCsv load_lod_csv(const std::string& path, uint32_t atlas_width, uint32_t atlas_height, uint64_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw Error(ErrorCode::io_failure, path + ": no such file");
  if (fs::is_directory(st)) throw Error(ErrorCode::io_failure, path + ": is a directory, not a CSV file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::io_failure, path + ": cannot open for reading: " + std::strerror(errno));

  // Read in chunks, checking both bounds as the bytes come: an endless or huge input (/dev/zero, a
  // sparse file with no line end) stops within kMaxLodCsvLineBytes + one chunk of memory.
  std::string text;
  char chunk[1 << 16];
  size_t line_no = 1, line_bytes = 0;
  for (;;) {
    in.read(chunk, sizeof chunk);
    const auto got = static_cast<size_t>(in.gcount());
    if (got == 0) break;
    if (text.size() + got > max_bytes) {
      throw Error(ErrorCode::invalid_argument, path + ": larger than " + std::to_string(max_bytes) +
                                                   " bytes, the limit of QUERIES.csv (" +
                                                   std::to_string(kMaxLodQueries) + " queries)");
    }
    for (size_t i = 0; i < got; ++i) {
      if (chunk[i] == '\n') {
        ++line_no;
        line_bytes = 0;
      } else if (++line_bytes > kMaxLodCsvLineBytes + 1) {  // + 1: a CR before the LF
        throw Error(ErrorCode::invalid_argument, path + ": line " + std::to_string(line_no) + ": longer than " +
                                                     std::to_string(kMaxLodCsvLineBytes) +
                                                     " bytes (the limit per line)");
      }
    }
    text.append(chunk, got);
  }
  if (in.bad()) throw Error(ErrorCode::io_failure, path + ": read error: " + std::strerror(errno));
  try {
    return parse_lod_csv(text, atlas_width, atlas_height);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

}  // namespace glint::io
