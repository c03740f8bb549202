// Measures docs/STABILITY.md's data and prints its tables: the flicker of a moving sub-pixel
// firefly per filter with and without the Karis guard, and the size of a point's bloom as a
// fraction of the image width at 720p, 1080p and 2160p. The tests (tests/stability_test.cpp)
// check the same numbers with the same code (tools/analysis/light_stats.h).
//
// Writes, into DIR, firefly_energy.json (the device and the bloom energy of every frame of every
// firefly configuration) and firefly_frames_raw.png (frames 0 to 2 of the 1e4 firefly, one row
// per guard, tiles described in the JSON); bench/plot.py --chart firefly draws the charts from
// them (docs/PERF.md). DIR and its parents are created when missing, before any measurement, so
// that a path that cannot be written fails at once; the two files replace the previous ones
// together (io::AtomicOutputs), so a failed run leaves the old pair untouched.
//
//   build/bench/glint_stability_report [--out DIR]     (DIR default docs/stability)
#include <glint/bloom.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "analysis/light_stats.h"
#include "core/resources.h"
#include "io/atomic_outputs.h"
#include "io/png_io.h"
#include "support/environment.h"
#include "support/transfer.h"

namespace glint {
namespace {

// Input and output images live as long as the Bloom that caches descriptor sets for their views:
// a destroyed view's handle can come back for a new view (lavapipe reuses them), and Bloom would
// then use the set it made for the old one.
struct Frame {
  detail::OwnedImage in, out;
  Frame(const Context& ctx, VkExtent2D e)
      : in(ctx, e, VK_FORMAT_R32G32B32A32_SFLOAT, detail::kToolImageUsage),
        out(ctx, e, VK_FORMAT_R32G32B32A32_SFLOAT, detail::kToolImageUsage) {}
  CpuImage run(const Context& ctx, Bloom& bloom, const CpuImage& input) {
    detail::upload(ctx, in.state, input);
    ctx.run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
    return detail::download(ctx, out.state);
  }
};

struct FireflySeries {
  std::vector<double> energy, centroid_error;
};

// A point moving right (or, with `diagonal`, right and down) by a quarter pixel per frame over 64
// frames (16 px).
FireflySeries firefly(const Context& ctx, const BloomConfig& config, float value, uint32_t w, uint32_t h,
                      bool diagonal = false) {
  Frame frame(ctx, {w, h});
  Bloom bloom(ctx, config);
  FireflySeries s;
  for (int f = 0; f < 64; ++f) {
    const double x = 100.0 + 0.25 * f, y = h / 2.0 - (diagonal ? 32.0 - 0.25 * f : 0.0);
    const CpuImage in = analysis::subpixel_point(w, h, x, y, value);
    const CpuImage out = frame.run(ctx, bloom, in);
    const auto st = analysis::light_stats(analysis::added_light(out, in), w, h);
    s.energy.push_back(st.energy);
    s.centroid_error.push_back(st.cx - x);
  }
  return s;
}

// Frames 0, 1, 2 (x = 100, 100.25, 100.5 px) of the 1e4 firefly for the default settings (top row)
// and with the per-box Karis guard (bottom row), each crop 96x48 around the point, intensity 1,
// tonemapped with exposure 0.5. The tiles' geometry is kFilmstrip, written to the JSON.
struct FilmstripLayout {
  uint32_t tile_w = 96, tile_h = 48, frames = 3;
  const char* rows[2] = {"karis_smooth", "karis"};
  double exposure = 0.5, intensity = 1.0, value = 1e4;
};
constexpr FilmstripLayout kFilmstrip;
constexpr const char* kFilmstripFile = "firefly_frames_raw.png";

CpuImage filmstrip(const Context& ctx) {
  const uint32_t w = 256, h = 128, cw = kFilmstrip.tile_w, ch = kFilmstrip.tile_h;
  CpuImage strip(3 * cw, 2 * ch, 0.0f);
  for (int row = 0; row < 2; ++row) {
    BloomConfig c;
    c.firefly_guard = row == 0 ? FireflyGuard::karis_smooth : FireflyGuard::karis;
    c.intensity = float(kFilmstrip.intensity);
    Frame frame(ctx, {w, h});
    Bloom bloom(ctx, c);
    for (int f = 0; f < int(kFilmstrip.frames); ++f) {
      const CpuImage in = analysis::subpixel_point(w, h, 100.0 + 0.25 * f, h / 2.0, float(kFilmstrip.value));
      const CpuImage out = frame.run(ctx, bloom, in);
      for (uint32_t y = 0; y < ch; ++y)
        for (uint32_t x = 0; x < cw; ++x) {
          const float* p = out.at(100 - cw / 2 + x, h / 2 - ch / 2 + y);
          float* q = strip.at(f * cw + x, row * ch + y);
          for (int k = 0; k < 4; ++k) q[k] = p[k];
        }
    }
  }
  return strip;
}

// One firefly configuration and its per-frame bloom energy (absolute: the light the bloom adds,
// summed over R, G, B and all pixels).
struct EnergyRecord {
  std::string filter, guard;
  double max_brightness, value;
  std::vector<double> energy;
};

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out + "\"";
}

// printf into a std::string.
void appendf(std::string& out, const char* format, ...) __attribute__((format(printf, 2, 3)));
void appendf(std::string& out, const char* format, ...) {
  va_list args, copy;
  va_start(args, format);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (n > 0) {
    const size_t at = out.size();
    out.resize(at + size_t(n) + 1);
    std::vsnprintf(out.data() + at, size_t(n) + 1, format, args);
    out.resize(at + size_t(n));
  }
  va_end(args);
}

// firefly_energy.json: what bench/plot.py --chart firefly draws. Frame f has the point at
// x = 100 + 0.25 f px on a 256x128 image.
std::string energy_json(const std::string& device, const std::vector<EnergyRecord>& rows) {
  std::string j;
  appendf(j, "{\n  \"device\": %s,\n  \"image\": [256, 128],\n  \"x0_px\": 100.0,\n  \"step_px\": 0.25,\n",
          json_string(device).c_str());
  appendf(j,
          "  \"filmstrip\": {\"file\": \"%s\", \"tile\": [%u, %u], \"frames\": %u, "
          "\"rows\": [\"%s\", \"%s\"], \"value\": %g, \"intensity\": %g, \"exposure\": %g},\n",
          kFilmstripFile, kFilmstrip.tile_w, kFilmstrip.tile_h, kFilmstrip.frames, kFilmstrip.rows[0],
          kFilmstrip.rows[1], kFilmstrip.value, kFilmstrip.intensity, kFilmstrip.exposure);
  appendf(j, "  \"series\": [\n");
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    appendf(j,
            "    {\"filter\": \"%s\", \"firefly_guard\": \"%s\", \"max_brightness\": %g, \"value\": %g, \"energy\": [",
            r.filter.c_str(), r.guard.c_str(), r.max_brightness, r.value);
    for (size_t k = 0; k < r.energy.size(); ++k) appendf(j, "%s%.9g", k ? ", " : "", r.energy[k]);
    appendf(j, "]}%s\n", i + 1 < rows.size() ? "," : "");
  }
  appendf(j, "  ]\n}\n");
  return j;
}

