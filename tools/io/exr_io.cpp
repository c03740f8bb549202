// OpenEXR io through the generic FrameBuffer API (OpenEXR 3.1 "Reading and Writing Image Files",
// section "Reading an image file with an arbitrary set of channels"), so that any channel set and
// pixel type converts to float. OpenEXR reports problems by throwing Iex exceptions (std::exception
// subclasses); each is caught here and re-thrown as glint::Error(io_failure) naming the path.
#include "io/exr_io.h"

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>
#include <ImfTestFile.h>
#include <glint/glint.h>
#include <half.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>

namespace glint::io {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::io_failure, path + ": " + what);
}

// OpenEXR messages sometimes span lines; callers print errors on one line.
std::string one_line(const char* text) {
  std::string s = text ? text : "unknown error";
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

// OpenEXR's own header sanity check: a bound on the data window and tile size, so that a corrupt
// header cannot make OpenEXR allocate a huge line-offset table before our size check runs. Looser
// than kMaxImageDimension so that most oversized files get our clearer message below.
void limit_openexr_sizes() {
  static const bool done = [] {
    Imf::Header::setMaxImageSize(4 * int(kMaxImageDimension), 4 * int(kMaxImageDimension));
    Imf::Header::setMaxTileSize(int(kMaxImageDimension), int(kMaxImageDimension));
    return true;
  }();
  (void)done;
}

// Walks the attribute list of every header (OpenEXR file layout: magic, version, then per header
// "name\0type\0" + int32 size + value, ended by an empty name; multi-part files end the header list
// with an empty header) and rejects a size that is negative or runs past the end of the file.
// OpenEXR 3.1 allocates an attribute's declared size before reading it (OpaqueAttribute), so a
// 40-byte file could otherwise make it allocate up to 2 GiB; found by fuzz/fuzz_exr.cpp. OpenEXR
// parses known types (chlist, ...) by content rather than by the declared size, so a corrupt file
// can still lead it to a different, huge declared size that this walk never saw: that allocation is
// virtual (never written before the read fails) and ends in Error(io_failure) like any other.
void check_header_sizes(const std::string& path, uint64_t file_bytes, bool multi_part) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(8);  // magic number and version field, already checked by isOpenExrFile
  uint64_t pos = 8;
  auto read_name = [&](std::string& name) {
    name.clear();
    for (char c; in.get(c);) {
      ++pos;
      if (c == '\0') return true;
      if (name.size() >= 255) fail(path, "corrupt header: an attribute name is longer than 255 bytes");
      name += c;
    }
    fail(path, "truncated header (the file ends inside the attribute list)");
  };
  for (int header = 0;; ++header) {
    if (header > 1024) fail(path, "corrupt header: more than 1024 parts");
    std::string name, type;
    int attributes = 0;
    for (;; ++attributes) {
      read_name(name);
      if (name.empty()) break;
      if (attributes > 4096) fail(path, "corrupt header: more than 4096 attributes");
      read_name(type);
      unsigned char size_bytes[4];
      if (!in.read(reinterpret_cast<char*>(size_bytes), 4)) fail(path, "truncated header (in attribute " + name + ")");
      pos += 4;
      const int32_t size = int32_t(uint32_t(size_bytes[0]) | uint32_t(size_bytes[1]) << 8 |
                                   uint32_t(size_bytes[2]) << 16 | uint32_t(size_bytes[3]) << 24);
      if (size < 0 || uint64_t(size) > file_bytes - pos) {
        fail(path, "corrupt header: attribute " + name + " declares " + std::to_string(size) + " bytes, but " +
                       std::to_string(file_bytes - pos) + " remain in the file");
      }
      in.seekg(size, std::ios::cur);
      pos += uint64_t(size);
    }
    // A single-part file has one header; a multi-part list ends with an empty header.
    if (!multi_part || attributes == 0) return;
  }
}

// Checks what the filesystem can tell before OpenEXR opens the file, for precise messages.
void check_input_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) fail(path, "cannot access: " + ec.message());
  if (!fs::exists(st)) fail(path, "no such file");
  if (fs::is_directory(st)) fail(path, "is a directory, not an OpenEXR file");
  if (!fs::is_regular_file(st)) fail(path, "not a regular file");
  const auto bytes = fs::file_size(path, ec);
  if (ec) fail(path, "cannot access: " + ec.message());
  if (bytes == 0) fail(path, "empty file (0 bytes), not an OpenEXR file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) fail(path, std::string("cannot open for reading: ") + std::strerror(errno));
  }
  bool tiled = false, deep = false, multi_part = false;
  if (!Imf::isOpenExrFile(path.c_str(), tiled, deep, multi_part)) {
    fail(path, "not an OpenEXR file (no OpenEXR magic number and version)");
  }
  if (deep) fail(path, "deep OpenEXR files are not supported");
  check_header_sizes(path, bytes, multi_part);
}

// Data window size, checked against the limits before anything is allocated.
struct Window {
  Imath::Box2i box;
  uint32_t width = 0;
  uint32_t height = 0;
};

