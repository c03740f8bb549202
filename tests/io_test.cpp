// tools/io: EXR and PNG round trips, and every way a file can be bad ending in Error(io_failure),
// never a crash. No GPU. Truncation is tried at every length of a small file (as meshoptimizer's
// tests do for buffers), so run this under GLINT_SANITIZE=ON as well.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>
#include <glint/glint.h>
#include <gtest/gtest.h>
#include <png.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/cpu_image.h"
#include "io/atomic_outputs.h"
#include "io/exr_io.h"
#include "io/png_io.h"
#include "support/host_memory.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

// Random HDR colour with a few very bright texels and some tiny ones (half subnormals).
CpuImage random_image(uint32_t width, uint32_t height, uint32_t stream) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  CpuImage img(width, height);
  for (float& v : img.rgba) {
    const float u = unit(rng);
    v = u < 0.02f ? 100.0f + 5000.0f * unit(rng) : u < 0.05f ? 1e-6f * unit(rng) : 4.0f * unit(rng);
  }
  return img;
}

// Expects `fn` to throw Error(io_failure) whose message starts with `path`.
void expect_io_failure(const std::string& path, const std::function<void()>& fn, const std::string& fragment = "") {
  try {
    fn();
    ADD_FAILURE() << "no exception for " << path;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::io_failure) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    if (!fragment.empty()) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a glint::Error: " << e.what();
  }
}

std::vector<char> read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const char* data, size_t size) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(data, static_cast<std::streamsize>(size));
}

// Writes a float EXR with the given channels, each filled by value(channel index, x, y).
void write_float_channels(const std::string& path, int width, int height, const std::vector<std::string>& names,
                          const std::function<float(size_t, int, int)>& value) {
  Imf::Header header(width, height);
  for (const auto& n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
  std::vector<std::vector<float>> planes(names.size(), std::vector<float>(size_t(width) * height));
  Imf::FrameBuffer fb;
  for (size_t c = 0; c < names.size(); ++c) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) planes[c][size_t(y) * width + x] = value(c, x, y);
    fb.insert(names[c],
              Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes[c].data()), sizeof(float), sizeof(float) * width));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(fb);
  file.writePixels(height);
}

class IoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("glint_io_test_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

TEST_F(IoTest, ExrRoundTripKeepsHalfPrecision) {
  const CpuImage in = random_image(37, 19, 7);  // odd sizes catch stride mistakes
  const std::string path = file("round.exr");
  io::write_exr_half(path, in);
  const CpuImage out = io::read_exr(path);
  ASSERT_EQ(out.width, in.width);
  ASSERT_EQ(out.height, in.height);
  ASSERT_EQ(out.rgba.size(), in.rgba.size());
  for (size_t i = 0; i < in.rgba.size(); ++i) {
    // Half: 11 significant bits (relative error <= 2^-11), absolute 2^-25 in the subnormal range.
    const float tol = std::max(std::abs(in.rgba[i]) * 0x1p-11f, 0x1p-25f);
    ASSERT_NEAR(out.rgba[i], in.rgba[i], tol) << "float " << i;
  }
}

TEST_F(IoTest, ExrWithoutAlphaReadsAlphaAsOne) {
  const std::string path = file("rgb.exr");
  std::vector<Imf::Rgba> px(8 * 4, Imf::Rgba(1.5f, 2.5f, 3.5f, 0.25f));
  {
    Imf::RgbaOutputFile out(path.c_str(), 8, 4, Imf::WRITE_RGB);
    out.setFrameBuffer(px.data(), 1, 8);
    out.writePixels(4);
  }
  const CpuImage img = io::read_exr(path);
  ASSERT_EQ(img.width, 8u);
  ASSERT_EQ(img.height, 4u);
  for (uint32_t y = 0; y < 4; ++y) {
    for (uint32_t x = 0; x < 8; ++x) {
      EXPECT_EQ(img.at(x, y)[0], 1.5f);
      EXPECT_EQ(img.at(x, y)[1], 2.5f);
      EXPECT_EQ(img.at(x, y)[2], 3.5f);
      EXPECT_EQ(img.at(x, y)[3], 1.0f);
    }
  }
}

TEST_F(IoTest, SingleChannelFileGoesToGrey) {
  for (const std::string name : {"Z", "Y", "depth"}) {
    const std::string path = file(name + ".exr");
    write_float_channels(path, 5, 3, {name}, [](size_t, int x, int y) { return 0.5f + float(x) + 10.0f * y; });
    const CpuImage img = io::read_exr(path);
    ASSERT_EQ(img.width, 5u);
    ASSERT_EQ(img.height, 3u);
    for (uint32_t y = 0; y < 3; ++y) {
      for (uint32_t x = 0; x < 5; ++x) {
        const float v = 0.5f + float(x) + 10.0f * y;
        EXPECT_EQ(img.at(x, y)[0], v) << name;
        EXPECT_EQ(img.at(x, y)[1], v) << name;
        EXPECT_EQ(img.at(x, y)[2], v) << name;
        EXPECT_EQ(img.at(x, y)[3], 1.0f) << name;
      }
    }
  }
}

// A file whose only channel is A: R = G = B = A = the channel (the single-channel rule). Before, the
// alpha slice replaced the grey one in OpenEXR's FrameBuffer (one slice per name): the image was black.
TEST_F(IoTest, SingleAlphaChannelGoesToGreyAndAlpha) {
  const std::string path = file("alpha.exr");
  write_float_channels(path, 5, 3, {"A"}, [](size_t, int x, int y) { return 0.25f + float(x) + 10.0f * y; });
  const CpuImage img = io::read_exr(path);
  ASSERT_EQ(img.width, 5u);
  ASSERT_EQ(img.height, 3u);
  for (uint32_t y = 0; y < 3; ++y) {
    for (uint32_t x = 0; x < 5; ++x) {
      const float v = 0.25f + float(x) + 10.0f * y;
      for (int c = 0; c < 4; ++c) EXPECT_EQ(img.at(x, y)[c], v) << "channel " << c << " at " << x << "," << y;
    }
  }
}

TEST_F(IoTest, ReadChannelByNameElseFirst) {
  const std::string path = file("multi.exr");
  write_float_channels(path, 4, 6, {"Z", "albedo", "mask"},
                       [](size_t c, int x, int y) { return float(c) * 1000.0f + float(x) + 0.25f * y; });
  const io::ExrChannel z = io::read_exr_channel(path, "Z");
  EXPECT_EQ(z.name, "Z");
  ASSERT_EQ(z.width, 4u);
  ASSERT_EQ(z.height, 6u);
  ASSERT_EQ(z.values.size(), 24u);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(z.values[size_t(y) * 4 + x], float(x) + 0.25f * y);
  const io::ExrChannel mask = io::read_exr_channel(path, "mask");
  EXPECT_EQ(mask.name, "mask");
  EXPECT_EQ(mask.values[0], 2000.0f);
  // Absent name: the first channel in OpenEXR's (alphabetical, upper case first) order.
  const io::ExrChannel first = io::read_exr_channel(path, "depth");
  EXPECT_EQ(first.name, "Z");
  EXPECT_EQ(io::read_exr_channel(path, "").name, "Z");
  // Several channels and none of them R, G, B or Y: read_exr refuses rather than guesses.
  expect_io_failure(
      path, [&] { io::read_exr(path); }, "channels: Z, albedo, mask");
}

TEST_F(IoTest, DataWindowWithOffsetIsTheImage) {
  const std::string path = file("offset.exr");
  const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(99, 99));
  const Imath::Box2i data(Imath::V2i(-3, 10), Imath::V2i(4, 12));  // 8x3
  Imf::Header header(display, data);
  header.channels().insert("R", Imf::Channel(Imf::FLOAT));
  std::vector<float> r(8 * 3);
  for (size_t i = 0; i < r.size(); ++i) r[i] = float(i);
  Imf::FrameBuffer fb;
  fb.insert("R", Imf::Slice::Make(Imf::FLOAT, r.data(), data));
  {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(3);
  }
  const CpuImage img = io::read_exr(path);
  ASSERT_EQ(img.width, 8u);
  ASSERT_EQ(img.height, 3u);
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(img.rgba[i * 4 + 0], float(i));
    EXPECT_EQ(img.rgba[i * 4 + 1], 0.0f);  // G and B absent: 0
    EXPECT_EQ(img.rgba[i * 4 + 2], 0.0f);
    EXPECT_EQ(img.rgba[i * 4 + 3], 1.0f);
  }
}