// Creates `dir` and its missing parents, then checks that files can be created in it; throws
// Error(io_failure) naming the path and the reason. Runs before the measurements (up to a minute
// on lavapipe), so that a bad --out fails at once instead of after them.
void prepare_out_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(ErrorCode::io_failure, "cannot create " + dir + ": " + ec.message());
  if (!fs::is_directory(dir, ec)) throw Error(ErrorCode::io_failure, "cannot create " + dir + ": not a directory");
  // access(2) with W_OK | X_OK: creating a file in a directory needs write and search permission.
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw Error(ErrorCode::io_failure, "cannot write into " + dir + ": " + std::strerror(errno));
  }
}

// Replaces DIR/firefly_energy.json and DIR/firefly_frames_raw.png together; on failure both old
// files stay and the error names the file and the reason.
void write_outputs(const std::string& dir, const std::string& json, const CpuImage& strip) {
  try {
    io::AtomicOutputs out;
    out.write(dir + "/firefly_energy.json", [&](const std::string& tmp) { io::write_text_file(tmp, json); });
    out.write(dir + "/" + kFilmstripFile,
              [&](const std::string& tmp) { io::write_png_tonemapped(tmp, strip, float(kFilmstrip.exposure)); });
    out.commit();
  } catch (const Error& e) {
    throw Error(e.code(), std::string("cannot write ") + e.what());
  }
}