Window checked_window(const std::string& path, const Imf::Header& header) {
  Window w;
  w.box = header.dataWindow();
  const int64_t width = int64_t(w.box.max.x) - w.box.min.x + 1;
  const int64_t height = int64_t(w.box.max.y) - w.box.min.y + 1;
  if (width <= 0 || height <= 0) fail(path, "empty data window (zero-size image)");
  if (width > kMaxImageDimension || height > kMaxImageDimension ||
      uint64_t(width) * uint64_t(height) > kMaxImagePixels) {
    std::ostringstream m;
    m << "image is " << width << "x" << height << ", larger than glint reads (at most " << kMaxImageDimension
      << " on a side and " << kMaxImagePixels << " pixels)";
    fail(path, m.str());
  }
  w.width = uint32_t(width);
  w.height = uint32_t(height);
  return w;
}

void require_full_resolution(const std::string& path, const char* name, const Imf::Channel& channel) {
  if (channel.xSampling != 1 || channel.ySampling != 1) {
    fail(path, std::string("channel ") + name + " is subsampled, which glint does not read");
  }
}

size_t channel_count(const Imf::ChannelList& channels) {
  size_t n = 0;
  for (auto it = channels.begin(); it != channels.end(); ++it) ++n;
  return n;
}

std::string channel_names(const Imf::ChannelList& channels) {
  std::string names;
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    if (!names.empty()) names += ", ";
    names += it.name();
  }
  return names.empty() ? "none" : names;
}

// Y (luminance), else the only channel of a one-channel file; empty when neither exists.
std::string grey_channel(const Imf::ChannelList& channels) {
  if (channels.findChannel("Y")) return std::string("Y");
  if (channel_count(channels) == 1) return std::string(channels.begin().name());
  return std::string();
}

// Runs `body` (which uses OpenEXR) and turns any exception but glint::Error into io_failure.
template <typename F>
auto guarded(const std::string& path, const char* action, F&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    fail(path, std::string("out of memory, cannot ") + action);
  } catch (const std::exception& e) {
    fail(path, std::string("cannot ") + action + ": " + one_line(e.what()));
  } catch (...) {
    fail(path, std::string("cannot ") + action + ": unknown error");
  }
}

// Opens `path` for reading with the size limits and file checks every reader needs, checks its
// data window and runs `body(file, window)` guarded as above.
template <typename F>
auto read_guarded(const std::string& path, F&& body) {
  limit_openexr_sizes();
  check_input_file(path);
  return guarded(path, "read OpenEXR file", [&] {
    Imf::InputFile file(path.c_str());
    const Window w = checked_window(path, file.header());
    return body(file, w);
  });
}

}  // namespace

void check_writable_image(const std::string& path, const CpuImage& image) {
  if (image.width == 0 || image.height == 0) {
    fail(path,
         "cannot write an empty image (" + std::to_string(image.width) + "x" + std::to_string(image.height) + ")");
  }
  if (image.rgba.size() != size_t(image.width) * image.height * 4) {
    throw Error(ErrorCode::invalid_argument,
                path + ": CpuImage has " + std::to_string(image.rgba.size()) +
                    " floats; width * height * 4 = " + std::to_string(size_t(image.width) * image.height * 4));
  }
  if (image.width > kMaxImageDimension || image.height > kMaxImageDimension ||
      uint64_t(image.width) * image.height > kMaxImagePixels) {
    fail(path, "image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                   ", larger than glint writes (at most " + std::to_string(kMaxImageDimension) + " on a side)");
  }
}

ExrExtent read_exr_extent(const std::string& path) {
  return read_guarded(path, [&](Imf::InputFile&, const Window& w) { return ExrExtent{w.width, w.height}; });
}

CpuImage read_exr(const std::string& path) {
  return read_guarded(path, [&](Imf::InputFile& file, const Window& w) {
    if (!file.isComplete()) fail(path, "truncated or incomplete OpenEXR file (missing pixel data)");
    const Imf::ChannelList& channels = file.header().channels();

    CpuImage image(w.width, w.height, 0.0f);
    const size_t x_stride = 4 * sizeof(float);
    const size_t y_stride = x_stride * w.width;
    Imf::FrameBuffer fb;
    const bool has_rgb = channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B");
    if (has_rgb) {
      // Missing colour channels are filled with 0 and a missing alpha with 1 by OpenEXR itself.
      const char* names[4] = {"R", "G", "B", "A"};
      for (int c = 0; c < 4; ++c) {
        if (const Imf::Channel* ch = channels.findChannel(names[c])) require_full_resolution(path, names[c], *ch);
        fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, image.rgba.data() + c, w.box, x_stride, y_stride, 1, 1,
                                             c == 3 ? 1.0 : 0.0));
      }
      file.setFrameBuffer(fb);
      file.readPixels(w.box.min.y, w.box.max.y);
      return image;
    }

    // Grey: Y (luminance), else the only channel. Read into R, copy to G and B.
    const std::string grey = grey_channel(channels);
    if (grey.empty()) {
      fail(path, "no R, G, B or Y channel and more than one channel to choose from (channels: " +
                     channel_names(channels) + ")");
    }
    require_full_resolution(path, grey.c_str(), *channels.findChannel(grey));
    // A FrameBuffer holds one slice per channel name: when the grey channel is A itself (a file with
    // the single channel A), inserting the alpha slice would replace the grey one and leave R = G =
    // B = 0. Then A is read once, into R, and copied to G, B and A.
    const bool grey_is_alpha = grey == "A";
    fb.insert(grey, Imf::Slice::Make(Imf::FLOAT, image.rgba.data(), w.box, x_stride, y_stride));
    if (!grey_is_alpha) {
      fb.insert("A", Imf::Slice::Make(Imf::FLOAT, image.rgba.data() + 3, w.box, x_stride, y_stride, 1, 1, 1.0));
    }
    file.setFrameBuffer(fb);
    file.readPixels(w.box.min.y, w.box.max.y);
    for (size_t i = 0; i < image.rgba.size(); i += 4) {
      image.rgba[i + 1] = image.rgba[i + 2] = image.rgba[i];
      if (grey_is_alpha) image.rgba[i + 3] = image.rgba[i];
    }
    return image;
  });
}