TEST_F(IoTest, MissingDirectoryEmptyAndForeignFilesFail) {
  const std::string missing = file("missing.exr");
  expect_io_failure(
      missing, [&] { io::read_exr(missing); }, "no such file");
  expect_io_failure(
      missing, [&] { io::read_exr_channel(missing, "Z"); }, "no such file");

  const std::string dir = dir_.string();
  expect_io_failure(
      dir, [&] { io::read_exr(dir); }, "directory");

  const std::string empty = file("empty.exr");
  write_bytes(empty, "", 0);
  expect_io_failure(
      empty, [&] { io::read_exr(empty); }, "empty");

  const std::string noise = file("noise.exr");
  std::mt19937 rng(3);
  std::vector<char> bytes(4096);
  for (char& b : bytes) b = static_cast<char>(rng());
  write_bytes(noise, bytes.data(), bytes.size());
  expect_io_failure(
      noise, [&] { io::read_exr(noise); }, "not an OpenEXR file");
  expect_io_failure(
      noise, [&] { io::read_exr_channel(noise, ""); }, "not an OpenEXR file");

  const std::string png = file("image.png");
  io::write_png_tonemapped(png, random_image(4, 4, 1));
  expect_io_failure(
      png, [&] { io::read_exr(png); }, "not an OpenEXR file");
}

TEST_F(IoTest, TruncatedExrFailsAtEveryLength) {
  const std::string good = file("good.exr");
  io::write_exr_half(good, random_image(16, 16, 11));
  const std::vector<char> bytes = read_bytes(good);
  ASSERT_GT(bytes.size(), 100u);
  const std::string cut = file("cut.exr");

  // The brief's case first: half the file.
  write_bytes(cut, bytes.data(), bytes.size() / 2);
  expect_io_failure(cut, [&] { io::read_exr(cut); });

  // Then every shorter length: each must throw io_failure (never crash, never return garbage).
  for (size_t n = 0; n < bytes.size(); ++n) {
    write_bytes(cut, bytes.data(), n);
    SCOPED_TRACE("length " + std::to_string(n) + " of " + std::to_string(bytes.size()));
    expect_io_failure(cut, [&] { io::read_exr(cut); });
    expect_io_failure(cut, [&] { io::read_exr_channel(cut, "R"); });
  }
}

TEST_F(IoTest, CorruptExrNeverCrashes) {
  const std::string good = file("good.exr");
  io::write_exr_half(good, random_image(16, 16, 12));
  const std::vector<char> bytes = read_bytes(good);
  const std::string bad = file("bad.exr");
  std::mt19937 rng(5);
  // Flip one byte at a time everywhere in the file: either it still decodes (pixel data that
  // happens to stay valid) or it fails with io_failure. Anything else fails the test or crashes.
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::vector<char> copy = bytes;
    copy[i] = static_cast<char>(copy[i] ^ static_cast<char>(1 + rng() % 255));
    write_bytes(bad, copy.data(), copy.size());
    try {
      const CpuImage img = io::read_exr(bad);
      EXPECT_EQ(img.rgba.size(), size_t(img.width) * img.height * 4);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::io_failure) << "byte " << i << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "byte " << i << ": not a glint::Error: " << e.what();
    }
  }
}

TEST_F(IoTest, OversizedExrIsRejectedBeforeAllocation) {
  const std::string path = file("wide.exr");
  const int width = int(io::kMaxImageDimension) + 1;
  std::vector<Imf::Rgba> row(size_t(width), Imf::Rgba(1.0f, 1.0f, 1.0f, 1.0f));
  {
    Imf::RgbaOutputFile out(path.c_str(), width, 1, Imf::WRITE_RGBA);
    out.setFrameBuffer(row.data(), 1, size_t(width));
    out.writePixels(1);
  }
  expect_io_failure(
      path, [&] { io::read_exr(path); }, "larger than glint reads");
  expect_io_failure(
      path, [&] { io::read_exr_channel(path, "R"); }, "larger than glint reads");
}