int main_impl(int argc, char** argv) {
  std::string out_dir = "docs/stability";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--out")) {
      if (i + 1 >= argc || argv[i + 1][0] == '\0') {
        throw Error(ErrorCode::invalid_argument, "--out needs a directory: accepted --out DIR");
      }
      out_dir = argv[++i];
    } else {
      throw Error(ErrorCode::invalid_argument,
                  std::string("unknown argument '") + argv[i] + "': accepted [--out DIR] (default docs/stability)");
    }
  }
  prepare_out_dir(out_dir);
  const Context ctx = Context::create(tools::context_options_from_environment());
  std::printf("device: %s\n\n", ctx.info().name.c_str());
  std::printf(
      "| filter | firefly_guard | max_brightness | value | energy spread | max step | centroid jitter px | mean energy "
      "|\n|---|---|---|---|---|---|---|---|\n");
  std::vector<EnergyRecord> records;
  for (float maxb : {1000.0f, 8000.0f}) {
    for (float value : {1e4f, 1e3f}) {
      for (BloomFilter f : {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9}) {
        for (FireflyGuard guard : {FireflyGuard::karis_smooth, FireflyGuard::karis, FireflyGuard::off}) {
          BloomConfig c;
          c.filter = f;
          c.firefly_guard = guard;
          c.max_brightness = maxb;
          const auto s = firefly(ctx, c, value, 256, 128);
          const auto ev = analysis::relative_variation(s.energy);
          double lo = 1e9, hi = -1e9;
          for (double e : s.centroid_error) lo = std::min(lo, e), hi = std::max(hi, e);
          records.push_back({bloom_filter_name(f), firefly_guard_name(guard), maxb, value, s.energy});
          double mean = 0;
          for (double e : s.energy) mean += e / s.energy.size();
          std::printf("| %s | %s | %g | %g | %.4f | %.4f | %.3f | %.4g |\n", bloom_filter_name(f),
                      firefly_guard_name(guard), maxb, value, ev.spread, ev.max_step, hi - lo, mean);
        }
      }
    }
  }
  std::printf("\n| filter (defaults) | diagonal path: energy spread | max step |\n|---|---|---|\n");
  for (BloomFilter f : {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9}) {
    BloomConfig c;
    c.filter = f;
    const auto ev = analysis::relative_variation(firefly(ctx, c, 1e4f, 256, 128, true).energy);
    std::printf("| %s | %.4f | %.4f |\n", bloom_filter_name(f), ev.spread, ev.max_step);
  }
  write_outputs(out_dir, energy_json(ctx.info().name, records), filmstrip(ctx));
  std::printf(
      "\n| filter | iterations | level0_height | size | r50 / width | r90 / width | sigma / width "
      "|\n|---|---|---|---|---|---|---|\n");
  for (BloomFilter f : {BloomFilter::cod13, BloomFilter::dual, BloomFilter::gauss9}) {
    struct Row {
      VkExtent2D e;
      uint32_t it;
      float radius;
      uint32_t level0_height;
    };
    for (Row row : {Row{{1280, 720}, 5, 1.f, 0}, Row{{1920, 1080}, 5, 1.f, 0}, Row{{3840, 2160}, 5, 1.f, 0},
                    Row{{1280, 720}, 5, 1.f, 540}, Row{{1920, 1080}, 5, 1.f, 540}, Row{{3840, 2160}, 5, 1.f, 540}}) {
      {
        const VkExtent2D e = row.e;
        const uint32_t it = row.it;
        BloomConfig c;
        c.filter = f;
        c.iterations = it;
        c.radius = row.radius;
        c.level0_height = row.level0_height;
        Frame frame(ctx, e);
        Bloom bloom(ctx, c);
        const double cx = e.width / 2 + 0.3, cy = e.height / 2 + 0.3;
        const CpuImage in = analysis::subpixel_point(e.width, e.height, cx, cy, 1000.0f);
        const auto added = analysis::added_light(frame.run(ctx, bloom, in), in);
        const auto st = analysis::light_stats(added, e.width, e.height);
        const double r50 = analysis::radius_holding(added, e.width, e.height, cx, cy, 0.5);
        const double r90 = analysis::radius_holding(added, e.width, e.height, cx, cy, 0.9);
        std::printf("| %s | %u | %u | %ux%u | %.5f | %.5f | %.5f |\n", bloom_filter_name(f), it, row.level0_height,
                    e.width, e.height, r50 / e.width, r90 / e.width, std::sqrt(st.xx + st.yy) / e.width);
      }
    }
  }
  // With validation on (GLINT_VALIDATION=1), any message fails the run: the data came from
  // commands the validation layers reject.
  if (const uint32_t messages = ctx.validation_messages()) {
    std::fprintf(stderr, "glint_stability_report: %u validation messages (printed above)\n", messages);
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace glint

int main(int argc, char** argv) {
  try {
    return glint::main_impl(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "glint_stability_report: %s\n", e.what());
    return 1;
  }
}
