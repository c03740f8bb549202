// libFuzzer target for the OpenEXR loader (tools/io/exr_io.cpp): any bytes must give an image or
// glint::Error(io_failure), never a crash, a hang or an allocation beyond the loader's size limit.
// The input goes through a file because read_exr takes a path (the CLI's only way in).
#include <glint/glint.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "io/exr_io.h"

namespace {

std::string scratch_path() {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir && *dir ? dir : "/tmp") + "/glint_fuzz_exr_" + std::to_string(getpid()) + ".exr";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = scratch_path();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  try {
    const glint::CpuImage image = glint::io::read_exr(path);
    if (image.rgba.size() != size_t(image.width) * image.height * 4) std::abort();
    const glint::io::ExrChannel channel = glint::io::read_exr_channel(path, "Z");
    if (channel.values.size() != size_t(channel.width) * channel.height) std::abort();
  } catch (const glint::Error& e) {
    if (e.code() != glint::ErrorCode::io_failure) std::abort();
  }
  return 0;
}