TEST_F(IoTest, WriteFailuresAreIoFailures) {
  const CpuImage img = random_image(4, 4, 2);
  const std::string no_dir = file("no/such/dir/out.exr");
  expect_io_failure(no_dir, [&] { io::write_exr_half(no_dir, img); });
  const std::string no_dir_png = file("no/such/dir/out.png");
  expect_io_failure(no_dir_png, [&] { io::write_png_tonemapped(no_dir_png, img); });
  const std::string dir = dir_.string();
  expect_io_failure(dir, [&] { io::write_exr_half(dir, img); });
  expect_io_failure(dir, [&] { io::write_png_tonemapped(dir, img); });

  const std::string empty = file("empty.exr");
  expect_io_failure(
      empty, [&] { io::write_exr_half(empty, CpuImage()); }, "empty");
  expect_io_failure(
      empty, [&] { io::write_png_tonemapped(empty, CpuImage()); }, "empty");

  CpuImage inconsistent(4, 4);
  inconsistent.rgba.resize(10);
  try {
    io::write_exr_half(file("x.exr"), inconsistent);
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
  }
  try {
    io::write_png_tonemapped(file("x.png"), img, -1.0f);
    ADD_FAILURE() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
  }
}

TEST(Tonemap, AcesFittedEndsAndNonFiniteValues) {
  EXPECT_EQ(io::tonemap_aces_fitted(0.0f), 0.0f);
  EXPECT_EQ(io::tonemap_aces_fitted(-5.0f), 0.0f);
  EXPECT_EQ(io::tonemap_aces_fitted(std::nanf("")), 0.0f);
  EXPECT_EQ(io::tonemap_aces_fitted(INFINITY), 1.0f);
  EXPECT_EQ(io::tonemap_aces_fitted(1e6f), 1.0f);
  // Narkowicz's curve at 1: 2.54 / 3.16.
  EXPECT_NEAR(io::tonemap_aces_fitted(1.0f), 2.54f / 3.16f, 1e-6f);
  float previous = 0.0f;
  for (float x = 1e-4f; x < 100.0f; x *= 1.1f) {
    const float y = io::tonemap_aces_fitted(x);
    EXPECT_GE(y, previous) << x;
    previous = y;
  }
  EXPECT_EQ(io::encode_srgb8(0.0f), 0);
  EXPECT_EQ(io::encode_srgb8(std::nanf("")), 0);
  EXPECT_EQ(io::encode_srgb8(1.0f), 255);
  EXPECT_EQ(io::encode_srgb8(0.5f), 188);  // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
  EXPECT_EQ(io::encode_srgb8(0.002f), 7);  // linear segment: 12.92 * 0.002 * 255 = 6.59
}

TEST_F(IoTest, PngHoldsTheTonemappedSrgbPixels) {
  CpuImage img = random_image(13, 7, 9);
  img.at(0, 0)[0] = std::nanf("");
  img.at(1, 0)[1] = INFINITY;
  img.at(2, 0)[2] = -3.0f;
  const float exposure = 0.7f;
  const std::string path = file("out.png");
  io::write_png_tonemapped(path, img, exposure);

  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&png, path.c_str())) << png.message;
  EXPECT_EQ(png.width, 13u);
  EXPECT_EQ(png.height, 7u);
  EXPECT_EQ(png.format, PNG_FORMAT_RGB);
  png.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(png));
  ASSERT_TRUE(png_image_finish_read(&png, nullptr, rgb.data(), 0, nullptr)) << png.message;
  for (uint32_t y = 0; y < 7; ++y) {
    for (uint32_t x = 0; x < 13; ++x) {
      for (int c = 0; c < 3; ++c) {
        const uint8_t want = io::encode_srgb8(io::tonemap_aces_fitted(img.at(x, y)[c] * exposure));
        ASSERT_EQ(rgb[(size_t(y) * 13 + x) * 3 + c], want) << x << "," << y << "," << c;
      }
    }
  }
  EXPECT_EQ(rgb[0], 0);        // NaN
  EXPECT_EQ(rgb[3 + 1], 255);  // +Inf
  EXPECT_EQ(rgb[6 + 2], 0);    // negative
}

