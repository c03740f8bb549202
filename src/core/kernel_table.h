// The SPIR-V of every kernel variant, embedded at build time (kernels/CMakeLists.txt).
#pragma once

#include <cstddef>
#include <cstdint>

namespace glint::detail {

struct KernelBinary {
  const char* id;        //!< "<kernel>_<variant>", e.g. "bloom_down_rgba16f"
  const uint32_t* code;  //!< SPIR-V words
  size_t size_bytes;
};

/// The embedded kernel with this id, or null.
const KernelBinary* find_kernel(const char* id);

}  // namespace glint::detail
