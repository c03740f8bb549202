// libFuzzer target for the QUERIES.csv parser of `glint lod` (tools/io/lod_csv.cpp): any bytes must
// give a list of queries or glint::Error(invalid_argument), never a crash, a hang or an unbounded
// allocation. Every accepted query must be one the LOD kernel treats as valid (finite numbers, a
// tile of at least 1x1 inside the atlas), so that no accepted row silently gets level 0.
#include <glint/glint.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "io/lod_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // The atlas size from the first two bytes, so that the range checks see small atlases too.
  const uint32_t w = size >= 1 ? 1u + data[0] * 16u : 4096u;
  const uint32_t h = size >= 2 ? 1u + data[1] * 16u : 4096u;
  try {
    const glint::io::LodCsv csv = glint::io::parse_lod_csv(text, w, h);
    if (csv.queries.size() != csv.rows.size() || csv.queries.size() != csv.lines.size()) std::abort();
    if (csv.queries.size() > glint::io::kMaxLodQueries) std::abort();
    for (const glint::LodQuery& q : csv.queries) {
      const float f[8] = {q.dudx, q.dvdx, q.dudy, q.dvdy, q.tex_w, q.tex_h, q.off_x, q.off_y};
      for (float v : f) {
        if (!std::isfinite(v)) std::abort();
      }
      if (!(q.tex_w >= 1.0f && q.tex_h >= 1.0f && q.off_x >= 0.0f && q.off_y >= 0.0f && q.off_x + q.tex_w <= float(w) &&
            q.off_y + q.tex_h <= float(h))) {
        std::abort();
      }
    }
  } catch (const glint::Error& e) {
    if (e.code() != glint::ErrorCode::invalid_argument) std::abort();
  }
  return 0;
}