// ---- AtomicOutputs ----

// Every file in `dir` whose name ends with the temporaries' suffix.
std::vector<std::string> temporaries_in(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() >= std::strlen(io::kTemporarySuffix) &&
        name.compare(name.size() - std::strlen(io::kTemporarySuffix), std::string::npos, io::kTemporarySuffix) == 0) {
      found.push_back(name);
    }
  }
  return found;
}

std::string read_text(const std::string& path) {
  const std::vector<char> b = read_bytes(path);
  return std::string(b.begin(), b.end());
}

TEST_F(IoTest, AtomicOutputsReplaceAllFilesOnCommit) {
  io::write_text_file(file("a.txt"), "old a");
  io::write_text_file(file("b.txt"), "old b");
  const CpuImage img = random_image(9, 7, 3);
  {
    io::AtomicOutputs out;
    out.write(file("a.txt"), [](const std::string& tmp) { io::write_text_file(tmp, "new a"); });
    out.write(file("b.txt"), [](const std::string& tmp) { io::write_text_file(tmp, "new b"); });
    out.write(file("c.exr"), [&](const std::string& tmp) { io::write_exr_half(tmp, img); });
    // Nothing is replaced before commit(): the temporaries sit next to the targets.
    EXPECT_EQ(read_text(file("a.txt")), "old a");
    EXPECT_EQ(read_text(file("b.txt")), "old b");
    EXPECT_FALSE(fs::exists(file("c.exr")));
    EXPECT_EQ(temporaries_in(dir_).size(), 3u);
    out.commit();
  }
  EXPECT_EQ(read_text(file("a.txt")), "new a");
  EXPECT_EQ(read_text(file("b.txt")), "new b");
  EXPECT_EQ(io::read_exr(file("c.exr")).width, 9u);
  EXPECT_TRUE(temporaries_in(dir_).empty());
}

// A writer that fails (as a full disk or a file-size limit does) after another file was written:
// no file is replaced, no temporary is left, and the error names the target, not the temporary.
TEST_F(IoTest, AtomicOutputsLeaveEverythingOnAFailingWrite) {
  io::write_text_file(file("a.txt"), "old a");
  io::write_text_file(file("b.txt"), "old b");
  expect_io_failure(
      file("b.txt"),
      [&] {
        io::AtomicOutputs out;
        out.write(file("a.txt"), [](const std::string& tmp) { io::write_text_file(tmp, "new a"); });
        out.write(file("b.txt"), [](const std::string& tmp) {
          io::write_text_file(tmp, "half of b");  // partly written, then the device is full
          throw Error(ErrorCode::io_failure, tmp + ": No space left on device");
        });
        out.commit();
      },
      "No space left on device");
  EXPECT_EQ(read_text(file("a.txt")), "old a");
  EXPECT_EQ(read_text(file("b.txt")), "old b");
  EXPECT_TRUE(temporaries_in(dir_).empty());
  // An exception of another type is reported as io_failure naming the target too.
  expect_io_failure(
      file("a.txt"),
      [&] {
        io::AtomicOutputs out;
        out.write(file("a.txt"), [](const std::string&) { throw std::runtime_error("disk on fire"); });
      },
      "disk on fire");
  EXPECT_EQ(read_text(file("a.txt")), "old a");
  EXPECT_TRUE(temporaries_in(dir_).empty());
  // A missing directory fails before any writer runs.
  bool ran = false;
  expect_io_failure(
      file("no/such/x.txt"),
      [&] {
        io::AtomicOutputs out;
        out.write(file("no/such/x.txt"), [&](const std::string&) { ran = true; });
      },
      "does not exist");
  EXPECT_FALSE(ran);
}

