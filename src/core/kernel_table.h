// The SPIR-V of every kernel variant of the library, embedded at build time (glint_add_kernels in
// cmake/GlintKernels.cmake). The tools embed their own kernels in a second table of the same form
// (tools/support/tool_kernels.h).
#pragma once

#include <cstddef>
#include <cstdint>

namespace glint::detail {

struct KernelBinary {
  const char* id;        //!< "<kernel>_<variant>", e.g. "bloom_down_rgba16f"
  const uint32_t* code;  //!< SPIR-V words
  size_t size_bytes;
};

/// The library's embedded kernel with this id, or null.
const KernelBinary* find_kernel(const char* id);

}  // namespace glint::detail