ExrChannel read_exr_channel(const std::string& path, const std::string& preferred_name) {
  return read_guarded(path, [&](Imf::InputFile& file, const Window& w) {
    if (!file.isComplete()) fail(path, "truncated or incomplete OpenEXR file (missing pixel data)");
    const Imf::ChannelList& channels = file.header().channels();
    if (channels.begin() == channels.end()) fail(path, "the file has no channels");

    ExrChannel out;
    out.name = (!preferred_name.empty() && channels.findChannel(preferred_name)) ? preferred_name
                                                                                 : std::string(channels.begin().name());
    require_full_resolution(path, out.name.c_str(), *channels.findChannel(out.name));
    out.width = w.width;
    out.height = w.height;
    out.values.assign(size_t(w.width) * w.height, 0.0f);
    Imf::FrameBuffer fb;
    fb.insert(out.name, Imf::Slice::Make(Imf::FLOAT, out.values.data(), w.box, sizeof(float), sizeof(float) * w.width));
    file.setFrameBuffer(fb);
    file.readPixels(w.box.min.y, w.box.max.y);
    return out;
  });
}

void write_exr_half(const std::string& path, const CpuImage& image) {
  limit_openexr_sizes();
  check_writable_image(path, image);
  guarded(path, "write OpenEXR file", [&] {
    std::vector<Imf::Rgba> pixels(size_t(image.width) * image.height);
    for (size_t i = 0; i < pixels.size(); ++i) {
      const float* p = &image.rgba[i * 4];
      pixels[i] = Imf::Rgba(half(p[0]), half(p[1]), half(p[2]), half(p[3]));
    }
    Imf::Header header(int(image.width), int(image.height));  // ZIP compression by default
    Imf::RgbaOutputFile file(path.c_str(), header, Imf::WRITE_RGBA);
    file.setFrameBuffer(pixels.data(), 1, image.width);
    file.writePixels(int(image.height));
  });
}

void write_exr_channel(const std::string& path, const std::string& name, uint32_t width, uint32_t height,
                       const std::vector<float>& values) {
  limit_openexr_sizes();
  if (name.empty()) throw Error(ErrorCode::invalid_argument, path + ": empty channel name");
  if (width == 0 || height == 0 || width > kMaxImageDimension || height > kMaxImageDimension ||
      uint64_t(width) * height > kMaxImagePixels) {
    fail(path, "cannot write a " + std::to_string(width) + "x" + std::to_string(height) + " image (1 to " +
                   std::to_string(kMaxImageDimension) + " on a side)");
  }
  if (values.size() != size_t(width) * height) {
    throw Error(ErrorCode::invalid_argument, path + ": " + std::to_string(values.size()) + " values for a " +
                                                 std::to_string(width) + "x" + std::to_string(height) + " image");
  }
  guarded(path, "write OpenEXR file", [&] {
    Imf::Header header(static_cast<int>(width), static_cast<int>(height));  // ZIP compression by default
    header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer fb;
    // OpenEXR's Slice takes a non-const pointer but only reads through it when writing.
    fb.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(values.data())), sizeof(float),
                               sizeof(float) * width));
    file.setFrameBuffer(fb);
    file.writePixels(static_cast<int>(height));
  });
}

void write_exr_float(const std::string& path, const CpuImage& image) {
  limit_openexr_sizes();
  check_writable_image(path, image);
  guarded(path, "write OpenEXR file", [&] {
    Imf::Header header(int(image.width), int(image.height));  // ZIP compression by default
    const char* names[4] = {"R", "G", "B", "A"};
    for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer fb;
    // Interleaved RGBA floats; OpenEXR's Slice takes a non-const pointer but only reads when writing.
    char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgba.data()));
    for (size_t c = 0; c < 4; ++c)
      fb.insert(names[c],
                Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 4 * sizeof(float), 4 * sizeof(float) * image.width));
    file.setFrameBuffer(fb);
    file.writePixels(int(image.height));
  });
}

}  // namespace glint::io