// A real file-size limit (RLIMIT_FSIZE, what `ulimit -f` sets): the EXR writer fails with EFBIG
// (SIGXFSZ is ignored by AtomicOutputs, else it would kill the process), the previous file stays.
// Run in a child process so that the limit does not touch the rest of the suite.
TEST_F(IoTest, AtomicOutputsUnderAFileSizeLimitKeepThePreviousFile) {
  const CpuImage big = random_image(256, 256, 5);  // ~500 kB of half RGBA, noise does not compress
  const CpuImage small = random_image(4, 4, 6);
  io::write_exr_half(file("out.exr"), small);
  const std::vector<char> before = read_bytes(file("out.exr"));
  const std::string target = file("out.exr");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const rlimit limit{64 << 10, 64 << 10};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    int code = 3;
    try {
      io::AtomicOutputs out;
      out.write(target, [&](const std::string& tmp) { io::write_exr_half(tmp, big); });
      out.commit();
      code = 0;
    } catch (const Error& e) {
      code = (e.code() == ErrorCode::io_failure && std::string(e.what()).rfind(target, 0) == 0) ? 2 : 4;
    }
    ::_exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 2) << "0: the write did not fail; 4: wrong error";
  EXPECT_EQ(read_bytes(file("out.exr")), before);
  EXPECT_TRUE(temporaries_in(dir_).empty());
}

// SIGTERM (and SIGINT) while a file is being written: the handler removes the temporaries and the
// process dies of the signal; the previous files are intact.
TEST_F(IoTest, AtomicOutputsRemoveTemporariesOnSigterm) {
  for (const int sig : {SIGTERM, SIGINT}) {
    io::write_text_file(file("a.txt"), "old a");
    io::write_text_file(file("b.txt"), "old b");
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(ready[0]);
      io::AtomicOutputs out;
      out.write(file("a.txt"), [](const std::string& tmp) { io::write_text_file(tmp, "new a"); });
      out.write(file("b.txt"), [&](const std::string& tmp) {
        io::write_text_file(tmp, "half of b");
        const char byte = 1;
        (void)!::write(ready[1], &byte, 1);  // "killing me now finds two temporaries"
        for (;;) ::pause();
      });
      ::_exit(0);
    }
    ::close(ready[1]);
    char byte = 0;
    ASSERT_EQ(::read(ready[0], &byte, 1), 1);
    ::close(ready[0]);
    EXPECT_EQ(temporaries_in(dir_).size(), 2u);
    ASSERT_EQ(::kill(child, sig), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_EQ(read_text(file("a.txt")), "old a");
    EXPECT_EQ(read_text(file("b.txt")), "old b");
    EXPECT_TRUE(temporaries_in(dir_).empty()) << "signal " << sig;
  }
}

TEST_F(IoTest, AtomicOutputsKeepThePermissionsOfTheReplacedFile) {
  io::write_text_file(file("p.txt"), "old");
  fs::permissions(file("p.txt"), fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  io::AtomicOutputs out;
  out.write(file("p.txt"), [](const std::string& tmp) { io::write_text_file(tmp, "new"); });
  out.commit();
  EXPECT_EQ(fs::status(file("p.txt")).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  EXPECT_EQ(read_text(file("p.txt")), "new");
}

}  // namespace
}  // namespace glint

namespace glint::test {
namespace {

// The tools refuse work the host cannot hold up front (the demo at 16384x16384 was killed by the
// kernel after minutes), naming the bytes; work that fits passes.
TEST(HostMemory, WorkBeyondTheAvailableMemoryIsRefusedByName) {
  const uint64_t available = tools::available_host_memory();
  ASSERT_GT(available, 0u) << "this system reports no available memory";
  EXPECT_NO_THROW(tools::check_host_memory("a small job", 1 << 20));
  try {
    tools::check_host_memory("a huge job", available + (uint64_t(1) << 30));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::unsupported_size);
    EXPECT_NE(std::string(e.what()).find("a huge job needs about"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("MiB are available"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace glint::test
